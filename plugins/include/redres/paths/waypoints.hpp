#pragma once
/// @file
/// `waypoints`: straight lines through points read from a CSV file (columns x,y or x,y,z, in m, relative to the
/// path origin; the file is relative to the scenario that names it). One stroke by default, so dense smooth data
/// gives a smooth motion; `stop_at_points = true` stops at every waypoint.

#include <filesystem>

#include "redres/control/path.hpp"

namespace redres {

/// The configuration of `waypoints`.
struct WaypointsConfig {
  std::filesystem::path file{};  //!< CSV file with columns x,y[,z]; required
  bool stop_at_points = false;   //!< stop (from rest to rest) at every point

  static const Schema<WaypointsConfig>& schema();
};

}  // namespace redres

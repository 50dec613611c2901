#pragma once
/// @file
/// `circle`: a circle that starts at the path origin (so the end effector starts on it). Planar by default; with
/// `normal` it lies in the plane through the origin with that normal (spatial tasks). Timed over the whole path by
/// default.

#include <array>
#include <optional>

#include "redres/control/path.hpp"

namespace redres {

/// The configuration of `circle`.
struct CircleConfig {
  enum class Direction { kCcw, kCw };
  double radius = 0.05;                           //!< radius (m)
  double turns = 1.0;                             //!< number of turns
  double start_angle_deg = 0.0;                   //!< the origin's angle on the circle (deg)
  Direction direction = Direction::kCcw;          //!< about the normal
  std::optional<std::array<double, 3>> normal{};  //!< plane normal (spatial tasks; default: z)

  static const Schema<CircleConfig>& schema();
};

inline auto enum_names(CircleConfig::Direction) {
  return std::array{std::pair{CircleConfig::Direction::kCcw, std::string_view("ccw")},
                    std::pair{CircleConfig::Direction::kCw, std::string_view("cw")}};
}

}  // namespace redres

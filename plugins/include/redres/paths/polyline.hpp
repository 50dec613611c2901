#pragma once
/// @file
/// `polyline`: planar lines and arcs from the path origin. `segments` is an array of inline tables, each either
/// `{ to = [x, y] }` (a line to that point) or `{ center = [x, y], sweep_deg = s }` (an arc about that centre from
/// the current point, counter-clockwise for s > 0). With `stop_at_corners = true` (the default) every segment is
/// its own stroke, drawn from rest to rest; with false the whole polyline is one stroke.

#include <array>
#include <optional>
#include <vector>

#include "redres/control/path.hpp"

namespace redres {

/// One polyline segment: a line (`to`) or an arc (`center` and `sweep_deg`).
struct PolylineSegment {
  std::optional<std::array<double, 2>> to{};      //!< line end (m)
  std::optional<std::array<double, 2>> center{};  //!< arc centre (m)
  std::optional<double> sweep_deg{};              //!< arc sweep (deg), counter-clockwise for > 0

  static const Schema<PolylineSegment>& schema();
};

/// The configuration of `polyline`.
struct PolylineConfig {
  std::vector<PolylineSegment> segments{};  //!< required, non-empty
  bool stop_at_corners = true;              //!< every segment drawn from rest to rest

  static const Schema<PolylineConfig>& schema();
};

}  // namespace redres

#pragma once
/// @file
/// `line`: a straight line from the path origin by `delta` (2 numbers for planar tasks, 3 for spatial ones).

#include <vector>

#include "redres/control/path.hpp"

namespace redres {

/// The configuration of `line`.
struct LineConfig {
  std::vector<double> delta{};  //!< displacement from the origin (m): [dx, dy] or [dx, dy, dz]; required

  static const Schema<LineConfig>& schema();
};

}  // namespace redres

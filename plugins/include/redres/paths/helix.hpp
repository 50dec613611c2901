#pragma once
/// @file
/// `helix`: a helix that starts at the path origin and advances along `axis` (spatial tasks only). Timed over the
/// whole path by default.

#include <array>

#include "redres/control/path.hpp"

namespace redres {

/// The configuration of `helix`.
struct HelixConfig {
  double radius = 0.04;                    //!< radius (m)
  double pitch = 0.02;                     //!< advance per turn (m)
  double turns = 2.0;                      //!< number of turns
  std::array<double, 3> axis = {0, 0, 1};  //!< helix axis

  static const Schema<HelixConfig>& schema();
};

}  // namespace redres

#pragma once
/// @file
/// `letter_r`: the letter "R" of the paper's experiment, with the geometry of docs/letter_r.md (the paper does not
/// give it). In letter coordinates (x right, y up), with h the height, c = h/6 and rho = h/4, three strokes:
///   1. stem: line (0, 0) -> (0, h);
///   2. bowl: line (0, h) -> (c, h); clockwise half circle about (c, 3h/4) of radius rho to (c, h/2);
///      line (c, h/2) -> (0, h/2);
///   3. leg: line (0, h/2) -> (c + rho, 0).
/// The shape prefers a rotation of 180 degrees (upright, the R leaves the arm's workspace) and per-stroke timing,
/// so r_d_dot is continuous at every corner.

#include "redres/control/path.hpp"

namespace redres {

/// The configuration of `letter_r`.
struct LetterRConfig {
  double height = 0.15;  //!< letter height h (m)

  static const Schema<LetterRConfig>& schema();
};

}  // namespace redres

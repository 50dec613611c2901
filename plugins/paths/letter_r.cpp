/// `letter_r`: the letter "R" of DESIGN section 5 (the paper does not give its geometry). In letter coordinates
/// (x right, y up), with h the height, c = h/6 and rho = h/4, three strokes drawn in order:
///   1. stem: line (0, 0) -> (0, h);
///   2. bowl: line (0, h) -> (c, h); clockwise half circle about (c, 3h/4) of radius rho to (c, h/2);
///      line (c, h/2) -> (0, h/2);
///   3. leg: line (0, h/2) -> (c + rho, 0).
/// Defaults: origin at f(theta(0)) (placement "relative"), rotated by 180 degrees (upright, the R leaves the
/// arm's workspace), cycloidal timing per stroke, so r_d_dot is continuous at every corner.
/// TOML keys: `height` (m, default 0.15), plus the common path keys.

#include <cmath>

#include "redres/path.hpp"

namespace redres {
namespace {

constexpr double kPi = 3.14159265358979323846;

const bool kRegistered = path_registry().add({
    "letter_r",
    "the letter R of DESIGN section 5 (stem, bowl, leg)",
    {{"height", "0.15", "letter height h (m)"},
     {"rotation_deg", "180", "rotation of the letter about its origin (deg)"}},
    [](const TableReader& r, const PathContext& /*ctx*/, PathDefaults& defaults) -> std::unique_ptr<PathGeometry> {
      const double h = r.number("height", 0.15);
      if (!(h > 0.0)) r.fail("height", "expected a letter height > 0 m");
      defaults.rotation_deg = 180.0;
      const double c = h / 6.0, rho = h / 4.0;
      auto g = std::make_unique<PathGeometry>();
      g->strokes.push_back({PathSegment::line({0, 0, 0}, {0, h, 0})});
      g->strokes.push_back({PathSegment::line({0, h, 0}, {c, h, 0}),
                            PathSegment::arc({c, 0.75 * h, 0}, rho, kPi / 2.0, -kPi),
                            PathSegment::line({c, h / 2.0, 0}, {0, h / 2.0, 0})});
      g->strokes.push_back({PathSegment::line({0, h / 2.0, 0}, {c + rho, 0, 0})});
      return g;
    },
});

}  // namespace
}  // namespace redres

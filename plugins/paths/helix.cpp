#include "redres/paths/helix.hpp"

#include <cmath>
#include <numbers>

namespace redres {

const Schema<HelixConfig>& HelixConfig::schema() {
  using C = HelixConfig;
  static const Schema<C> s{{field("radius", &C::radius, "m", "radius", greater(0.0)),
                            field("pitch", &C::pitch, "m", "advance along the axis per turn"),
                            field("turns", &C::turns, "", "number of turns",
                                  rule<double>("in (0, 1e6]", [](const double& v) { return v > 0.0 && v <= 1e6; })),
                            field("axis", &C::axis, "", "helix axis (non-zero)")}};
  return s;
}

namespace {

std::unique_ptr<PathGeometry> make_helix(const HelixConfig& c, const PathContext& ctx) {
  if (ctx.dim != 3) throw FieldError("type", "a helix needs a spatial task (3 position rows)");
  Eigen::Vector3d axis(c.axis[0], c.axis[1], c.axis[2]);
  if (!(axis.norm() > 0.0)) throw FieldError("axis", "expected a non-zero axis");
  axis.normalize();
  Eigen::Vector3d e1, e2;
  plane_axes(axis, e1, e2);
  const double two_pi = 2.0 * std::numbers::pi;
  PathSegment s = PathSegment::arc(-c.radius * e1, c.radius, 0.0, two_pi * c.turns, e1, e2);
  s.kind = PathSegment::Kind::kHelix;
  s.axis = axis;
  s.rise = c.pitch * c.turns;
  s.length = c.turns * std::hypot(two_pi * c.radius, c.pitch);
  auto g = std::make_unique<PathGeometry>();
  g->scope = TimingScope::kWhole;
  g->strokes.push_back({s});
  return g;
}

const bool kHelixRegistered = path_registry().add<HelixConfig>(
    "helix", "a helix through the path origin, advancing along `axis` (spatial tasks)", make_helix);

}  // namespace
}  // namespace redres

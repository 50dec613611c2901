#include "redres/paths/circle.hpp"

#include <cmath>
#include <numbers>

namespace redres {

const Schema<CircleConfig>& CircleConfig::schema() {
  using C = CircleConfig;
  static const Schema<C> s{{field("radius", &C::radius, "m", "radius", greater(0.0)),
                            field("turns", &C::turns, "", "number of turns",
                                  rule<double>("in (0, 1e6]", [](const double& v) { return v > 0.0 && v <= 1e6; })),
                            field("start_angle_deg", &C::start_angle_deg, "deg", "angle of the origin on the circle"),
                            field("direction", &C::direction, "", "sense of rotation about the normal"),
                            field("normal", &C::normal, "", "plane normal (spatial tasks)")}};
  return s;
}

namespace {

std::unique_ptr<PathGeometry> make_circle(const CircleConfig& c, const PathContext& ctx) {
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::UnitY();
  if (c.normal) {
    if (ctx.dim != 3) throw FieldError("normal", "is for spatial tasks; a planar circle lies in the x-y plane");
    const Eigen::Vector3d n(c.normal->at(0), c.normal->at(1), c.normal->at(2));
    if (!(n.norm() > 0.0)) throw FieldError("normal", "expected a non-zero normal");
    plane_axes(n.normalized(), e1, e2);
  }
  const double a0 = c.start_angle_deg * std::numbers::pi / 180.0;
  const double sense = c.direction == CircleConfig::Direction::kCcw ? 1.0 : -1.0;
  const Eigen::Vector3d centre = -c.radius * (std::cos(a0) * e1 + std::sin(a0) * e2);
  auto g = std::make_unique<PathGeometry>();
  g->scope = TimingScope::kWhole;
  g->strokes.push_back({PathSegment::arc(centre, c.radius, a0, sense * 2.0 * std::numbers::pi * c.turns, e1, e2)});
  return g;
}

const bool kCircleRegistered = path_registry().add<CircleConfig>(
    "circle", "a circle through the path origin (planar, or in any plane with `normal`)", make_circle);

}  // namespace
}  // namespace redres

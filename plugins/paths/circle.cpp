/// `circle`: a circle that starts at the path origin (so the end effector starts on it). Planar by default; with
/// `normal` it lies in the plane through the origin with that normal (spatial tasks).
/// TOML keys: `radius` (m, default 0.05), `turns` (default 1), `start_angle_deg` (the origin's angle on the
/// circle, default 0: the centre lies at -radius along the first in-plane axis), `direction` ("ccw" or "cw",
/// default "ccw"), `normal` (3 numbers, spatial only).

#include <cmath>

#include <Eigen/Geometry>

#include "redres/path.hpp"

namespace redres {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Orthonormal in-plane axes for a plane normal.
void plane_axes(const Eigen::Vector3d& n, Eigen::Vector3d& e1, Eigen::Vector3d& e2) {
  const Eigen::Vector3d helper = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  e1 = (helper - helper.dot(n) * n).normalized();
  e2 = n.cross(e1);
}

const bool kRegistered = path_registry().add({
    "circle",
    "a circle through the path origin (planar, or in any plane with `normal`)",
    {{"radius", "0.05", "radius (m)"},
     {"turns", "1", "number of turns"},
     {"start_angle_deg", "0", "angle of the origin on the circle (deg)"},
     {"direction", "\"ccw\"", "\"ccw\" or \"cw\" about the normal"},
     {"normal", "[0, 0, 1]", "plane normal (spatial tasks)"}},
    [](const TableReader& r, const PathContext& ctx, PathDefaults& defaults) -> std::unique_ptr<PathGeometry> {
      const double radius = r.number("radius", 0.05);
      const double turns = r.number("turns", 1.0);
      const double a0 = r.number("start_angle_deg", 0.0) * kPi / 180.0;
      const bool ccw = r.choice("direction", {"ccw", "cw"}, "ccw") == "ccw";
      if (!(radius > 0.0)) r.fail("radius", "expected a radius > 0 m");
      if (!(turns > 0.0)) r.fail("turns", "expected turns > 0");
      Eigen::Vector3d e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::UnitY();
      if (r.has("normal")) {
        if (ctx.dim != 3) r.fail("normal", "is for spatial tasks; a planar circle lies in the x-y plane");
        const std::vector<double> v = r.numbers("normal", 3);
        const Eigen::Vector3d n(v[0], v[1], v[2]);
        if (!(n.norm() > 0.0)) r.fail("normal", "expected a non-zero normal");
        plane_axes(n.normalized(), e1, e2);
      }
      defaults.scope = TimingScope::kWhole;
      const Eigen::Vector3d centre = -radius * (std::cos(a0) * e1 + std::sin(a0) * e2);
      auto g = std::make_unique<PathGeometry>();
      g->strokes.push_back({PathSegment::arc(centre, radius, a0, (ccw ? 1.0 : -1.0) * 2.0 * kPi * turns, e1, e2)});
      return g;
    },
});

}  // namespace
}  // namespace redres

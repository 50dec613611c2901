/// `helix`: a helix that starts at the path origin and advances along `axis` (spatial tasks only).
/// TOML keys: `radius` (m, default 0.04), `pitch` (m per turn, default 0.02), `turns` (default 2),
/// `axis` (3 numbers, default [0, 0, 1]).

#include <cmath>

#include <Eigen/Geometry>

#include "redres/path.hpp"

namespace redres {
namespace {

constexpr double kPi = 3.14159265358979323846;

const bool kRegistered = path_registry().add({
    "helix",
    "a helix through the path origin, advancing along `axis` (spatial tasks)",
    {{"radius", "0.04", "radius (m)"},
     {"pitch", "0.02", "advance per turn (m)"},
     {"turns", "2", "number of turns"},
     {"axis", "[0, 0, 1]", "helix axis"}},
    [](const TableReader& r, const PathContext& ctx, PathDefaults& defaults) -> std::unique_ptr<PathGeometry> {
      if (ctx.dim != 3) r.fail("type", "a helix needs a spatial task (3 position rows)");
      const double radius = r.number("radius", 0.04);
      const double pitch = r.number("pitch", 0.02);
      const double turns = r.number("turns", 2.0);
      if (!(radius > 0.0)) r.fail("radius", "expected a radius > 0 m");
      if (!(turns > 0.0)) r.fail("turns", "expected turns > 0");
      Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
      if (r.has("axis")) {
        const std::vector<double> v = r.numbers("axis", 3);
        axis = Eigen::Vector3d(v[0], v[1], v[2]);
        if (!(axis.norm() > 0.0)) r.fail("axis", "expected a non-zero axis");
        axis.normalize();
      }
      const Eigen::Vector3d helper =
          std::abs(axis.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
      const Eigen::Vector3d e1 = (helper - helper.dot(axis) * axis).normalized();
      const Eigen::Vector3d e2 = axis.cross(e1);
      PathSegment s = PathSegment::arc(-radius * e1, radius, 0.0, 2.0 * kPi * turns, e1, e2);
      s.kind = PathSegment::Kind::kHelix;
      s.axis = axis;
      s.rise = pitch * turns;
      s.length = turns * std::hypot(2.0 * kPi * radius, pitch);
      defaults.scope = TimingScope::kWhole;
      auto g = std::make_unique<PathGeometry>();
      g->strokes.push_back({s});
      return g;
    },
});

}  // namespace
}  // namespace redres

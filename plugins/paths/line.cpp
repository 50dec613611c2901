/// `line`: a straight line from the path origin by `delta` (2 numbers for planar tasks, 3 for spatial ones).
/// TOML keys: `delta` (m, required).

#include "redres/path.hpp"

namespace redres {
namespace {

const bool kRegistered = path_registry().add({
    "line",
    "a straight line from the path origin (planar or spatial)",
    {{"delta", "", "displacement from the origin (m): [dx, dy] or [dx, dy, dz]"}},
    [](const TableReader& r, const PathContext& ctx, PathDefaults& /*defaults*/) -> std::unique_ptr<PathGeometry> {
      const std::vector<double> d = r.numbers("delta", static_cast<std::size_t>(ctx.dim));
      const Eigen::Vector3d to(d[0], d[1], ctx.dim == 3 ? d[2] : 0.0);
      if (!(to.norm() > 0.0)) r.fail("delta", "expected a non-zero displacement");
      auto g = std::make_unique<PathGeometry>();
      g->strokes.push_back({PathSegment::line(Eigen::Vector3d::Zero(), to)});
      return g;
    },
});

}  // namespace
}  // namespace redres

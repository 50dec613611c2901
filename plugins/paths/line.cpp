#include "redres/paths/line.hpp"

namespace redres {

const Schema<LineConfig>& LineConfig::schema() {
  static const Schema<LineConfig> s{
      {field("delta", &LineConfig::delta, "m", "displacement from the origin: [dx, dy] or [dx, dy, dz]").required()}};
  return s;
}

namespace {

std::unique_ptr<PathGeometry> make_line(const LineConfig& c, const PathContext& ctx) {
  if (static_cast<int>(c.delta.size()) != ctx.dim) {
    throw FieldError("delta",
                     "expected " + std::to_string(ctx.dim) + " numbers, got " + std::to_string(c.delta.size()));
  }
  const Eigen::Vector3d to(c.delta[0], c.delta[1], ctx.dim == 3 ? c.delta[2] : 0.0);
  if (!(to.norm() > 0.0)) throw FieldError("delta", "expected a non-zero displacement");
  auto g = std::make_unique<PathGeometry>();
  g->strokes.push_back({PathSegment::line(Eigen::Vector3d::Zero(), to)});
  return g;
}

const bool kLineRegistered =
    path_registry().add<LineConfig>("line", "a straight line from the path origin (planar or spatial)", make_line);

}  // namespace
}  // namespace redres

#include "redres/paths/polyline.hpp"

#include <cmath>
#include <numbers>

namespace redres {

const Schema<PolylineSegment>& PolylineSegment::schema() {
  using S = PolylineSegment;
  static const Schema<S> s{
      {field("to", &S::to, "m", "a line to this point").in_group("segment"),
       field("center", &S::center, "m", "an arc about this centre").in_group("segment"),
       field("sweep_deg", &S::sweep_deg, "deg", "the arc's sweep, counter-clockwise for > 0").in_group("segment")},
      [](const S& seg) {
        if (seg.to && (seg.center || seg.sweep_deg)) {
          throw FieldError("to", "expected a line (`to`) or an arc (`center`, `sweep_deg`), not both");
        }
        if (!seg.to && !(seg.center && seg.sweep_deg)) {
          throw FieldError("", "expected `to` (a line) or `center` and `sweep_deg` (an arc)");
        }
      },
      {{"segment", "give `to`, or `center` and `sweep_deg`"}}};
  return s;
}

const Schema<PolylineConfig>& PolylineConfig::schema() {
  using C = PolylineConfig;
  static const Schema<C> s{
      {field("segments", &C::segments, "", "lines {to = [x, y]} and arcs {center = [x, y], sweep_deg = s}").required(),
       field("stop_at_corners", &C::stop_at_corners, "", "each segment drawn from rest to rest")},
      [](const C& c) {
        for (const auto& seg : c.segments) PolylineSegment::schema().validate(seg);
      },
      {}};
  return s;
}

namespace {

std::unique_ptr<PathGeometry> make_polyline(const PolylineConfig& c, const PathContext& ctx) {
  if (ctx.dim != 2) throw FieldError("type", "a polyline is planar; use `line`, `circle` or `helix` for spatial tasks");
  std::vector<PathSegment> all;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < c.segments.size(); ++k) {
    const PolylineSegment& seg = c.segments[k];
    if (seg.to) {
      const Eigen::Vector3d q((*seg.to)[0], (*seg.to)[1], 0.0);
      all.push_back(PathSegment::line(p, q));
      p = q;
    } else {
      const Eigen::Vector3d centre((*seg.center)[0], (*seg.center)[1], 0.0);
      const double radius = (p - centre).norm();
      if (!(radius > 0.0)) {
        throw FieldError("segments",
                         "segment " + std::to_string(k + 1) + ": expected a centre away from the current point");
      }
      const double a0 = std::atan2(p.y() - centre.y(), p.x() - centre.x());
      all.push_back(PathSegment::arc(centre, radius, a0, *seg.sweep_deg * std::numbers::pi / 180.0));
      p = all.back().end();
    }
  }
  return std::make_unique<PathGeometry>(strokes_from(std::move(all), c.stop_at_corners));
}

const bool kPolylineRegistered = path_registry().add<PolylineConfig>(
    "polyline", "planar lines ({to = [x, y]}) and arcs ({center = [x, y], sweep_deg = s}) from the path origin",
    make_polyline);

}  // namespace
}  // namespace redres

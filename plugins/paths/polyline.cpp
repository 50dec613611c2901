/// `polyline`: planar lines and arcs from the path origin. `segments` is an array of inline tables, each either
/// `{ to = [x, y] }` (a line to that point) or `{ center = [x, y], sweep_deg = s }` (an arc about that centre
/// from the current point, counter-clockwise for s > 0). With `stop_at_corners = true` (the default) every
/// segment is its own stroke, drawn from rest to rest; with false the whole polyline is one stroke.
/// TOML keys: `segments` (required), `stop_at_corners` (default true).

#include <cmath>

#include "redres/path.hpp"

namespace redres {
namespace {

constexpr double kPi = 3.14159265358979323846;

const bool kRegistered = path_registry().add({
    "polyline",
    "planar lines ({to = [x, y]}) and arcs ({center = [x, y], sweep_deg = s}) from the path origin",
    {{"segments", "", "array of {to = [x, y]} or {center = [x, y], sweep_deg = s}"},
     {"stop_at_corners", "true", "each segment drawn from rest to rest"}},
    [](const TableReader& r, const PathContext& ctx, PathDefaults& /*defaults*/) -> std::unique_ptr<PathGeometry> {
      if (ctx.dim != 2) r.fail("type", "a polyline is planar; use `line`, `circle` or `helix` for spatial tasks");
      const bool stop = r.boolean("stop_at_corners", true);
      const toml::node* node = r.raw().get("segments");
      (void)r.has("segments");
      const toml::array* arr = node != nullptr ? node->as_array() : nullptr;
      if (arr == nullptr || arr->empty()) r.fail("segments", "expected a non-empty array of inline tables");
      std::vector<PathSegment> all;
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      int k = 0;
      for (const toml::node& el : *arr) {
        ++k;
        const toml::table* t = el.as_table();
        if (t == nullptr) {
          throw ConfigError(location_of(r.file(), el), "polyline segment " + std::to_string(k) +
                                                           ": expected {to = [x, y]} or {center = [x, y], "
                                                           "sweep_deg = s}, got " + describe_type(el));
        }
        const TableReader s(r.file_ptr(), *t, "polyline segment " + std::to_string(k));
        if (s.has("to")) {
          const std::vector<double> to = s.numbers("to", 2);
          const Eigen::Vector3d q(to[0], to[1], 0.0);
          all.push_back(PathSegment::line(p, q));
          p = q;
        } else if (s.has("center")) {
          const std::vector<double> c = s.numbers("center", 2);
          const double sweep = s.number("sweep_deg") * kPi / 180.0;
          const Eigen::Vector3d centre(c[0], c[1], 0.0);
          const double radius = (p - centre).norm();
          if (!(radius > 0.0)) s.fail("center", "expected a centre away from the current point");
          const double a0 = std::atan2(p.y() - centre.y(), p.x() - centre.x());
          all.push_back(PathSegment::arc(centre, radius, a0, sweep));
          p = all.back().end();
        } else {
          s.fail("expected `to` (a line) or `center` and `sweep_deg` (an arc)");
        }
        s.finish();
      }
      return std::make_unique<PathGeometry>(strokes_from(std::move(all), stop));
    },
});

}  // namespace
}  // namespace redres

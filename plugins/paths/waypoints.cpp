#include "redres/paths/waypoints.hpp"

#include "redres/common/csv.hpp"

namespace redres {

const Schema<WaypointsConfig>& WaypointsConfig::schema() {
  using C = WaypointsConfig;
  static const Schema<C> s{
      {field("file", &C::file, "", "CSV file with columns x,y[,z], relative to the scenario").required(),
       field("stop_at_points", &C::stop_at_points, "", "stop at every point")}};
  return s;
}

namespace {

std::unique_ptr<PathGeometry> make_waypoints(const WaypointsConfig& c, const PathContext& ctx) {
  std::vector<std::string> cols = {"x", "y"};
  if (ctx.dim == 3) cols.push_back("z");
  // A file that is missing, not a regular file or empty is reported at the `file` key; an error inside the file
  // is a ConfigError at its own file:line:col.
  const CsvTable csv = [&] {
    try {
      return read_csv(c.file, cols);
    } catch (const ConfigError& e) {
      if (e.where().line == 0) throw FieldError("file", e.what());
      throw;
    }
  }();
  const std::vector<double>& x = csv.column("x");
  const std::vector<double>& y = csv.column("y");
  if (x.size() < 2) throw FieldError("file", "expected at least 2 waypoints in " + csv.path);
  std::vector<PathSegment> all;
  for (std::size_t k = 1; k < x.size(); ++k) {
    const double z0 = ctx.dim == 3 ? csv.column("z")[k - 1] : 0.0;
    const double z1 = ctx.dim == 3 ? csv.column("z")[k] : 0.0;
    const PathSegment s = PathSegment::line({x[k - 1], y[k - 1], z0}, {x[k], y[k], z1});
    if (s.length > 0.0) all.push_back(s);
  }
  auto g = std::make_unique<PathGeometry>(strokes_from(std::move(all), c.stop_at_points));
  return g;
}

const bool kWaypointsRegistered = path_registry().add<WaypointsConfig>(
    "waypoints", "lines through CSV waypoints (columns x,y[,z]), relative to the path origin", make_waypoints);

}  // namespace
}  // namespace redres

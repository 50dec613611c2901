/// `waypoints`: straight lines through points read from a CSV file (columns x,y or x,y,z, in m, relative to
/// the path origin; the path is relative to the file that names it). One stroke by default, so dense smooth
/// data gives a smooth motion; `stop_at_points = true` stops at every waypoint.
/// TOML keys: `file` (required), `stop_at_points` (default false).

#include "redres/csv.hpp"
#include "redres/path.hpp"

namespace redres {
namespace {

const bool kRegistered = path_registry().add({
    "waypoints",
    "lines through CSV waypoints (columns x,y[,z]), relative to the path origin",
    {{"file", "", "CSV file, relative to the scenario file"}, {"stop_at_points", "false", "stop at every point"}},
    [](const TableReader& r, const PathContext& ctx, PathDefaults& /*defaults*/) -> std::unique_ptr<PathGeometry> {
      std::vector<std::string> cols = {"x", "y"};
      if (ctx.dim == 3) cols.push_back("z");
      const CsvTable csv = read_csv(r.path("file"), cols);
      const bool stop = r.boolean("stop_at_points", false);
      const std::vector<double>& x = csv.column("x");
      const std::vector<double>& y = csv.column("y");
      if (x.size() < 2) r.fail("file", "expected at least 2 waypoints in " + csv.path);
      std::vector<PathSegment> all;
      for (std::size_t k = 1; k < x.size(); ++k) {
        const double z0 = ctx.dim == 3 ? csv.column("z")[k - 1] : 0.0;
        const double z1 = ctx.dim == 3 ? csv.column("z")[k] : 0.0;
        const PathSegment s = PathSegment::line({x[k - 1], y[k - 1], z0}, {x[k], y[k], z1});
        if (s.length > 0.0) all.push_back(s);
      }
      return std::make_unique<PathGeometry>(strokes_from(std::move(all), stop));
    },
});

}  // namespace
}  // namespace redres

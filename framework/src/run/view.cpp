#include "redres/run/view.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "common/xml_text.hpp"
#include "redres/common/output_file.hpp"
#include "redres/model/convex.hpp"
#include "redres/model/mesh.hpp"
#include "redres/parsers/mesh_file.hpp"
#include "run/view_assets.hpp"

namespace redres {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

std::string read_file(const fs::path& file, const std::string& what) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(what + ": cannot read " + file.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A run's table as written by redres (docs/output_formats.md): a header, then rows of numbers, `inf` and `nan`
// included (strtod reads them). Every row must have the header's width.
struct Table {
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;
  [[nodiscard]] int index(const std::string& name) const {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? -1 : static_cast<int>(it - names.begin());
  }
};

Table read_table(const fs::path& file) {
  const std::string text = read_file(file, "view");
  Table t;
  std::size_t pos = 0;
  int line = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string row = text.substr(pos, end - pos);
    pos = end + 1;
    ++line;
    if (!row.empty() && row.back() == '\r') row.pop_back();
    if (row.empty()) continue;
    if (t.names.empty()) {
      std::stringstream cells(row);
      for (std::string cell; std::getline(cells, cell, ',');) t.names.push_back(cell);
      continue;
    }
    std::vector<double> values;
    values.reserve(t.names.size());
    const char* p = row.c_str();
    while (true) {
      char* after = nullptr;
      errno = 0;
      const double v = std::strtod(p, &after);
      if (after == p) {
        throw std::runtime_error("view: " + file.string() + ":" + std::to_string(line) + ": column " +
                                 std::to_string(values.size() + 1) + " is not a number");
      }
      values.push_back(v);
      p = after;
      if (*p == ',') {
        ++p;
        continue;
      }
      if (*p != '\0') {
        throw std::runtime_error("view: " + file.string() + ":" + std::to_string(line) + ": unexpected '" +
                                 std::string(1, *p) + "' after column " + std::to_string(values.size()));
      }
      break;
    }
    if (values.size() != t.names.size()) {
      throw std::runtime_error("view: " + file.string() + ":" + std::to_string(line) + ": " +
                               std::to_string(values.size()) + " columns, the header has " +
                               std::to_string(t.names.size()));
    }
    t.rows.push_back(std::move(values));
  }
  if (t.names.empty() || t.rows.empty()) throw std::runtime_error("view: " + file.string() + " holds no rows");
  return t;
}

// A number with `digits` significant digits: nlohmann writes the shortest text that reads back as the double, so
// rounding first keeps the page small. Non-finite numbers become null (JSON has no inf).
json rounded(double v, int digits) {
  if (!std::isfinite(v)) return nullptr;
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return std::strtod(buf, nullptr);
}

// Rows 0, k, 2k, ... and the last, with k the smallest stride that keeps at most `most` rows.
std::vector<std::size_t> decimated(std::size_t rows, int most) {
  const std::size_t m = static_cast<std::size_t>(std::max(2, most));
  std::size_t k = 1;
  while ((rows + k - 1) / k + 1 > m && k < rows) ++k;
  std::vector<std::size_t> out;
  for (std::size_t r = 0; r < rows; r += k) out.push_back(r);
  if (out.back() != rows - 1) out.push_back(rows - 1);
  return out;
}

Eigen::Matrix3d rotation_of(const json& rows) {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (!rows.is_array() || rows.size() != 3) return R;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) R(i, j) = rows[i][j].get<double>();
  }
  return R;
}

json quaternion_json(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  return {rounded(q.x(), 10), rounded(q.y(), 10), rounded(q.z(), 10), rounded(q.w(), 10)};
}

json vec_json(const Eigen::Vector3d& v, int digits = 10) {
  return {rounded(v.x(), digits), rounded(v.y(), digits), rounded(v.z(), digits)};
}

Eigen::Vector3d vec_of(const json& j) {
  if (!j.is_array() || j.size() != 3) return Eigen::Vector3d::Zero();
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

// The hulls of a mesh file's pieces, read once per file (a robot's decomposition names its file once per piece).
struct HullCache {
  std::map<std::string, std::vector<std::pair<std::shared_ptr<const ConvexHull>, Eigen::Vector3d>>> files;
  const std::vector<std::pair<std::shared_ptr<const ConvexHull>, Eigen::Vector3d>>& of(const std::string& file) {
    auto it = files.find(file);
    if (it != files.end()) return it->second;
    std::vector<std::pair<std::shared_ptr<const ConvexHull>, Eigen::Vector3d>> hulls;
    const MeshData mesh = read_mesh(file, Eigen::Vector3d::Ones());
    for (std::size_t p = 0; p < mesh.pieces.size(); ++p) {
      Eigen::Vector3d centre;
      try {
        hulls.emplace_back(convex_hull(mesh.pieces[p], file, centre), centre);
      } catch (const std::invalid_argument&) {
        // a flat piece: robot files refuse it, so no recorded hull can be it
      }
    }
    return files.emplace(file, std::move(hulls)).first->second;
  }
};

// One shape (a link's or an obstacle's) for the page: its kind and sizes, its pose in its frame. A convex shape
// gets its hull's vertices and faces, made again from the mesh it names (the hull whose counts and bounding box are
// those recorded: a decomposition's pieces are told apart by them); without the mesh it is drawn as its bounding
// box, and a note says so.
json shape_for_page(const json& s, HullCache& hulls, std::vector<std::string>& notes, const std::string& owner) {
  json out = {{"shape", s.value("shape", "")}};
  for (const char* key : {"radius", "length"}) {
    if (s.contains(key)) out[key] = rounded(s[key].get<double>(), 10);
  }
  if (s.contains("size")) out["size"] = vec_json(vec_of(s["size"]));
  out["position"] = vec_json(vec_of(s.value("position", json::array({0.0, 0.0, 0.0}))));
  out["quaternion"] = quaternion_json(rotation_of(s.value("rotation", json())));
  if (s.contains("velocity")) out["velocity"] = vec_json(vec_of(s["velocity"]));
  const std::string kind = out["shape"];
  if (kind == "convex") {
    const std::string file = s.value("file", "");
    const std::size_t nv = s.value("vertices", std::size_t{0});
    const Eigen::Vector3d size = s.contains("size") ? vec_of(s["size"]) : Eigen::Vector3d::Zero();
    std::shared_ptr<const ConvexHull> found;
    try {
      for (const auto& [hull, centre] : hulls.of(file)) {
        if (hull->vertices.size() == nv && (2.0 * hull->half_extent - size).cwiseAbs().maxCoeff() < 1e-9) {
          found = hull;
          break;
        }
      }
    } catch (const std::exception& e) {
      notes.push_back(owner + ": its hull's mesh cannot be read (" + std::string(e.what()) +
                      "); drawn as its bounding box");
    }
    if (found) {
      json v = json::array();
      for (const Eigen::Vector3d& p : found->vertices) {
        for (int i = 0; i < 3; ++i) v.push_back(rounded(p(i), 7));
      }
      json f = json::array();
      for (const auto& face : found->faces) {
        for (const int i : face) f.push_back(i);
      }
      out["vertices"] = std::move(v);
      out["faces"] = std::move(f);
    } else {
      if (notes.empty() || notes.back().rfind(owner, 0) != 0) {
        notes.push_back(owner + ": no piece of " + file + " has the recorded hull; drawn as its bounding box");
      }
      out["shape"] = "box";
    }
  }
  if (kind == "points" || kind == "octree") {
    // The occupied cells summary.json keeps (centre x, y, z and edge, in the cloud's frame), each grown by radius.
    json cells = json::array();
    for (const auto& c : s.value("cells", json::array())) {
      for (int i = 0; i < 4; ++i) cells.push_back(rounded(c[i].get<double>(), 6));
    }
    out["cells"] = std::move(cells);
    out["cells_total"] = s.value("cells_total", std::size_t{0});
  }
  return out;
}

// A series of the plots: the column's values at the kept rows.
json column_json(const Table& t, int col, const std::vector<std::size_t>& rows, int digits = 7) {
  json out = json::array();
  for (const std::size_t r : rows) out.push_back(rounded(t.rows[r][static_cast<std::size_t>(col)], digits));
  return out;
}

std::string base64(const void* bytes, std::size_t size) {
  static const char* const digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* b = static_cast<const unsigned char*>(bytes);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  for (std::size_t i = 0; i < size; i += 3) {
    const unsigned v = (unsigned{b[i]} << 16) | (i + 1 < size ? unsigned{b[i + 1]} << 8 : 0U) |
                       (i + 2 < size ? unsigned{b[i + 2]} : 0U);
    out += digits[(v >> 18) & 63];
    out += digits[(v >> 12) & 63];
    out += i + 1 < size ? digits[(v >> 6) & 63] : '=';
    out += i + 2 < size ? digits[v & 63] : '=';
  }
  return out;
}

// The visual meshes of every run, read once each (keyed by file and scale) and shared by the runs and frames that
// draw them: per part its colour and its triangles as little-endian float32 positions and uint16 (or, past 65,536
// vertices, uint32) indices, base64.
struct DrawMeshes {
  json meshes = json::object();
  std::size_t triangles = 0;
  // The key of the mesh (read now if new); empty when it cannot be read (a note says why).
  std::string add(const std::string& file, const Eigen::Vector3d& scale, std::vector<std::string>& notes,
                  const std::string& owner) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "|%.9g,%.9g,%.9g", scale.x(), scale.y(), scale.z());
    const std::string key = file + buf;
    if (meshes.contains(key)) return key;
    try {
      const DrawMesh mesh = read_draw_mesh(file, scale);
      json parts = json::array();
      for (const DrawMesh::Part& p : mesh.parts) {
        json part = {{"positions", base64(p.positions.data(), p.positions.size() * sizeof(float))}};
        if (p.positions.size() / 3 <= 65536) {  // 16-bit indices where they reach every vertex: half the size
          const std::vector<std::uint16_t> small(p.indices.begin(), p.indices.end());
          part["indices16"] = base64(small.data(), small.size() * sizeof(std::uint16_t));
        } else {
          part["indices"] = base64(p.indices.data(), p.indices.size() * sizeof(std::uint32_t));
        }
        if (p.coloured) part["colour"] = {p.colour[0], p.colour[1], p.colour[2]};
        parts.push_back(std::move(part));
      }
      triangles += mesh.triangles();
      meshes[key] = {{"file", file}, {"parts", std::move(parts)}};
      return key;
    } catch (const std::exception& e) {
      notes.push_back(owner + ": " + e.what() + "; not drawn");
      return "";
    }
  }
};

fs::path in_run(const fs::path& dir, const char* name) {
  const fs::path file = dir / name;
  if (fs::exists(file)) return file;
  std::string why = "view: " + dir.string() + " has no " + name;
  if (fs::exists(dir / "trajectory.h5")) {
    why += " (the run wrote trajectory.h5, --format hdf5: run it again with the CSV format to view it)";
  } else if (fs::exists(dir / "summary.json")) {
    why += " (a run with --record none keeps no rows to replay: run it again with --record all or every=N)";
  } else {
    why += " (not a run's directory: redres run --out DIR writes summary.json, trajectory.csv and frames.csv)";
  }
  throw std::runtime_error(why);
}

json run_json(const fs::path& dir, const ViewOptions& options, HullCache& hulls, DrawMeshes& draw, ViewReport& report) {
  const fs::path summary_file = in_run(dir, "summary.json");
  json summary;
  try {
    summary = json::parse(read_file(summary_file, "view"));
  } catch (const json::exception& e) {
    throw std::runtime_error("view: " + summary_file.string() + " is not JSON: " + e.what());
  }
  const Table frames = read_table(in_run(dir, "frames.csv"));
  const Table traj = read_table(in_run(dir, "trajectory.csv"));
  const json& robot = summary.value("robot", json::object());
  const std::vector<std::string> joint_names = robot.value("joint_names", std::vector<std::string>{});
  const int n = static_cast<int>(joint_names.size());
  if (n == 0) throw std::runtime_error("view: " + summary_file.string() + " names no joints (robot.joint_names)");
  const std::string name = summary.value("name", dir.filename().string());
  json run = {{"name", name},
              {"label", summary.value("label", name)},
              {"dir", dir.string()},
              {"kind", robot.value("kind", "spatial")},
              {"joint_names", joint_names},
              {"status", summary.value("status", "")},
              {"duration", summary.value("duration", 0.0)}};
  run["lower_limits"] = robot.value("lower_limits", json::array());
  run["upper_limits"] = robot.value("upper_limits", json::array());
  run["base_position"] = robot.value("base_position", json::array({0.0, 0.0, 0.0}));

  // The 3-D frames: every row of frames.csv, each joint's origin and rotation (as a quaternion) and the end effector.
  std::vector<int> cols;
  for (int j = 1; j <= n; ++j) {
    const std::string p = "joint_" + std::to_string(j) + "_";
    for (const char* c : {"x", "y", "z", "r11", "r12", "r13", "r21", "r22", "r23", "r31", "r32", "r33"}) {
      const int i = frames.index(p + c);
      if (i < 0) throw std::runtime_error("view: " + (dir / "frames.csv").string() + " has no column " + p + c);
      cols.push_back(i);
    }
  }
  const int ee[3] = {frames.index("ee_x"), frames.index("ee_y"), frames.index("ee_z")};
  const int ft = frames.index("t");
  if (ft < 0 || ee[0] < 0 || ee[1] < 0 || ee[2] < 0) {
    throw std::runtime_error("view: " + (dir / "frames.csv").string() + " lacks t or ee_x, ee_y, ee_z");
  }
  json times = json::array(), poses = json::array(), ees = json::array();
  for (const auto& row : frames.rows) {
    times.push_back(rounded(row[static_cast<std::size_t>(ft)], 12));
    for (int j = 0; j < n; ++j) {
      const int* c = &cols[static_cast<std::size_t>(12 * j)];
      Eigen::Matrix3d R;
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) R(a, b) = row[static_cast<std::size_t>(c[3 + 3 * a + b])];
      }
      const Eigen::Vector3d o(row[static_cast<std::size_t>(c[0])], row[static_cast<std::size_t>(c[1])],
                              row[static_cast<std::size_t>(c[2])]);
      for (const auto& v : vec_json(o)) poses.push_back(v);
      for (const auto& v : quaternion_json(R)) poses.push_back(v);
    }
    for (const int c : ee) ees.push_back(rounded(row[static_cast<std::size_t>(c)], 10));
  }
  // The end effector in the last joint's frame: fixed, so the page places it from that frame (and a test can check
  // that the page's poses put it where the run recorded it).
  {
    const auto& row = frames.rows.front();
    const int* c = &cols[static_cast<std::size_t>(12 * (n - 1))];
    Eigen::Matrix3d R;
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) R(a, b) = row[static_cast<std::size_t>(c[3 + 3 * a + b])];
    }
    const Eigen::Vector3d o(row[static_cast<std::size_t>(c[0])], row[static_cast<std::size_t>(c[1])],
                            row[static_cast<std::size_t>(c[2])]);
    const Eigen::Vector3d e(row[static_cast<std::size_t>(ee[0])], row[static_cast<std::size_t>(ee[1])],
                            row[static_cast<std::size_t>(ee[2])]);
    run["tool"] = vec_json(R.transpose() * (e - o), 12);
  }
  run["frames"] = {{"t", times}, {"poses", poses}, {"ee", ees}};
  report.frames = std::max(report.frames, static_cast<int>(frames.rows.size()));

  // The robot's shapes, posed in their joints' frames.
  json shapes = json::array();
  int index = 0;
  for (const auto& s : robot.value("link_shapes", json::array())) {
    json shape = shape_for_page(s, hulls, report.notes, name + ": link shape " + std::to_string(++index));
    shape["joint"] = s.value("joint", 1);
    shapes.push_back(std::move(shape));
  }
  run["link_shapes"] = std::move(shapes);
  json obstacles = json::array();
  index = 0;
  for (const auto& o : summary.value("obstacles", json::array())) {
    json shape = shape_for_page(o, hulls, report.notes, name + ": obstacle " + std::to_string(++index));
    shape["plugin"] = o.value("plugin", "");
    obstacles.push_back(std::move(shape));
  }
  report.bodies += static_cast<int>(run["link_shapes"].size() + obstacles.size());
  // A URDF robot's visual elements: meshes (shared), boxes, cylinders, spheres.
  json visuals = json::array();
  index = 0;
  for (const auto& v : robot.value("visuals", json::array())) {
    ++index;
    json out = {{"joint", v.value("joint", 0)},
                {"shape", v.value("shape", "mesh")},
                {"position", vec_json(vec_of(v.value("position", json::array({0.0, 0.0, 0.0}))))},
                {"quaternion", quaternion_json(rotation_of(v.value("rotation", json())))}};
    if (v.contains("rgba")) out["rgba"] = v["rgba"];
    if (out["shape"] == "mesh") {
      const std::string who = name + ": visual " + std::to_string(index) + " (link '" + v.value("link", "") + "')";
      if (v.contains("problem")) {
        report.notes.push_back(who + ": " + v["problem"].get<std::string>() + "; not drawn");
        continue;
      }
      const std::string key =
          draw.add(v.value("file", ""), vec_of(v.value("scale", json::array({1.0, 1.0, 1.0}))), report.notes, who);
      if (key.empty()) continue;
      out["mesh"] = key;
    } else {
      for (const char* k : {"size", "radius", "length"}) {
        if (v.contains(k)) out[k] = v[k];
      }
    }
    visuals.push_back(std::move(out));
  }
  report.visuals += static_cast<int>(visuals.size());
  run["visuals"] = std::move(visuals);
  run["obstacles"] = std::move(obstacles);

  // The plots' series, at most max_plot_points rows of trajectory.csv.
  const std::vector<std::size_t> rows = decimated(traj.rows.size(), options.max_plot_points);
  json series = json::object();
  const int tt = traj.index("t");
  if (tt < 0) throw std::runtime_error("view: " + (dir / "trajectory.csv").string() + " has no column t");
  series["t"] = column_json(traj, tt, rows, 12);
  for (std::size_t c = 0; c < traj.names.size(); ++c) {
    const std::string& col = traj.names[c];
    static const char* const kept_prefixes[] = {"theta_",  "vel_lo_", "vel_hi_", "acc_lo_",
                                                "acc_hi_", "torque_", "rd_",     "r_"};
    static const char* const kept[] = {
        "manipulability",        "position_error",    "orientation_error", "solver_status",
        "min_obstacle_distance", "min_self_distance", "contacts",          "penetration"};
    bool keep =
        std::find_if(std::begin(kept), std::end(kept), [&](const char* k) { return col == k; }) != std::end(kept);
    for (const char* p : kept_prefixes) keep = keep || col.rfind(p, 0) == 0;
    if (col.rfind("measured_", 0) == 0) keep = true;
    if (keep) series[col] = column_json(traj, static_cast<int>(c), rows);
  }
  run["series"] = std::move(series);
  run["task_rows"] = robot.value("task_rows", json::array());
  // The safety distances the distance plot draws.
  json limits = json::object();
  const json& metrics = summary.value("metrics", json::object());
  for (const auto& [plugin, figures] : metrics.items()) {
    if (figures.is_object() && figures.contains("safety_distance")) limits[plugin] = figures["safety_distance"];
  }
  run["safety_distances"] = std::move(limits);
  if (summary.contains("path")) run["path"] = summary["path"];
  return run;
}

fs::path three_directory(const ViewOptions& options) {
  if (!options.three_dir.empty()) return options.three_dir;
  if (const char* env = std::getenv("REDRES_THREE_DIR"); env != nullptr && *env != '\0') return env;
  return "/usr/share/javascript/three";
}

// Text for inside a <script> element: "</" cannot end it early.
std::string script_safe(std::string text) {
  for (std::size_t p = text.find("</"); p != std::string::npos; p = text.find("</", p + 3)) text.insert(p + 1, "\\");
  return text;
}

void replace_once(std::string& text, const std::string& marker, const std::string& with) {
  const std::size_t p = text.find(marker);
  if (p == std::string::npos) throw std::logic_error("view: the page template lacks " + marker);
  text.replace(p, marker.size(), with);
}

}  // namespace

std::string view_data(const std::vector<fs::path>& run_dirs, const ViewOptions& options, ViewReport& report) {
  if (run_dirs.empty()) throw std::invalid_argument("view: no run directory given");
  if (options.max_plot_points < 2) throw std::invalid_argument("view: max_plot_points must be at least 2");
  HullCache hulls;
  DrawMeshes draw;
  json runs = json::array();
  for (const fs::path& dir : run_dirs) runs.push_back(run_json(dir, options, hulls, draw, report));
  report.visual_triangles = draw.triangles;
  report.runs = static_cast<int>(runs.size());
  std::string title = options.title;
  if (title.empty()) {
    for (const auto& r : runs) title += (title.empty() ? "" : " vs ") + r["label"].get<std::string>();
  }
  report.title = title;
  json data = {{"format", 1},
               {"title", title},
               {"runs", std::move(runs)},
               {"meshes", std::move(draw.meshes)},
               {"notes", report.notes}};
  return data.dump();
}

std::string view_html(const std::vector<fs::path>& run_dirs, const ViewOptions& options, ViewReport& report) {
  const fs::path dir = three_directory(options);
  const fs::path three = dir / "build" / "three.min.js";
  const fs::path orbit = dir / "examples" / "js" / "controls" / "OrbitControls.js";
  for (const fs::path& f : {three, orbit}) {
    if (!fs::exists(f)) {
      throw std::runtime_error("view: " + f.string() +
                               " not found: the page inlines three.js from Debian's libjs-three (apt-get install "
                               "libjs-three), or from the directory REDRES_THREE_DIR names");
    }
  }
  const std::string data = view_data(run_dirs, options, report);
  std::string page = view_assets::kPage;
  replace_once(page, "/*REDRES_THREE*/", script_safe(read_file(three, "view")));
  replace_once(page, "/*REDRES_ORBIT*/", script_safe(read_file(orbit, "view")));
  replace_once(page, "/*REDRES_VIEWER*/", script_safe(view_assets::kScript));
  replace_once(page, "/*REDRES_DATA*/", script_safe(data));
  replace_once(page, "REDRES_TITLE", xml_escaped(report.title));
  return page;
}

ViewReport write_view(const std::vector<fs::path>& run_dirs, const fs::path& file, const ViewOptions& options,
                      bool replace) {
  ViewReport report;
  const std::string page = view_html(run_dirs, options, report);
  std::error_code ec;
  const auto status = fs::symlink_status(file, ec);
  if (!ec && fs::exists(status)) {
    require_replaceable(file, "view");
    if (!replace) {
      throw std::runtime_error("view: " + file.string() +
                               " exists; a view replaces nothing that redres did not "
                               "write: remove it or name another file");
    }
  }
  write_text_file(file, page);
  report.file = file;
  report.bytes = fs::file_size(file);
  return report;
}

}  // namespace redres

// Reading the files of cloud obstacles (redres/parsers/cloud_file.hpp): OctoMap's octrees (.bt, .ot) and point clouds
// (.ply through Assimp, .pcd, .xyz), each checked as it is read; the model puts what they hold into an OccupancyMap
// (occupancy_of_points(), occupancy_of_octree()). Every problem is a std::invalid_argument naming the file, and the
// line or byte.

#include "redres/parsers/cloud_file.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include "common/input_file.hpp"
#include "redres/common/error.hpp"
#include "redres/model/collision.hpp"

namespace redres {

namespace {

// Cloud files may be large (a depth camera's frame is some 10 MB as text): read whole, up to 1 GiB.
constexpr std::uintmax_t kMaxCloudBytes = std::uintmax_t{1} << 30;

[[noreturn]] void fail_line(const std::filesystem::path& file, std::size_t line, const std::string& what) {
  throw std::invalid_argument(file.string() + ":" + std::to_string(line) + ": " + what);
}

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw std::invalid_argument(file.string() + ": " + what);
}

std::string lower_extension(const std::filesystem::path& file) {
  std::string e = file.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

std::string read_cloud_file(const std::filesystem::path& file) {
  try {
    return read_input_file(file, "cloud file", kMaxCloudBytes);
  } catch (const ConfigError& e) {
    fail(file, e.detail());
  }
}

// Splits a line into tokens at blanks and commas.
int split(std::string_view line, std::string_view* out, int max) {
  int n = 0;
  std::size_t i = 0;
  while (i < line.size() && n < max) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == ',' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && !(line[i] == ' ' || line[i] == '\t' || line[i] == ',' || line[i] == '\r')) ++i;
    if (i > start) out[n++] = line.substr(start, i - start);
  }
  return n;
}

bool number(std::string_view token, double& v) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
  return ec == std::errc() && end == token.data() + token.size();
}

// Calls f(line number, content) for each line of `text` while f returns true.
template <class F>
void for_each_line(std::string_view text, F&& f) {
  std::size_t line = 0, pos = 0;
  while (pos < text.size()) {
    ++line;
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    if (!f(line, text.substr(pos, end - pos))) return;
    pos = end + 1;
  }
}

// .xyz: one point a line, x y z first (further columns, such as normals or colours, are ignored), separated by blanks
// or commas; '#' starts a comment.
std::vector<Eigen::Vector3d> read_xyz(const std::filesystem::path& file, const std::string& text) {
  std::vector<Eigen::Vector3d> points;
  for_each_line(text, [&](std::size_t line, std::string_view s) {
    if (const auto hash = s.find('#'); hash != std::string_view::npos) s = s.substr(0, hash);
    std::array<std::string_view, 3> tok;
    const int n = split(s, tok.data(), 3);
    if (n == 0) return true;
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) {
      if (k >= n || !number(tok[static_cast<std::size_t>(k)], p(k))) {
        fail_line(file, line, "expected the numbers x y z, saw '" + std::string(s.substr(0, 60)) + "'");
      }
    }
    if (!p.allFinite()) fail_line(file, line, "a coordinate is not finite");
    points.push_back(p);
    return true;
  });
  return points;
}

// .pcd (the Point Cloud Library's format, version 0.7): a text header, then the points as ascii or binary. Fields x, y
// and z must be floating point (F, 4 or 8 bytes); other fields are skipped. Points with a NaN coordinate are PCL's
// "no return" and are left out. binary_compressed (LZF) is not read.
std::vector<Eigen::Vector3d> read_pcd(const std::filesystem::path& file, const std::string& text) {
  std::vector<std::string> fields;
  std::vector<int> sizes, counts;
  std::vector<char> types;
  long points_declared = -1;
  std::string data;
  std::size_t pos = 0, line = 0;
  while (data.empty()) {
    if (pos >= text.size()) fail(file, "the header ends before its DATA line");
    ++line;
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    std::string_view s(text.data() + pos, end - pos);
    pos = std::min(end + 1, text.size());
    if (const auto hash = s.find('#'); hash != std::string_view::npos) s = s.substr(0, hash);
    std::array<std::string_view, 65> tok;
    const int n = split(s, tok.data(), 65);
    if (n == 0) continue;
    if (n > 64) fail_line(file, line, "more than 63 fields on a header line are not read");
    const std::string key(tok[0]);
    std::vector<std::string> values;
    for (int k = 1; k < n; ++k) values.emplace_back(tok[static_cast<std::size_t>(k)]);
    const auto integers = [&](std::vector<int>& out) {
      for (const std::string& v : values) {
        int x = 0;
        const auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
        if (ec != std::errc() || p != v.data() + v.size() || x <= 0) {
          fail_line(file, line, key + ": expected positive integers, saw '" + v + "'");
        }
        out.push_back(x);
      }
    };
    if (key == "FIELDS") {
      fields = values;
    } else if (key == "SIZE") {
      integers(sizes);
    } else if (key == "COUNT") {
      integers(counts);
    } else if (key == "TYPE") {
      for (const std::string& v : values) types.push_back(v.empty() ? '?' : v[0]);
    } else if (key == "POINTS") {
      std::vector<int> p;
      integers(p);
      if (p.size() != 1) fail_line(file, line, "POINTS: expected one count");
      points_declared = p[0];
    } else if (key == "DATA") {
      if (values.size() != 1) fail_line(file, line, "DATA: expected ascii, binary or binary_compressed");
      data = values[0];
      if (data == "binary_compressed") {
        fail_line(file, line,
                  "DATA binary_compressed (LZF) is not read: save the cloud as `binary` or `ascii` (PCL's "
                  "pcl_convert_pcd_ascii_binary does)");
      }
      if (data != "ascii" && data != "binary") fail_line(file, line, "DATA: expected ascii or binary, saw " + data);
    }
  }
  if (fields.empty()) fail(file, "the header has no FIELDS line");
  if (counts.empty()) counts.assign(fields.size(), 1);
  if (sizes.size() != fields.size() || types.size() != fields.size() || counts.size() != fields.size()) {
    fail(file, "FIELDS, SIZE, TYPE and COUNT must list as many entries (" + std::to_string(fields.size()) + " fields)");
  }
  if (points_declared < 0) fail(file, "the header has no POINTS line");
  // Each field's first value: its column (ascii) and byte offset (binary).
  std::array<long, 3> column{-1, -1, -1}, offset{-1, -1, -1}, size{0, 0, 0};
  long columns = 0, bytes = 0;
  for (std::size_t f = 0; f < fields.size(); ++f) {
    // PCD's sizes are 1, 2, 4 or 8 bytes; a count past 4096 is no point cloud. Checked first, so the sums below stay
    // small (at most 63 fields).
    if (sizes[f] > 8 || counts[f] > 4096) {
      fail(file, "field " + fields[f] + ": SIZE " + std::to_string(sizes[f]) + " and COUNT " +
                     std::to_string(counts[f]) + " are not read (a point of more than 4096 values is not read)");
    }
    const int axis = fields[f] == "x" ? 0 : fields[f] == "y" ? 1 : fields[f] == "z" ? 2 : -1;
    if (axis >= 0) {
      if (types[f] != 'F' || (sizes[f] != 4 && sizes[f] != 8)) {
        fail(file, "field " + fields[f] + " must be floating point (TYPE F, SIZE 4 or 8)");
      }
      column[static_cast<std::size_t>(axis)] = columns;
      offset[static_cast<std::size_t>(axis)] = bytes;
      size[static_cast<std::size_t>(axis)] = sizes[f];
    }
    columns += counts[f];
    bytes += static_cast<long>(sizes[f]) * counts[f];
  }
  if (column[0] < 0 || column[1] < 0 || column[2] < 0) fail(file, "FIELDS must include x, y and z");
  if (columns > 4096 || bytes > 65536) fail(file, "a point of more than 4096 values or 65536 bytes is not read");
  std::vector<Eigen::Vector3d> points;
  if (data == "binary") {
    // The declared points must fit in the data (checked before anything is reserved for them).
    const auto have = static_cast<unsigned long long>(text.size() - pos);
    const unsigned long long need =
        static_cast<unsigned long long>(points_declared) * static_cast<unsigned long long>(bytes);
    if (have < need) {
      fail(file, "the binary data holds " + std::to_string(text.size() - pos) + " bytes; POINTS " +
                     std::to_string(points_declared) + " of " + std::to_string(bytes) + " bytes need " +
                     std::to_string(need));
    }
    points.reserve(static_cast<std::size_t>(points_declared));
    for (long i = 0; i < points_declared; ++i) {
      const char* record = text.data() + pos + static_cast<std::size_t>(i) * static_cast<std::size_t>(bytes);
      Eigen::Vector3d p;
      for (std::size_t k = 0; k < 3; ++k) {
        if (size[k] == 4) {
          float v = 0.0F;
          std::memcpy(&v, record + offset[k], 4);
          p(static_cast<Eigen::Index>(k)) = static_cast<double>(v);
        } else {
          std::memcpy(&p(static_cast<Eigen::Index>(k)), record + offset[k], 8);
        }
      }
      if (p.hasNaN()) continue;
      if (!p.allFinite()) fail(file, "point " + std::to_string(i + 1) + " has an infinite coordinate");
      points.push_back(p);
    }
    return points;
  }
  long read = 0;
  const std::size_t header_lines = line;
  std::vector<std::string_view> tok(static_cast<std::size_t>(columns) + 1);
  for_each_line(std::string_view(text).substr(std::min(pos, text.size())), [&](std::size_t l, std::string_view s) {
    const int n = split(s, tok.data(), static_cast<int>(columns) + 1);
    if (n == 0) return true;
    if (n != columns) {
      fail_line(file, header_lines + l,
                "expected " + std::to_string(columns) + " values (FIELDS and COUNT), saw " + std::to_string(n));
    }
    Eigen::Vector3d p;
    for (std::size_t k = 0; k < 3; ++k) {
      const std::string_view t = tok[static_cast<std::size_t>(column[k])];  // column < columns = n
      if (t == "nan" || t == "NaN" || t == "-nan") {
        p(static_cast<Eigen::Index>(k)) = std::nan("");
      } else if (!number(t, p(static_cast<Eigen::Index>(k)))) {
        fail_line(file, header_lines + l, "expected a number, saw '" + std::string(t) + "'");
      }
    }
    ++read;
    if (p.hasNaN()) return true;
    if (!p.allFinite()) fail_line(file, header_lines + l, "a coordinate is infinite");
    points.push_back(p);
    return true;
  });
  if (read != points_declared) {
    fail(file, "POINTS says " + std::to_string(points_declared) + " points, the data holds " + std::to_string(read));
  }
  return points;
}

// .ply through Assimp (ascii and binary, either byte order). Assimp fills a missing coordinate with 0, so the header
// is checked first: its vertex element must have x, y and z properties.
std::vector<Eigen::Vector3d> read_ply(const std::filesystem::path& file, const std::string& text) {
  const std::size_t end = text.find("end_header");
  if (text.rfind("ply", 0) != 0 || end == std::string::npos) fail(file, "not a PLY file (no `ply` ... `end_header`)");
  bool in_vertex = false;
  std::array<bool, 3> has{false, false, false};
  for_each_line(std::string_view(text).substr(0, end), [&](std::size_t, std::string_view s) {
    std::array<std::string_view, 8> tok;
    const int n = split(s, tok.data(), 8);
    if (n >= 2 && tok[0] == "element") in_vertex = tok[1] == "vertex";
    if (in_vertex && n >= 3 && tok[0] == "property") {
      const std::string_view name = tok[static_cast<std::size_t>(n - 1)];
      if (name.size() == 1 && name[0] >= 'x' && name[0] <= 'z') has[static_cast<std::size_t>(name[0] - 'x')] = true;
    }
    return true;
  });
  if (!has[0] || !has[1] || !has[2]) fail(file, "the PLY header's `element vertex` needs properties x, y and z");
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFileFromMemory(text.data(), text.size(), 0, "ply");
  if (scene == nullptr) fail(file, std::string("Assimp could not read it: ") + importer.GetErrorString());
  std::vector<Eigen::Vector3d> points;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& a = mesh->mVertices[v];
      const Eigen::Vector3d p(static_cast<double>(a.x), static_cast<double>(a.y), static_cast<double>(a.z));
      if (!p.allFinite()) fail(file, "vertex " + std::to_string(v + 1) + " has a coordinate that is not finite");
      points.push_back(p);
    }
  }
  return points;
}

// OctoMap's files: a text header ("# Octomap OcTree binary file" or "# Octomap OcTree file", comment lines, then `id`,
// `size`, `res` and `data` lines), then the nodes, which OccupancyMap's octree reader takes (occupancy_of_octree()).
std::shared_ptr<const OccupancyMap> read_octree(const std::filesystem::path& file, const std::string& text, bool binary,
                                                double grow) {
  const std::string_view first = binary ? "# Octomap OcTree binary file" : "# Octomap OcTree file";
  if (text.rfind(first, 0) != 0)
    fail(file, "not an OctoMap " + std::string(binary ? ".bt" : ".ot") + " file (its first line is not '" +
                   std::string(first) + "')");
  std::string id;
  double res = 0.0;
  long size = -1;
  std::size_t pos = 0, line = 0;
  bool data = false;
  while (!data) {
    if (pos >= text.size()) fail(file, "the header ends before its `data` line");
    ++line;
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    std::string_view s(text.data() + pos, end - pos);
    pos = std::min(end + 1, text.size());
    if (!s.empty() && s.back() == '\r') s.remove_suffix(1);
    if (s.empty() || s.front() == '#') continue;
    std::array<std::string_view, 3> tok;
    const int n = split(s, tok.data(), 3);
    if (tok[0] == "data" && n == 1) {
      data = true;
    } else if (tok[0] == "id" && n == 2) {
      id = std::string(tok[1]);
    } else if (tok[0] == "res" && n == 2 && number(tok[1], res)) {
      if (!(std::isfinite(res) && res >= 1e-4 && res <= 100.0))
        fail_line(file, line, "res: expected a cell edge in [1e-4, 100] m");
    } else if (tok[0] == "size" && n == 2) {
      double v = 0.0;
      if (!number(tok[1], v) || !(v >= 0.0 && v < 1e12)) fail_line(file, line, "size: expected a node count");
      size = static_cast<long>(v);
    } else {
      fail_line(file, line, "expected `id`, `size`, `res` or `data`, saw '" + std::string(s.substr(0, 60)) + "'");
    }
  }
  if (id != "OcTree") fail(file, "holds an octree of type '" + id + "'; an occupancy octree (id OcTree) is read");
  if (!(res > 0.0)) fail(file, "the header gives no `res`");
  try {
    return occupancy_of_octree(std::string_view(text).substr(pos), binary, res, size, grow);
  } catch (const std::invalid_argument& e) {
    fail(file, e.what());
  }
}

}  // namespace

std::vector<Eigen::Vector3d> read_points(const std::filesystem::path& file) {
  const std::string ext = lower_extension(file);
  if (ext != ".ply" && ext != ".pcd" && ext != ".xyz") {
    fail(file, "a point cloud is read from a .ply, .pcd or .xyz file (saw '" + ext + "')");
  }
  const std::string text = read_cloud_file(file);
  if (ext == ".ply") return read_ply(file, text);
  if (ext == ".pcd") return read_pcd(file, text);
  return read_xyz(file, text);
}

void load_cloud(ShapeSpec& spec) {
  if (spec.cloud || !spec.is_cloud()) return;
  if (!spec.file || spec.file->empty()) throw std::invalid_argument("a cloud obstacle needs `file`");
  const std::filesystem::path& file = *spec.file;
  const double grow = spec.radius.value_or(0.0);
  if (spec.shape == ShapeSpec::Kind::kOctree) {
    const std::string ext = lower_extension(file);
    if (ext != ".bt" && ext != ".ot")
      fail(file, "an octree is read from an OctoMap .bt or .ot file (saw '" + ext + "')");
    spec.cloud = read_octree(file, read_cloud_file(file), ext == ".bt", grow);
  } else {
    const std::vector<Eigen::Vector3d> points = read_points(file);
    if (points.empty()) fail(file, "holds no points");
    try {
      spec.cloud = occupancy_of_points(points, *spec.resolution, grow);
    } catch (const std::invalid_argument& e) {
      fail(file, e.what());
    }
  }
}

}  // namespace redres

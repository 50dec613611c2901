// The files of cloud obstacles (redres/parsers/cloud_file.hpp): every format reads the same points as written; bad
// files are reported with the file and the line or byte; OctoMap's files are checked before OctoMap reads them; a
// malformed .pcd header is refused before its data is read.

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "cloud_samples.hpp"
#include "redres/model/collision.hpp"
#include "redres/parsers/cloud_file.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

using testing::cloud_spec;
using testing::sample_cloud;
using testing::write_xyz;

// What read_points says of a file `name` in `dir` holding `text` ("no error" when it reads it).
std::string read_error(const std::filesystem::path& dir, const std::string& name, const std::string& text) {
  std::ofstream(dir / name, std::ios::binary) << text;
  try {
    (void)read_points(dir / name);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

void write_pcd(const std::filesystem::path& f, const std::vector<Eigen::Vector3d>& pts, bool binary) {
  std::ofstream o(f, std::ios::binary);
  o.precision(17);
  o << "# .PCD v0.7\nVERSION 0.7\nFIELDS intensity x y z\nSIZE 4 8 8 8\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH "
    << pts.size() + 1 << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << pts.size() + 1 << "\nDATA "
    << (binary ? "binary" : "ascii") << "\n";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Eigen::Vector3d> all = pts;
  all.emplace_back(nan, nan, nan);  // PCL's "no return": left out
  for (const auto& p : all) {
    if (binary) {
      const float i = 7.0F;
      o.write(reinterpret_cast<const char*>(&i), 4);
      o.write(reinterpret_cast<const char*>(p.data()), 24);
    } else {
      o << "7 ";
      for (int k = 0; k < 3; ++k) {
        if (std::isnan(p(k))) {
          o << "nan ";
        } else {
          o << p(k) << " ";
        }
      }
      o << "\n";
    }
  }
}

void write_ply(const std::filesystem::path& f, const std::vector<Eigen::Vector3d>& pts, bool binary) {
  std::ofstream o(f, std::ios::binary);
  o << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\nelement vertex " << pts.size()
    << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nend_header\n";
  o.precision(9);
  for (const auto& p : pts) {
    if (binary) {
      const float v[3] = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
      o.write(reinterpret_cast<const char*>(v), 12);
      o.put(static_cast<char>(9));
    } else {
      o << static_cast<float>(p.x()) << " " << static_cast<float>(p.y()) << " " << static_cast<float>(p.z()) << " 9\n";
    }
  }
}

TEST(Clouds, EveryFormatReadsTheSamePoints) {
  std::mt19937 rng(1);
  const auto pts = sample_cloud(rng, 500);
  const auto dir = scratch_dir("cloud_formats");
  write_xyz(dir / "c.xyz", pts);
  write_pcd(dir / "a.pcd", pts, false);
  write_pcd(dir / "b.pcd", pts, true);
  write_ply(dir / "a.ply", pts, false);
  write_ply(dir / "b.ply", pts, true);
  for (const char* name : {"c.xyz", "a.pcd", "b.pcd", "a.ply", "b.ply"}) {
    const auto got = read_points(dir / name);
    ASSERT_EQ(got.size(), pts.size()) << name;
    const bool single = std::string(name).find(".ply") != std::string::npos;
    double worst = 0.0;
    for (std::size_t i = 0; i < pts.size(); ++i) worst = std::max(worst, (got[i] - pts[i]).norm());
    EXPECT_LE(worst, single ? 1e-7 : 1e-15) << name;
  }
}

TEST(Clouds, BadFilesAreReportedWithTheFileAndTheLine) {
  const auto dir = scratch_dir("cloud_bad");
  const auto message = [&](const std::string& name, const std::string& text) { return read_error(dir, name, text); };
  EXPECT_NE(message("a.xyz", "0 0 0\n1 2\n").find("a.xyz:2: expected the numbers x y z"), std::string::npos)
      << message("a.xyz", "0 0 0\n1 2\n");
  EXPECT_NE(message("b.xyz", "0 0 inf\n").find("b.xyz:1: a coordinate is not finite"), std::string::npos);
  EXPECT_NE(message("c.pcd",
                    "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nPOINTS 1\nDATA "
                    "binary_compressed\n")
                .find("c.pcd:7: DATA binary_compressed (LZF) is not read"),
            std::string::npos);
  EXPECT_NE(message("d.pcd", "FIELDS x y\nSIZE 4 4\nTYPE F F\nPOINTS 1\nDATA ascii\n1 2\n").find("x, y and z"),
            std::string::npos);
  EXPECT_NE(message("e.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 2\nDATA ascii\n1 2 3\n")
                .find("POINTS says 2 points, the data holds 1"),
            std::string::npos);
  EXPECT_NE(message("f.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 2\nDATA binary\nabc")
                .find("the binary data holds 3 bytes"),
            std::string::npos);
  EXPECT_NE(message("g.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                    "end_header\n1 2\n")
                .find("needs properties x, y and z"),
            std::string::npos);
  EXPECT_NE(message("h.obj", "v 1 2 3\n").find("a .ply, .pcd or .xyz file"), std::string::npos);
  ShapeSpec missing = cloud_spec(dir / "missing.xyz", 0.01, 0.0);
  try {
    load_cloud(missing);
    ADD_FAILURE() << "a missing file loaded";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("missing.xyz"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "empty.xyz") << "# nothing\n";
  ShapeSpec empty = cloud_spec(dir / "empty.xyz", 0.01, 0.0);
  EXPECT_THROW(load_cloud(empty), std::invalid_argument);
  std::ofstream(dir / "far.xyz") << "0 0 0\n1000 0 0\n";
  ShapeSpec far = cloud_spec(dir / "far.xyz", 0.01, 0.0);
  try {
    load_cloud(far);
    ADD_FAILURE() << "a point out of the tree's reach loaded";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("point 2"), std::string::npos) << e.what();
  }
}

// OctoMap's own files, whole, cut short or foreign: read, or refused with a reason (never a crash: OctoMap's readers
// recurse without a limit and read past the end, so redres walks the nodes first).
TEST(Clouds, OctreeFilesAreCheckedBeforeOctoMapReadsThem) {
  std::mt19937 rng(11);
  const auto pts = sample_cloud(rng, 800);
  const auto dir = scratch_dir("cloud_octree_files");
  octomap::OcTree tree(0.03);
  for (const auto& p : pts) tree.updateNode(octomap::point3d(p.x(), p.y(), p.z()), true);
  tree.updateInnerOccupancy();
  ASSERT_TRUE(tree.writeBinary((dir / "c.bt").string()));
  ASSERT_TRUE(tree.write((dir / "c.ot").string()));
  const auto load = [&](const std::string& name) {
    ShapeSpec s;
    s.shape = ShapeSpec::Kind::kOctree;
    s.file = dir / name;
    load_cloud(s);
    return s;
  };
  const ShapeSpec bt = load("c.bt"), ot = load("c.ot");
  EXPECT_EQ(occupancy_info(*bt.cloud).cells, occupancy_info(*ot.cloud).cells);
  EXPECT_GT(occupancy_info(*bt.cloud).cells, 100U);
  const auto refused = [&](const std::string& name, const std::string& bytes, const std::string& says) {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    try {
      (void)load(name);
      ADD_FAILURE() << name << " loaded";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  const std::string whole = read_text(dir / "c.bt");
  refused("cut.bt", whole.substr(0, whole.size() - 40), "end early");
  std::string deep = "# Octomap OcTree binary file\nid OcTree\nsize 40\nres 0.1\ndata\n";
  deep += std::string(40, '\xff');  // every child an inner node: deeper than 16 levels, or cut
  refused("deep.bt", deep, "end early or nest deeper than 16 levels");
  refused("other.bt", "# Octomap OcTree binary file\nid ColorOcTree\nres 0.1\ndata\n", "'ColorOcTree'");
  refused("text.bt", "hello\n", "not an OctoMap .bt file");
  refused("nores.ot", "# Octomap OcTree file\nid OcTree\ndata\n", "no `res`");
}

TEST(Clouds, MalformedPcdHeadersAreRefusedNotRead) {
  const auto dir = scratch_dir("cloud_bad_pcd");
  const auto message = [&](const std::string& name, const std::string& text) { return read_error(dir, name, text); };
  // DATA as the last bytes, without a newline, and no data: nothing is read past the end.
  EXPECT_NE(message("a.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 3\nDATA binary").find("holds 0 bytes"),
            std::string::npos);
  // More points than the data holds: refused before anything is reserved for them.
  EXPECT_NE(message("b.pcd", "FIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nPOINTS 2000000000\nDATA binary\n")
                .find("POINTS 2000000000"),
            std::string::npos);
  // Counts that would overflow an int.
  EXPECT_NE(message("c.pcd", "FIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 2000000000\nPOINTS 1\nDATA binary\n")
                .find("not read"),
            std::string::npos);
  // A coordinate beyond the tree's reach at the cloud's resolution (OctoMap would overflow an int converting it).
  std::ofstream(dir / "far.xyz") << "0 0 0\n1e30 0 0\n";
  ShapeSpec far = cloud_spec(dir / "far.xyz", 0.01, 0.0);
  EXPECT_THROW(load_cloud(far), std::invalid_argument);
}

}  // namespace
}  // namespace redres

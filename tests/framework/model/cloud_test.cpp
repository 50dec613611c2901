// Cloud obstacles (octrees and point clouds): the files are read as written in every format; the distance to a cloud
// matches FCL's own octree distance (an independent implementation: GJK on each cell) and a brute force over the
// occupied cells, and it brackets the brute-force distance to the points themselves (the cells hold the points, so
// the cloud is never farther than the points and at most a cell diagonal nearer); box links are measured
// conservatively; bad files and keys are reported with the file and the line; and the search allocates nothing.

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <fcl/geometry/octree/octree.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "alloc_counter.hpp"
#include "redres/common/error.hpp"
#include "redres/model/collision.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

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

// A table top, a ball's surface and a scatter: points with structure at several scales.
std::vector<Eigen::Vector3d> sample_cloud(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < n; ++i) {
    if (i % 3 == 0) {
      out.emplace_back(0.5 + 0.2 * u(rng), 0.2 * u(rng), 0.002 * u(rng));
    } else if (i % 3 == 1) {
      Eigen::Vector3d d(g(rng), g(rng), g(rng));
      out.emplace_back(Eigen::Vector3d(0.5, 0.3, 0.3) + 0.1 * d.normalized());
    } else {
      out.emplace_back(0.5 + 0.4 * u(rng), 0.4 * u(rng), 0.5 + 0.5 * u(rng));
    }
  }
  return out;
}

void write_xyz(const std::filesystem::path& f, const std::vector<Eigen::Vector3d>& pts) {
  std::ofstream o(f);
  o.precision(17);
  o << "# x y z r g b\n";
  for (const auto& p : pts) o << p.x() << " " << p.y() << ", " << p.z() << " 1 2 3\n";
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

ShapeSpec cloud_spec(const std::filesystem::path& file, double resolution, double radius) {
  ShapeSpec s;
  s.shape = ShapeSpec::Kind::kPoints;
  s.file = file;
  s.resolution = resolution;
  s.radius = radius;
  return s;
}

ShapeSpec capsule(double r, double l) {
  ShapeSpec s;
  s.shape = ShapeSpec::Kind::kCapsule;
  s.radius = r;
  s.length = l;
  return s;
}

Eigen::Isometry3d random_pose(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
  T.translation() << 0.5 + 0.6 * u(rng), 0.6 * u(rng), 0.5 + 0.6 * u(rng);
  return T;
}

// Distance from a capsule (axis a-b, radius r) to a point.
double capsule_point(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r, const Eigen::Vector3d& p) {
  const Eigen::Vector3d ab = b - a;
  const double s = ab.squaredNorm() > 0.0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + s * ab - p).norm() - r;
}

// Distance from a capsule to an axis-aligned cube (centre c, half edge h), apart: the minimum over the axis of the
// point-box distance, by golden-section search on the convex function (independent of the library's closed form).
double capsule_cube(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r, const Eigen::Vector3d& c, double h) {
  const auto f = [&](double s) {
    const Eigen::Vector3d q = a + s * (b - a) - c;
    return (q.cwiseAbs() - Eigen::Vector3d::Constant(h)).cwiseMax(0.0).norm();
  };
  double lo = 0.0, hi = 1.0;
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int k = 0; k < 200; ++k) {
    const double x1 = hi - phi * (hi - lo), x2 = lo + phi * (hi - lo);
    if (f(x1) < f(x2)) {
      hi = x2;
    } else {
      lo = x1;
    }
  }
  return std::min({f(0.0), f(1.0), f(0.5 * (lo + hi))}) - r;
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

TEST(Clouds, KeysAreChecked) {
  ShapeSpec s;
  s.shape = ShapeSpec::Kind::kPoints;
  s.file = "x.xyz";
  EXPECT_THROW(check_config(s, ShapeSpec::schema()), FieldError);  // no resolution
  s.resolution = 0.01;
  EXPECT_NO_THROW(check_config(s, ShapeSpec::schema()));
  s.radius = -0.1;
  EXPECT_THROW(check_config(s, ShapeSpec::schema()), FieldError);
  s.radius = 0.0;
  s.size = std::array<double, 3>{1, 1, 1};
  EXPECT_THROW(check_config(s, ShapeSpec::schema()), FieldError);
  s.size.reset();
  s.shape = ShapeSpec::Kind::kOctree;
  s.file = "x.bt";
  EXPECT_THROW(check_config(s, ShapeSpec::schema()), FieldError);  // an octree's cells come from the file
  s.resolution.reset();
  EXPECT_NO_THROW(check_config(s, ShapeSpec::schema()));
  ShapeSpec box;
  box.shape = ShapeSpec::Kind::kBox;
  box.size = std::array<double, 3>{1, 1, 1};
  box.file = "x.xyz";
  EXPECT_THROW(check_config(box, ShapeSpec::schema()), FieldError);
}

struct CloudFixture {
  std::vector<Eigen::Vector3d> points;
  std::filesystem::path file;
  double resolution = 0.02;
};

// Our distance against (1) FCL's octree distance on the same cells (GJK per cell; apart pairs only, since FCL's
// unsigned query gives -1 for overlaps), (2) a brute force over every occupied cell, (3) the points themselves.
TEST(Clouds, CapsuleDistancesMatchFclAndBruteForce) {
  std::mt19937 rng(7);
  const double res = 0.02;
  const auto pts = sample_cloud(rng, 3000);
  const auto dir = scratch_dir("cloud_distances");
  write_xyz(dir / "c.xyz", pts);
  for (const double grow : {0.0, 0.015}) {
    ShapeSpec cloud = cloud_spec(dir / "c.xyz", res, grow);
    load_cloud(cloud);
    const auto cells = occupied_cells(*cloud.cloud);
    ASSERT_GT(cells.size(), 500U);
    EXPECT_LE(cells.size(), pts.size());
    // The same cells in FCL's octree.
    auto tree = std::make_shared<octomap::OcTree>(res);
    for (const auto& p : pts) tree->updateNode(octomap::point3d(p.x(), p.y(), p.z()), true);
    tree->updateInnerOccupancy();
    fcl::CollisionObjectd fcl_cloud(std::make_shared<fcl::OcTreed>(std::shared_ptr<const octomap::OcTree>(tree)));
    Eigen::Isometry3d Tc = Eigen::Isometry3d::Identity();
    Tc.translation() << 0.05, -0.02, 0.01;
    Tc.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, 0.3, 1.0).normalized()).toRotationMatrix();
    fcl_cloud.setTransform(fcl::Transform3d(Tc.matrix()));
    const std::vector<ShapeSpec> shapes = {capsule(0.04, 0.25), cloud};
    const DistanceQuery q(shapes);
    int compared_fcl = 0, overlapping = 0;
    for (int trial = 0; trial < 40; ++trial) {
      const Eigen::Isometry3d T = random_pose(rng);
      const ShapeDistance d = q.distance(0, T, 1, Tc);
      ASSERT_TRUE(d.ok);
      const Eigen::Vector3d a = T * Eigen::Vector3d(0, 0, -0.125), b = T * Eigen::Vector3d(0, 0, 0.125);
      // (2) every cell, in the cloud's frame.
      const Eigen::Vector3d la = Tc.inverse() * a, lb = Tc.inverse() * b;
      double cells_min = std::numeric_limits<double>::infinity();
      for (const auto& c : cells)
        cells_min = std::min(cells_min, capsule_cube(la, lb, 0.04, {c[0], c[1], c[2]}, 0.5 * c[3]));
      cells_min -= grow;
      if (cells_min > 0.0) {
        EXPECT_NEAR(d.distance, cells_min, 1e-9) << "trial " << trial;
        EXPECT_NEAR((d.point_a - d.point_b).norm(), d.distance, 1e-9) << "witness points " << trial;
        EXPECT_NEAR(capsule_point(a, b, 0.04, d.point_a), 0.0, 1e-9) << "point_a lies on the capsule";
      } else {
        ++overlapping;
        EXPECT_LE(d.distance, 1e-12) << "an overlap reads as one, trial " << trial;
      }
      // (3) the points: the grown cells hold the points' balls of radius grow, and every point of a cell lies within
      // a cell diagonal of the point that made it.
      double points_min = std::numeric_limits<double>::infinity();
      for (const auto& p : pts) points_min = std::min(points_min, capsule_point(la, lb, 0.04, p) - grow);
      if (points_min > 0.0 && cells_min > 0.0) {
        EXPECT_LE(d.distance, points_min + 1e-9);
        EXPECT_GE(d.distance, points_min - std::sqrt(3.0) * res - 1e-9);
      }
      // (1) FCL, on the cells themselves (grow = 0), apart.
      if (grow == 0.0 && cells_min > 1e-3) {
        fcl::CollisionObjectd cap(std::make_shared<fcl::Capsuled>(0.04, 0.25), fcl::Transform3d(T.matrix()));
        fcl::DistanceRequestd req(true, false, 0.0, 0.0, 1e-12, fcl::GST_LIBCCD);
        fcl::DistanceResultd res_fcl;
        fcl::distance(&cap, &fcl_cloud, req, res_fcl);
        EXPECT_NEAR(d.distance, res_fcl.min_distance, 1e-6) << "trial " << trial;
        ++compared_fcl;
      }
      // A bounded search: beyond `within` the pair reads +inf; within it, the same distance.
      const ShapeDistance near = q.distance(0, T, 1, Tc, d.distance + 1e-9);
      EXPECT_EQ(near.distance, d.distance);
      const ShapeDistance none = q.distance(0, T, 1, Tc, d.distance - 1e-9);
      EXPECT_TRUE(std::isinf(none.distance) && none.distance > 0.0);
    }
    if (grow == 0.0) {
      EXPECT_GE(compared_fcl, 20);
    }
    EXPECT_GE(overlapping, 1) << "some trials overlap the cloud";
  }
}

TEST(Clouds, AnOctreeFileMeasuresAsThePointsItWasBuiltFrom) {
  std::mt19937 rng(8);
  const auto pts = sample_cloud(rng, 2000);
  const auto dir = scratch_dir("cloud_octree");
  write_xyz(dir / "c.xyz", pts);
  ShapeSpec points = cloud_spec(dir / "c.xyz", 0.025, 0.01);
  load_cloud(points);
  octomap::OcTree tree(0.025);
  for (const auto& p : pts) tree.updateNode(octomap::point3d(p.x(), p.y(), p.z()), true);
  tree.updateInnerOccupancy();
  ASSERT_TRUE(tree.writeBinary((dir / "c.bt").string()));
  ShapeSpec octree;
  octree.shape = ShapeSpec::Kind::kOctree;
  octree.file = dir / "c.bt";
  octree.radius = 0.01;
  load_cloud(octree);
  EXPECT_EQ(occupancy_info(*octree.cloud).cells, occupancy_info(*points.cloud).cells);
  const DistanceQuery q({capsule(0.03, 0.2), points, octree});
  for (int trial = 0; trial < 30; ++trial) {
    const Eigen::Isometry3d T = random_pose(rng);
    const double a = q.distance(0, T, 1, Eigen::Isometry3d::Identity()).distance;
    const double b = q.distance(0, T, 2, Eigen::Isometry3d::Identity()).distance;
    EXPECT_NEAR(a, b, 1e-12) << "trial " << trial;
  }
}

TEST(Clouds, BoxLinksAndPointsAreMeasuredOnTheNearSide) {
  std::mt19937 rng(9);
  const double res = 0.02;
  const auto pts = sample_cloud(rng, 1500);
  const auto dir = scratch_dir("cloud_box");
  write_xyz(dir / "c.xyz", pts);
  ShapeSpec cloud = cloud_spec(dir / "c.xyz", res, 0.0);
  load_cloud(cloud);
  ShapeSpec box;
  box.shape = ShapeSpec::Kind::kBox;
  box.size = std::array<double, 3>{0.08, 0.12, 0.2};
  ShapeSpec cube;  // one cell at a time, measured by the library's box-box path (GJK, polished)
  cube.shape = ShapeSpec::Kind::kBox;
  cube.size = std::array<double, 3>{res, res, res};
  const auto cells = occupied_cells(*cloud.cloud);
  const DistanceQuery q({box, cloud, cube});
  int apart = 0;
  for (int trial = 0; trial < 15; ++trial) {
    const Eigen::Isometry3d T = random_pose(rng);
    const ShapeDistance d = q.distance(0, T, 1, Eigen::Isometry3d::Identity());
    ASSERT_TRUE(d.ok);
    double exact = std::numeric_limits<double>::infinity();
    for (const auto& c : cells) {
      Eigen::Isometry3d Tcell = Eigen::Isometry3d::Identity();
      Tcell.translation() << c[0], c[1], c[2];
      const ShapeDistance e = q.distance(0, T, 2, Tcell);
      exact = std::min(exact, e.ok ? e.distance : 0.0);
    }
    if (exact <= 0.0) continue;
    ++apart;
    EXPECT_LE(d.distance, exact + 1e-9) << "never farther than the cells, trial " << trial;
    EXPECT_GE(d.distance, exact - (std::sqrt(3.0) - 1.0) * 0.5 * res - 1e-9) << "trial " << trial;
  }
  EXPECT_GE(apart, 5);
  // The nearest point of the cloud to a world point: on a cell, and at the distance of the nearest cell.
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d w = random_pose(rng).translation();
    const Eigen::Vector3d p = q.nearest_point(1, Eigen::Isometry3d::Identity(), w);
    double best = std::numeric_limits<double>::infinity();
    for (const auto& c : cells) {
      const Eigen::Vector3d e = ((w - Eigen::Vector3d(c[0], c[1], c[2])).cwiseAbs().array() - 0.5 * c[3]).max(0.0);
      best = std::min(best, e.norm());
    }
    EXPECT_NEAR((w - p).norm(), best, 1e-12) << "trial " << trial;
  }
}

TEST(Clouds, TheSearchAllocatesNothing) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  std::mt19937 rng(10);
  const auto pts = sample_cloud(rng, 5000);
  const auto dir = scratch_dir("cloud_alloc");
  write_xyz(dir / "c.xyz", pts);
  ShapeSpec box;
  box.shape = ShapeSpec::Kind::kBox;
  box.size = std::array<double, 3>{0.08, 0.12, 0.2};
  const DistanceQuery q({capsule(0.04, 0.2), box, cloud_spec(dir / "c.xyz", 0.01, 0.005)});
  std::vector<Eigen::Isometry3d> poses;
  for (int k = 0; k < 50; ++k) poses.push_back(random_pose(rng));
  double sum = 0.0;
  long count = 0;
  {
    const testing::AllocationCounter counter;
    for (const auto& T : poses) {
      sum += q.distance(0, T, 2, Eigen::Isometry3d::Identity(), 0.3).distance;
      sum += q.distance(1, T, 2, Eigen::Isometry3d::Identity(), 0.3).distance;
      sum += q.nearest_point(2, Eigen::Isometry3d::Identity(), T.translation()).x();
    }
    count = counter.count();
  }
  EXPECT_EQ(count, 0);
  EXPECT_FALSE(std::isnan(sum));
}

TEST(Clouds, ARobotLinkCannotBeACloud) {
  const auto dir = scratch_dir("cloud_link");
  std::string robot = read_text(source_path("robots/franka_panda.toml"));
  const auto at = robot.find("collision = [");
  ASSERT_NE(at, std::string::npos);
  robot.insert(at + std::string("collision = [").size(),
               "{ shape = \"points\", file = \"c.xyz\", resolution = 0.01 }, ");
  std::ofstream(dir / "c.xyz") << "0 0 0\n";
  std::ofstream(dir / "robot.toml") << robot;
  try {
    (void)load_robot(dir / "robot.toml");
    ADD_FAILURE() << "a cloud link loaded";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("octrees and point clouds are obstacles"), std::string::npos) << e.what();
  }
}

// A point inside the cloud is its own nearest point (as for any shape), so a box corner inside gets no row that would
// push it deeper.
TEST(Clouds, APointInsideIsItsOwnNearestPoint) {
  const auto dir = scratch_dir("cloud_inside");
  std::ofstream(dir / "c.xyz") << "0.5 0.5 0.5\n0.52 0.5 0.5\n";
  ShapeSpec cloud = cloud_spec(dir / "c.xyz", 0.02, 0.01);
  load_cloud(cloud);
  const DistanceQuery q({cloud});
  const auto cells = occupied_cells(*cloud.cloud);
  ASSERT_FALSE(cells.empty());
  for (const auto& c : cells) {
    const Eigen::Vector3d centre(c[0], c[1], c[2]);
    EXPECT_EQ(q.nearest_point(0, Eigen::Isometry3d::Identity(), centre), centre);
    const Eigen::Vector3d shell = centre + Eigen::Vector3d(0.5 * c[3] + 0.005, 0.0, 0.0);  // in the grown shell
    EXPECT_EQ(q.nearest_point(0, Eigen::Isometry3d::Identity(), shell), shell);
  }
  const Eigen::Vector3d out(0.5, 0.5, 0.6);
  const Eigen::Vector3d p = q.nearest_point(0, Eigen::Isometry3d::Identity(), out);
  double best = std::numeric_limits<double>::infinity();
  for (const auto& c : cells) {
    const Eigen::Vector3d e = ((out - Eigen::Vector3d(c[0], c[1], c[2])).cwiseAbs().array() - 0.5 * c[3]).max(0.0);
    best = std::min(best, e.norm() - 0.01);
  }
  EXPECT_NEAR((out - p).norm(), best, 1e-12) << "outside: on the grown cell";
  EXPECT_GT(best, 0.05);
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

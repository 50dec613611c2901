// Cloud obstacles (octrees and point clouds; their files' readers are tested in tests/framework/parsers/
// cloud_file_test.cpp): the distance to a cloud
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
#include "cloud_samples.hpp"
#include "redres/common/error.hpp"
#include "redres/model/collision.hpp"
#include "redres/parsers/cloud_file.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "shape_samples.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

using testing::capsule;

using testing::cloud_spec;
using testing::sample_cloud;
using testing::write_xyz;

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
  ShapeSpec cloud = cloud_spec(dir / "c.xyz", 0.01, 0.005);
  load_cloud(cloud);
  const DistanceQuery q({capsule(0.04, 0.2), box, cloud});
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

// The model reads no file: a DistanceQuery takes a cloud whose cells are read (load_cloud(), in parsers/) and refuses
// one that is not, naming the shape and its file; once read, the cells are shared by the spec's copies.
TEST(Clouds, ADistanceQueryTakesOnlyACloudThatIsRead) {
  std::mt19937 rng(12);
  const auto dir = scratch_dir("cloud_unread");
  write_xyz(dir / "c.xyz", sample_cloud(rng, 300));
  ShapeSpec cloud = cloud_spec(dir / "c.xyz", 0.02, 0.0);
  try {
    const DistanceQuery q({capsule(0.03, 0.2), cloud});
    ADD_FAILURE() << "an unread cloud was taken";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("shape 1 (points, "), std::string::npos) << what;
    EXPECT_NE(what.find("c.xyz"), std::string::npos) << what;
    EXPECT_NE(what.find("load_cloud()"), std::string::npos) << what;
  }
  load_cloud(cloud);
  ASSERT_TRUE(cloud.cloud);
  const ShapeSpec copy = cloud;
  EXPECT_EQ(copy.cloud.get(), cloud.cloud.get());
  const DistanceQuery q({capsule(0.03, 0.2), copy});
  EXPECT_TRUE(q.distance(0, Eigen::Isometry3d::Identity(), 1, Eigen::Isometry3d::Identity()).ok);
}

}  // namespace
}  // namespace redres

// Distances between shapes (FCL, and the analytic penetration of spheres and capsules) against closed forms: the
// value, its sign when the shapes overlap, and witness points that lie on the surfaces.

#include <cmath>

#include <gtest/gtest.h>

#include "redres/model/collision.hpp"

namespace redres {
namespace {

ShapeSpec sphere(double r) {
  ShapeSpec s;
  s.shape = ShapeSpec::Kind::kSphere;
  s.radius = r;
  return s;
}
ShapeSpec capsule(double r, double l) {
  ShapeSpec s;
  s.shape = ShapeSpec::Kind::kCapsule;
  s.radius = r;
  s.length = l;
  return s;
}
ShapeSpec box(double x, double y, double z) {
  ShapeSpec s;
  s.shape = ShapeSpec::Kind::kBox;
  s.size = std::array<double, 3>{x, y, z};
  return s;
}
Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}
Eigen::Isometry3d tilted(double x, double y, double z, double about_y) {
  Eigen::Isometry3d T = at(x, y, z);
  T.linear() = Eigen::AngleAxisd(about_y, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return T;
}

struct Case {
  const char* what;
  ShapeSpec a, b;
  Eigen::Isometry3d Ta, Tb;
  double expected;
};

TEST(Collision, DistancesMatchClosedFormsApartAndOverlapping) {
  const std::vector<Case> cases = {
      {"sphere-sphere apart", sphere(0.1), sphere(0.2), at(0, 0, 0), at(0.5, 0, 0), 0.2},
      {"sphere-sphere overlapping", sphere(0.1), sphere(0.2), at(0, 0, 0), at(0.25, 0, 0), -0.05},
      // A capsule along z from -0.2 to 0.2; a sphere beside its middle, and beyond its end.
      {"sphere-capsule apart (side)", sphere(0.05), capsule(0.1, 0.4), at(0.3, 0, 0.1), at(0, 0, 0), 0.15},
      {"sphere-capsule apart (end)", sphere(0.05), capsule(0.1, 0.4), at(0, 0, 0.5), at(0, 0, 0), 0.15},
      {"sphere-capsule overlapping", sphere(0.05), capsule(0.1, 0.4), at(0.12, 0, 0), at(0, 0, 0), -0.03},
      // Two capsules, crossed at right angles, axes 0.3 apart; then overlapping by 0.04.
      {"capsule-capsule apart", capsule(0.1, 0.4), capsule(0.05, 0.6), at(0, 0, 0), tilted(0, 0.3, 0, M_PI / 2), 0.15},
      {"capsule-capsule overlapping", capsule(0.1, 0.4), capsule(0.05, 0.6), at(0, 0, 0), tilted(0, 0.11, 0, M_PI / 2),
       -0.04},
      {"sphere-box apart", sphere(0.1), box(0.2, 0.4, 0.6), at(0.5, 0, 0), at(0, 0, 0), 0.3},
      {"sphere-box overlapping", sphere(0.1), box(0.2, 0.4, 0.6), at(0.15, 0, 0), at(0, 0, 0), -0.05},
      {"capsule-box apart", capsule(0.05, 0.4), box(0.2, 0.2, 0.2), at(0.4, 0, 0), at(0, 0, 0), 0.25},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const DistanceQuery q({c.a, c.b});
    const ShapeDistance d = q.distance(0, c.Ta, 1, c.Tb);
    ASSERT_TRUE(d.ok) << d.error;
    EXPECT_NEAR(d.distance, c.expected, 1e-6);
    // Witness points: |p_a - p_b| is the distance's magnitude.
    EXPECT_NEAR((d.point_a - d.point_b).norm(), std::abs(c.expected), 1e-6);
  }
}

TEST(Collision, RepeatedQueriesDoNotKeepAStaleResult) {
  const DistanceQuery q({sphere(0.1), sphere(0.1)});
  const ShapeDistance overlapping = q.distance(0, at(0, 0, 0), 1, at(0.1, 0, 0));
  EXPECT_NEAR(overlapping.distance, -0.1, 1e-9);
  const ShapeDistance apart = q.distance(0, at(0, 0, 0), 1, at(2.0, 0, 0));
  EXPECT_NEAR(apart.distance, 1.8, 1e-9);  // FCL keeps min_distance unless the result is cleared
}

TEST(Collision, ShapesAreCheckedAndDescribed) {
  ShapeSpec bad = sphere(-0.1);
  EXPECT_THROW(DistanceQuery({bad}), std::invalid_argument);
  ShapeSpec no_size;
  no_size.shape = ShapeSpec::Kind::kBox;
  EXPECT_THROW(DistanceQuery({no_size}), std::invalid_argument);
  ShapeSpec between = capsule(0.05, 0.1);
  between.length.reset();
  between.from = std::array<double, 3>{0, 0, 0};
  between.to = std::array<double, 3>{0.3, 0.4, 0};
  EXPECT_NEAR(between.axis_length(), 0.5, 1e-15);
  EXPECT_NEAR((between.pose().linear().col(2) - Eigen::Vector3d(0.6, 0.8, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((between.pose().translation() - Eigen::Vector3d(0.15, 0.2, 0)).norm(), 0.0, 1e-15);
  EXPECT_EQ(sphere(0.25).describe(), "sphere(r = 0.25 m)");
}

}  // namespace
}  // namespace redres

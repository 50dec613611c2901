// Convex hull collision geometry (collision_model = "hull"): hulls made by qhull, and their distances to every
// primitive and to each other checked against a brute force over the shapes' features (vertices, edges, triangles),
// written here independently of the library's GJK: every distance apart to 1e-9 m, every overlap negative, witness
// points on the shapes, symmetry, the gradient, no allocation per query; the robot files' meshes made into hulls.

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "alloc_counter.hpp"
#include "redres/common/error.hpp"
#include "redres/config/config.hpp"
#include "redres/model/collision.hpp"
#include "redres/model/convex.hpp"
#include "redres/model/mesh.hpp"
#include "redres/parsers/cloud_file.hpp"
#include "redres/parsers/mesh_file.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/run/scenario.hpp"
#include "scenario_text.hpp"
#include "shape_samples.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

using testing::cube_obj;

namespace fs = std::filesystem;
using Eigen::Isometry3d;
using Eigen::Vector3d;

// ---- The brute-force reference: a shape as its core's features (world frame) and a radius. ----

struct Features {
  std::vector<Vector3d> v;
  std::vector<std::array<int, 2>> e;
  std::vector<std::array<int, 3>> f;
  double r = 0.0;
};

double point_segment(const Vector3d& p, const Vector3d& a, const Vector3d& b) {
  const Vector3d ab = b - a;
  const double L2 = ab.squaredNorm();
  const double t = L2 > 0.0 ? std::clamp((p - a).dot(ab) / L2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

// Projected onto the plane; inside the triangle by the signs of three cross products, else the nearest edge.
double point_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d n = (b - a).cross(c - a);
  const double edges = std::min({point_segment(p, a, b), point_segment(p, b, c), point_segment(p, c, a)});
  if (!(n.norm() > 1e-14)) return edges;
  const Vector3d u = n.normalized();
  const Vector3d q = p - (p - a).dot(u) * u;
  const bool inside =
      (b - a).cross(q - a).dot(n) >= 0.0 && (c - b).cross(q - b).dot(n) >= 0.0 && (a - c).cross(q - c).dot(n) >= 0.0;
  return inside ? std::abs((p - a).dot(u)) : edges;
}

// The unconstrained closest pair when it lies inside both segments, else the four ends against the other segment.
double segment_segment(const Vector3d& p0, const Vector3d& p1, const Vector3d& q0, const Vector3d& q1) {
  double best = std::min(
      {point_segment(p0, q0, q1), point_segment(p1, q0, q1), point_segment(q0, p0, p1), point_segment(q1, p0, p1)});
  const Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.dot(d1), b = d1.dot(d2), c = d2.dot(d2), d = d1.dot(r), e = d2.dot(r);
  const double det = a * c - b * b;
  if (det > 1e-12 * a * c) {
    const double s = (b * e - c * d) / det, t = (a * e - b * d) / det;
    if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0) best = std::min(best, ((p0 + s * d1) - (q0 + t * d2)).norm());
  }
  return best;
}

// The distance from x to the core's features (its surface, for a solid core and x outside it).
double feature_distance(const Features& A, const Vector3d& x) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& p : A.v) best = std::min(best, (x - p).norm());
  for (const auto& e : A.e) best = std::min(best, point_segment(x, A.v[e[0]], A.v[e[1]]));
  for (const auto& f : A.f) best = std::min(best, point_triangle(x, A.v[f[0]], A.v[f[1]], A.v[f[2]]));
  return best;
}

// The distance between two cores that do not meet: every pair of features.
double brute_core_distance(const Features& A, const Features& B) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& p : A.v) best = std::min(best, feature_distance(B, p));
  for (const auto& p : B.v) best = std::min(best, feature_distance(A, p));
  for (const auto& ea : A.e) {
    for (const auto& eb : B.e) best = std::min(best, segment_segment(A.v[ea[0]], A.v[ea[1]], B.v[eb[0]], B.v[eb[1]]));
  }
  return best;
}

Vector3d centroid(const Features& A) {
  Vector3d c = Vector3d::Zero();
  for (const auto& p : A.v) c += p;
  return c / static_cast<double>(A.v.size());
}

bool inside_polytope(const Features& A, const Vector3d& x) {
  if (A.f.empty()) return false;
  const Vector3d c = centroid(A);
  for (const auto& f : A.f) {
    const Vector3d& a = A.v[f[0]];
    Vector3d n = (A.v[f[1]] - a).cross(A.v[f[2]] - a);
    if ((c - a).dot(n) > 0.0) n = -n;  // outward
    if ((x - a).dot(n) > 0.0) return false;
  }
  return true;
}

bool segment_crosses_triangle(const Vector3d& p, const Vector3d& q, const Vector3d& a, const Vector3d& b,
                              const Vector3d& c) {
  const Vector3d n = (b - a).cross(c - a);
  const double sp = (p - a).dot(n), sq = (q - a).dot(n);
  if (sp * sq > 0.0 || sp == sq) return false;
  const Vector3d x = p + (sp / (sp - sq)) * (q - p);
  return (b - a).cross(x - a).dot(n) >= 0.0 && (c - b).cross(x - b).dot(n) >= 0.0 && (a - c).cross(x - c).dot(n) >= 0.0;
}

// Two convex cores meet when one holds a vertex of the other or an edge of one crosses a triangle of the other.
bool cores_meet(const Features& A, const Features& B) {
  for (const auto& p : A.v) {
    if (inside_polytope(B, p)) return true;
  }
  for (const auto& p : B.v) {
    if (inside_polytope(A, p)) return true;
  }
  const auto crosses = [](const Features& X, const Features& Y) {
    for (const auto& e : X.e) {
      for (const auto& f : Y.f) {
        if (segment_crosses_triangle(X.v[e[0]], X.v[e[1]], Y.v[f[0]], Y.v[f[1]], Y.v[f[2]])) return true;
      }
    }
    return false;
  };
  return crosses(A, B) || crosses(B, A);
}

Features features(const ShapeSpec& s, const Isometry3d& T) {
  Features out;
  switch (s.shape) {
    case ShapeSpec::Kind::kSphere:
      out.v = {T.translation()};
      out.r = *s.radius;
      break;
    case ShapeSpec::Kind::kCapsule:
      out.v = {T * Vector3d(0, 0, -0.5 * *s.length), T * Vector3d(0, 0, 0.5 * *s.length)};
      out.e = {{0, 1}};
      out.r = *s.radius;
      break;
    case ShapeSpec::Kind::kBox: {
      for (int c = 0; c < 8; ++c) {
        out.v.push_back(T * Vector3d(((c & 1) ? 0.5 : -0.5) * (*s.size)[0], ((c & 2) ? 0.5 : -0.5) * (*s.size)[1],
                                     ((c & 4) ? 0.5 : -0.5) * (*s.size)[2]));
      }
      for (int c = 0; c < 8; ++c) {
        for (const int bit : {1, 2, 4}) {
          if (!(c & bit)) out.e.push_back({c, c | bit});
        }
      }
      // Each face (the corners with one coordinate fixed) as two triangles.
      for (const int bit : {1, 2, 4}) {
        for (const int side : {0, bit}) {
          std::vector<int> q;
          for (int c = 0; c < 8; ++c) {
            if ((c & bit) == side) q.push_back(c);
          }
          // q holds 4 corners in binary order: 0-1-3-2 goes round the face.
          out.f.push_back({q[0], q[1], q[3]});
          out.f.push_back({q[0], q[3], q[2]});
        }
      }
      break;
    }
    case ShapeSpec::Kind::kConvex: {
      for (const auto& p : s.hull->vertices) out.v.push_back(T * p);
      out.f = s.hull->faces;
      std::set<std::pair<int, int>> edges;
      for (const auto& f : s.hull->faces) {
        for (int k = 0; k < 3; ++k) {
          const int a = f[static_cast<std::size_t>(k)], b = f[static_cast<std::size_t>((k + 1) % 3)];
          edges.insert({std::min(a, b), std::max(a, b)});
        }
      }
      for (const auto& [a, b] : edges) out.e.push_back({a, b});
      break;
    }
    default: ADD_FAILURE() << "no features for " << s.describe();
  }
  return out;
}

// ---- Random shapes and poses ----

Isometry3d random_pose(std::mt19937& rng, double reach) {
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  Isometry3d T = Isometry3d::Identity();
  T.linear() = q.toRotationMatrix();
  T.translation() = reach * Vector3d(g(rng), g(rng), g(rng));
  return T;
}

ShapeSpec random_hull(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), size(0.03, 0.2);
  std::uniform_int_distribution<int> count(8, 60);
  const Vector3d half(size(rng), size(rng), size(rng));
  std::vector<Vector3d> pts;
  const int n = count(rng);
  for (int k = 0; k < n; ++k) pts.push_back(Vector3d(u(rng), u(rng), u(rng)).cwiseProduct(half));
  return convex_shape(pts, "random.obj");
}

ShapeSpec random_primitive(std::mt19937& rng, ShapeSpec::Kind kind) {
  std::uniform_real_distribution<double> r(0.01, 0.12), len(0.02, 0.4);
  ShapeSpec s;
  s.shape = kind;
  switch (kind) {
    case ShapeSpec::Kind::kSphere: s.radius = r(rng); break;
    case ShapeSpec::Kind::kCapsule:
    case ShapeSpec::Kind::kCylinder:
      s.radius = r(rng);
      s.length = len(rng);
      break;
    case ShapeSpec::Kind::kBox: s.size = std::array<double, 3>{len(rng), len(rng), len(rng)}; break;
    default: return random_hull(rng);
  }
  return s;
}

// Is x within tol of the shape's surface (the radius away from its core's features)?
double surface_gap(const Features& A, const Vector3d& x) { return std::abs(feature_distance(A, x) - A.r); }

// The shapes a hull is measured against.
constexpr std::array<ShapeSpec::Kind, 4> kOthers = {ShapeSpec::Kind::kSphere, ShapeSpec::Kind::kCapsule,
                                                    ShapeSpec::Kind::kBox, ShapeSpec::Kind::kConvex};

struct PairStats {
  int apart = 0, overlapping = 0;
  double worst_error = 0.0, worst_witness = 0.0, worst_symmetry = 0.0;
};

// Random pairs of a hull and `other`: apart, the distance matches the brute force to 1e-9 m, the witness points lie
// on the surfaces and are |d| apart, d(a, b) = d(b, a); the cores overlapping, the distance is negative.
PairStats check_pairs(ShapeSpec::Kind other, int trials, unsigned seed) {
  std::mt19937 rng(seed);
  PairStats st;
  for (int trial = 0; trial < trials; ++trial) {
    const ShapeSpec a = random_hull(rng);
    const ShapeSpec b = random_primitive(rng, other);
    const DistanceQuery q({a, b});
    const Isometry3d Ta = random_pose(rng, 0.05), Tb = random_pose(rng, 0.2);
    const ShapeDistance d = q.distance(0, Ta, 1, Tb);
    const ShapeDistance back = q.distance(1, Tb, 0, Ta);
    EXPECT_TRUE(d.ok && back.ok) << d.error;
    const Features fa = features(a, Ta), fb = features(b, Tb);
    if (cores_meet(fa, fb)) {
      ++st.overlapping;
      EXPECT_LT(d.distance, 0.0) << "trial " << trial;
      EXPECT_LT(back.distance, 0.0) << "trial " << trial;
      EXPECT_TRUE(std::isfinite(d.distance));
      continue;
    }
    const double expected = brute_core_distance(fa, fb) - fa.r - fb.r;
    if (expected > 0.0)
      ++st.apart;
    else
      ++st.overlapping;  // the radii overlap: exact too, from the cores
    st.worst_error = std::max(st.worst_error, std::abs(d.distance - expected));
    EXPECT_NEAR(d.distance, expected, 1e-9) << "trial " << trial << ": " << a.describe() << " vs " << b.describe();
    st.worst_symmetry = std::max(st.worst_symmetry, std::abs(d.distance - back.distance));
    EXPECT_NEAR(d.distance, back.distance, 1e-10);
    const double w = std::max(surface_gap(fa, d.point_a), surface_gap(fb, d.point_b));
    st.worst_witness = std::max(st.worst_witness, w);
    EXPECT_LE(w, 1e-9) << "trial " << trial;
    EXPECT_NEAR((d.point_a - d.point_b).norm(), std::abs(d.distance), 1e-9);
  }
  return st;
}

void report(const char* what, const PairStats& st) {
  std::printf(
      "hull vs %s: %d apart, %d overlapping; worst |d - brute| %.2e m, witness off the surface %.2e m, "
      "|d(a,b) - d(b,a)| %.2e m\n",
      what, st.apart, st.overlapping, st.worst_error, st.worst_witness, st.worst_symmetry);
}

TEST(ConvexDistance, HullVsSphereMatchesTheBruteForce) {
  const PairStats st = check_pairs(ShapeSpec::Kind::kSphere, 1500, 1);
  report("sphere", st);
  EXPECT_GT(st.apart, 300);
  EXPECT_GT(st.overlapping, 50);
}

TEST(ConvexDistance, HullVsCapsuleMatchesTheBruteForce) {
  const PairStats st = check_pairs(ShapeSpec::Kind::kCapsule, 1500, 2);
  report("capsule", st);
  EXPECT_GT(st.apart, 300);
  EXPECT_GT(st.overlapping, 50);
}

TEST(ConvexDistance, HullVsBoxMatchesTheBruteForce) {
  const PairStats st = check_pairs(ShapeSpec::Kind::kBox, 1500, 3);
  report("box", st);
  EXPECT_GT(st.apart, 300);
  EXPECT_GT(st.overlapping, 50);
}

TEST(ConvexDistance, HullVsHullMatchesTheBruteForce) {
  const PairStats st = check_pairs(ShapeSpec::Kind::kConvex, 1500, 4);
  report("hull", st);
  EXPECT_GT(st.apart, 300);
  EXPECT_GT(st.overlapping, 50);
}

// Touching and nearly touching: a hull's face against a box's face, a gap of 1e-6 down to 0 and -1e-6.
TEST(ConvexDistance, NearTouchingFacesKeepTheirSign) {
  std::vector<Vector3d> cube;
  for (int c = 0; c < 8; ++c) cube.emplace_back((c & 1) ? 0.1 : -0.1, (c & 2) ? 0.1 : -0.1, (c & 4) ? 0.1 : -0.1);
  ShapeSpec box;
  box.shape = ShapeSpec::Kind::kBox;
  box.size = std::array<double, 3>{0.4, 0.4, 0.4};
  const DistanceQuery q({convex_shape(cube, "cube.obj"), box});
  for (const double gap : {1e-3, 1e-6, 1e-9, 1e-11, -1e-9, -1e-6, -1e-3}) {
    Isometry3d Ta = Isometry3d::Identity(), Tb = Isometry3d::Identity();
    Ta.translation() = Vector3d(0.03, -0.02, 0.1 + 0.2 + gap);
    const ShapeDistance d = q.distance(0, Ta, 1, Tb);
    ASSERT_TRUE(d.ok);
    if (std::abs(gap) >= 1e-9) {
      EXPECT_EQ(d.distance > 0.0, gap > 0.0) << gap;
    }
    EXPECT_NEAR(d.distance, gap, 1e-12) << gap;  // overlapping: a face normal is the contact's
  }
}

// Overlapping: the translation by the depth along the normal separates the shapes (to rounding), so the depth is
// the one along that direction; the witness points are |d| apart along it, on the first shape.
TEST(ConvexDistance, AnOverlapIsUndoneByMovingItsDepthAlongItsNormal) {
  std::mt19937 rng(5);
  int checked = 0;
  for (int trial = 0; trial < 600; ++trial) {
    const ShapeSpec a = random_hull(rng);
    const ShapeSpec b = random_primitive(rng, kOthers[static_cast<std::size_t>(trial % 4)]);
    const DistanceQuery q({a, b});
    const Isometry3d Ta = random_pose(rng, 0.02), Tb = random_pose(rng, 0.05);
    const ShapeDistance d = q.distance(0, Ta, 1, Tb);
    ASSERT_TRUE(d.ok);
    if (!(d.distance < 0.0)) continue;
    ++checked;
    EXPECT_TRUE(std::isfinite(d.distance));
    const Vector3d diff = d.point_a - d.point_b;
    EXPECT_NEAR(diff.norm(), -d.distance, 1e-9);
    EXPECT_LE(surface_gap(features(a, Ta), d.point_a), 1e-9);
    const Vector3d u = -diff.normalized();  // from b towards a
    Isometry3d moved = Ta;
    moved.translation() += (-d.distance + 1e-9) * u;
    const ShapeDistance after = q.distance(0, moved, 1, Tb);
    EXPECT_GE(after.distance, -1e-9) << "trial " << trial << ": depth " << -d.distance;
  }
  EXPECT_GT(checked, 200);
}

// A sphere whose centre is inside a hull: the depth is exact, the centre's distance to the hull's boundary plus r.
TEST(ConvexDistance, ASphereInsideAHullHasItsExactDepth) {
  std::mt19937 rng(12);
  int checked = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const ShapeSpec a = random_hull(rng);
    const ShapeSpec b = random_primitive(rng, ShapeSpec::Kind::kSphere);
    const DistanceQuery q({a, b});
    const Isometry3d Ta = random_pose(rng, 0.02), Tb = random_pose(rng, 0.05);
    const Features fa = features(a, Ta);
    if (!inside_polytope(fa, Tb.translation())) continue;
    ++checked;
    const double expected = -(feature_distance(fa, Tb.translation()) + *b.radius);
    EXPECT_NEAR(q.distance(0, Ta, 1, Tb).distance, expected, 1e-12) << "trial " << trial;
    EXPECT_NEAR(q.distance(1, Tb, 0, Ta).distance, expected, 1e-12) << "trial " << trial;
  }
  EXPECT_GT(checked, 50);
}

// Apart, the distance's gradient with respect to b's translation is minus the unit normal from b to a.
TEST(ConvexDistance, TheGradientIsTheUnitNormal) {
  std::mt19937 rng(6);
  int checked = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const ShapeSpec a = random_hull(rng);
    const ShapeSpec b = random_primitive(rng, kOthers[static_cast<std::size_t>(trial % 4)]);
    const DistanceQuery q({a, b});
    const Isometry3d Ta = random_pose(rng, 0.05), Tb = random_pose(rng, 0.3);
    const ShapeDistance d = q.distance(0, Ta, 1, Tb);
    if (!(d.distance > 1e-3)) continue;
    ++checked;
    const Vector3d n = (d.point_a - d.point_b).normalized();
    const double h = 1e-6;
    Vector3d grad;
    for (int k = 0; k < 3; ++k) {
      Isometry3d plus = Tb, minus = Tb;
      plus.translation()(k) += h;
      minus.translation()(k) -= h;
      grad(k) = (q.distance(0, Ta, 1, plus).distance - q.distance(0, Ta, 1, minus).distance) / (2.0 * h);
    }
    EXPECT_LE((grad + n).norm(), 1e-5) << "trial " << trial << ": gradient " << grad.transpose() << ", normal "
                                       << n.transpose();
  }
  EXPECT_GT(checked, 100);
}

// A cylinder's support is smooth: GJK stops within 1e-13 of the distance; checked against a sampled cylinder.
TEST(ConvexDistance, HullVsCylinderIsCloseToASampledCylinder) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    const ShapeSpec a = random_hull(rng);
    const ShapeSpec c = random_primitive(rng, ShapeSpec::Kind::kCylinder);
    const DistanceQuery q({a, c});
    const Isometry3d Ta = random_pose(rng, 0.05), Tc = random_pose(rng, 0.4);
    const ShapeDistance d = q.distance(0, Ta, 1, Tc);
    ASSERT_TRUE(d.ok);
    if (!(d.distance > 0.0)) continue;
    // The witness on the cylinder is on it: within its radius and half length, on its side or a cap.
    const Vector3d local = Tc.inverse() * d.point_b;
    const double rho = std::hypot(local.x(), local.y()), half = 0.5 * *c.length;
    EXPECT_LE(rho, *c.radius + 1e-9);
    EXPECT_LE(std::abs(local.z()), half + 1e-9);
    EXPECT_TRUE(std::abs(rho - *c.radius) < 1e-9 || std::abs(std::abs(local.z()) - half) < 1e-9);
    EXPECT_LE(surface_gap(features(a, Ta), d.point_a), 1e-9);
    // No point of a fine sampling of the cylinder is nearer the hull than d (each sample is a sphere of radius
    // 1e-12, whose distance to the hull is exact).
    ShapeSpec dot;
    dot.shape = ShapeSpec::Kind::kSphere;
    dot.radius = 1e-12;
    const DistanceQuery qp({a, dot});
    double sampled = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 24; ++i) {
      for (int j = 0; j < 48; ++j) {
        const double ang = j * 2.0 * M_PI / 48, z = -half + i * (2.0 * half / 24);
        for (const double rr : {*c.radius, 0.5 * *c.radius}) {
          Isometry3d Tp = Isometry3d::Identity();
          Tp.translation() = Tc * Vector3d(rr * std::cos(ang), rr * std::sin(ang), z);
          sampled = std::min(sampled, qp.distance(0, Ta, 1, Tp).distance);
        }
      }
    }
    EXPECT_LE(d.distance, sampled + 1e-9);
    EXPECT_GE(d.distance, sampled - 0.05 * *c.radius) << "far below a fine sampling";
  }
}

TEST(ConvexDistance, QueriesAllocateNothing) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  std::mt19937 rng(8);
  std::vector<ShapeSpec> shapes = {random_hull(rng),
                                   random_hull(rng),
                                   random_primitive(rng, ShapeSpec::Kind::kSphere),
                                   random_primitive(rng, ShapeSpec::Kind::kCapsule),
                                   random_primitive(rng, ShapeSpec::Kind::kBox),
                                   random_primitive(rng, ShapeSpec::Kind::kCylinder)};
  const DistanceQuery q(shapes);
  std::vector<Isometry3d> poses;
  for (int k = 0; k < 200; ++k) poses.push_back(random_pose(rng, 0.15));
  double sum = 0.0;
  int overlaps = 0;
  long count = 0;
  {
    const testing::AllocationCounter counter;
    for (std::size_t k = 0; k + 1 < poses.size(); ++k) {
      for (int b = 1; b < 6; ++b) {
        const ShapeDistance d = q.distance(0, poses[k], b, poses[k + 1]);
        sum += d.distance;
        overlaps += d.distance < 0.0 ? 1 : 0;
      }
      sum += q.nearest_point(0, poses[k], poses[k + 1].translation()).x();
      sum += q.lower_bound(0, poses[k], 3, poses[k + 1]);
    }
    count = counter.count();
  }
  EXPECT_EQ(count, 0);
  EXPECT_GT(overlaps, 50);  // MPR ran, too
  EXPECT_TRUE(std::isfinite(sum));
}

// nearest_point on a hull is exact (the brute force's nearest feature), and a point inside is its own.
TEST(ConvexDistance, NearestPointOnAHull) {
  std::mt19937 rng(9);
  for (int trial = 0; trial < 200; ++trial) {
    const ShapeSpec a = random_hull(rng);
    const DistanceQuery q({a});
    const Isometry3d T = random_pose(rng, 0.05);
    const Vector3d w = random_pose(rng, 0.2).translation();
    const Vector3d p = q.nearest_point(0, T, w);
    const Features f = features(a, T);
    if (inside_polytope(f, w)) {
      EXPECT_LE((p - w).norm(), 1e-15);  // itself (through the shape's frame and back)
      continue;
    }
    EXPECT_NEAR((p - w).norm(), feature_distance(f, w), 1e-9);
    EXPECT_LE(feature_distance(f, p), 1e-9);
    // The lower bound is one.
    ShapeSpec s;
    s.shape = ShapeSpec::Kind::kSphere;
    s.radius = 0.01;
    const DistanceQuery q2({a, s});
    Isometry3d Ts = Isometry3d::Identity();
    Ts.translation() = w;
    EXPECT_LE(q2.lower_bound(0, T, 1, Ts), q2.distance(0, T, 1, Ts).distance + 1e-12);
  }
}

// ---- Hulls from meshes ----

TEST(ConvexHull, ACubesVerticesWithInteriorPointsMakeEightVertices) {
  std::mt19937 rng(10);
  std::uniform_real_distribution<double> u(-0.99, 0.99);
  std::vector<Vector3d> pts;
  for (int k = 0; k < 200; ++k) pts.emplace_back(u(rng), u(rng), u(rng));
  for (int c = 0; c < 8; ++c) pts.emplace_back((c & 1) ? 1.0 : -1.0, (c & 2) ? 1.0 : -1.0, (c & 4) ? 1.0 : -1.0);
  // Points on the faces too (not corners): not vertices of the hull.
  pts.emplace_back(1.0, 0.2, 0.3);
  pts.emplace_back(-0.5, 1.0, 0.0);
  std::shuffle(pts.begin(), pts.end(), rng);
  for (auto& p : pts) p += Vector3d(3.0, -1.0, 0.5);
  const ShapeSpec s = convex_shape(pts, "dir/cube.stl");
  ASSERT_EQ(s.shape, ShapeSpec::Kind::kConvex);
  ASSERT_TRUE(s.hull);
  EXPECT_EQ(s.hull->vertices.size(), 8u);
  EXPECT_EQ(s.hull->faces.size(), 12u);
  EXPECT_NEAR(s.hull->bound, std::sqrt(3.0), 1e-12);
  EXPECT_EQ((s.hull->half_extent - Vector3d::Ones()).norm(), 0.0);
  EXPECT_NEAR((Vector3d(s.xyz[0], s.xyz[1], s.xyz[2]) - Vector3d(3.0, -1.0, 0.5)).norm(), 0.0, 1e-15);
  for (const auto& v : s.hull->vertices) EXPECT_NEAR(v.cwiseAbs().minCoeff(), 1.0, 1e-15);
  // Faces counter-clockwise from outside: each normal points away from the centre.
  for (const auto& f : s.hull->faces) {
    const Vector3d& a = s.hull->vertices[static_cast<std::size_t>(f[0])];
    const Vector3d n = (s.hull->vertices[static_cast<std::size_t>(f[1])] - a)
                           .cross(s.hull->vertices[static_cast<std::size_t>(f[2])] - a);
    EXPECT_GT(n.dot(a), 0.0);
  }
  EXPECT_EQ(s.describe(), "convex(8 vertices, 12 faces, from cube.stl)");
  // A copy shares the hull.
  const ShapeSpec copy = s.placed(Isometry3d::Identity());
  EXPECT_EQ(copy.hull.get(), s.hull.get());
}

TEST(ConvexHull, FlatOrTooFewPointsAreRefusedNamingTheMesh) {
  std::vector<Vector3d> flat;
  for (int k = 0; k < 20; ++k) flat.emplace_back(std::cos(k), std::sin(k), 0.0);
  const auto message = [](const std::vector<Vector3d>& pts) {
    try {
      (void)convex_shape(pts, "meshes/plate.stl", 1, 3);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string m = message(flat);
  EXPECT_NE(m.find("meshes/plate.stl"), std::string::npos) << m;
  EXPECT_NE(m.find("piece 2 of 3"), std::string::npos) << m;
  EXPECT_NE(m.find("plane"), std::string::npos) << m;
  const std::string few = message({Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0, 1, 0), Vector3d(1, 0, 0)});
  EXPECT_NE(few.find("3 distinct vertices"), std::string::npos) << few;
  std::vector<Vector3d> line;
  for (int k = 0; k < 10; ++k) line.emplace_back(k, 2.0 * k, 0.5 * k);
  EXPECT_NE(message(line).find("plate.stl"), std::string::npos);
}

TEST(ConvexHull, AScenarioCannotWriteAConvexShape) {
  ShapeSpec s;
  s.shape = ShapeSpec::Kind::kConvex;
  try {
    check_config(s, ShapeSpec::schema());
    FAIL() << "expected an error";
  } catch (const FieldError& e) {
    EXPECT_NE(std::string(e.what()).find("collision_model = \"hull\""), std::string::npos) << e.what();
  }
  EXPECT_THROW(DistanceQuery({s}), std::invalid_argument);
  // In a scenario file: refused at the obstacle, with the same message.
  const fs::path dir = scratch_dir("hull_scenario");
  std::string text = shipped_scenario_text("panda_hulls_table_pole.toml");
  const std::string pole = "{ shape = \"capsule\", radius = 0.03, from = [0.25, -0.2, 0.4], to = [0.25, -0.2, 1.0] }";
  ASSERT_NE(text.find(pole), std::string::npos);
  text.replace(text.find(pole), pole.size(), "{ shape = \"convex\", file = \"pole.obj\" }");
  std::ofstream(dir / "s.toml") << text;
  try {
    (void)load_scenario(dir / "s.toml");
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("collision_model = \"hull\""), std::string::npos) << e.what();
  }
}

// A hull against a point cloud: measured to each cell's bounding ball, so never farther than the nearest point and
// at most a cell's half diagonal nearer.
TEST(ConvexDistance, AHullAgainstAPointCloud) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::vector<Vector3d> pts;
  for (int k = 0; k < 2000; ++k) pts.emplace_back(u(rng), u(rng), 0.3 * u(rng));
  const fs::path dir = scratch_dir("hull_cloud");
  {
    std::ofstream o(dir / "c.xyz");
    o.precision(17);
    for (const auto& p : pts) o << p.x() << " " << p.y() << " " << p.z() << "\n";
  }
  ShapeSpec cloud;
  cloud.shape = ShapeSpec::Kind::kPoints;
  cloud.file = dir / "c.xyz";
  const double edge = 0.02;
  cloud.resolution = edge;
  load_cloud(cloud);
  int reached = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const ShapeSpec a = random_hull(rng);
    const DistanceQuery q({a, cloud});
    Isometry3d Ta = random_pose(rng, 0.05);
    Ta.translation().z() += 0.3 + 0.1 * (trial % 3);
    const ShapeDistance d = q.distance(0, Ta, 1, Isometry3d::Identity());
    ASSERT_TRUE(d.ok);
    const Features f = features(a, Ta);
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& p : pts) nearest = std::min(nearest, inside_polytope(f, p) ? 0.0 : feature_distance(f, p));
    EXPECT_LE(d.distance, nearest + 1e-9) << "trial " << trial;
    EXPECT_GE(d.distance, nearest - std::sqrt(3.0) * edge - 1e-9) << "trial " << trial;
    if (d.distance > 0.0) {
      EXPECT_LE(surface_gap(f, d.point_a), 1e-9) << "trial " << trial;
    }
    reached += d.distance > 0.0 ? 0 : 1;
  }
  EXPECT_GT(reached, 0);  // some poses reach into the cloud
}

const char* kArm = R"(<robot name="arm">
  <link name="base"/>
  <link name="l1"><collision><origin xyz="0 0 0.5"/><geometry><mesh filename="two_vhacd.obj" scale="0.1 0.1 0.1"/>
    </geometry></collision></link>
  <link name="l2"><collision><geometry><mesh filename="L2_MESH"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 1"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>)";

fs::path write_arm(const std::string& name, const std::string& l2_mesh, const std::string& model) {
  const fs::path dir = scratch_dir(name);
  std::ofstream(dir / "two_vhacd.obj") << cube_obj("a", Vector3d(0, 0, 0), 0) << cube_obj("b", Vector3d(5, 0, 0), 8);
  std::ofstream(dir / "one.obj") << cube_obj("c", Vector3d(0, 0, 1), 0);
  std::ofstream(dir / "flat.obj") << "o flat\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
  std::string urdf = kArm;
  urdf.replace(urdf.find("L2_MESH"), 7, l2_mesh);
  std::ofstream(dir / "arm.urdf") << urdf;
  std::ofstream(dir / "arm.toml") << "urdf = \"arm.urdf\"\nbase_link = \"base\"\ntip_link = \"l2\"\n" << model;
  return dir / "arm.toml";
}

TEST(ConvexHull, ADecompositionKeepsItsPiecesOneHullEach) {
  const RobotModel robot = load_robot(write_arm("hull_pieces", "one.obj", "collision_model = \"hull\"\n"));
  ASSERT_EQ(robot.link_shapes().size(), 3u);  // two pieces on l1, one on l2
  for (const auto& s : robot.link_shapes()) {
    ASSERT_EQ(s.spec.shape, ShapeSpec::Kind::kConvex);
    EXPECT_EQ(s.spec.hull->vertices.size(), 8u);
  }
  // The pieces where the URDF puts them: scaled by 0.1, at z = 0.5 in l1's frame, the second 0.5 along x.
  const auto &p1 = robot.link_shapes()[0], &p2 = robot.link_shapes()[1];
  EXPECT_EQ(p1.link, 0);
  EXPECT_EQ(p2.link, 0);
  EXPECT_NEAR((p1.pose.translation() - Vector3d(0, 0, 0.5)).norm(), 0.0, 1e-6);
  EXPECT_NEAR((p2.pose.translation() - Vector3d(0.5, 0, 0.5)).norm(), 0.0, 1e-6);
  EXPECT_NEAR(p1.spec.hull->half_extent.x(), 0.1, 1e-6);
  EXPECT_NE(p1.spec.describe().find("two_vhacd.obj piece 1 of 2"), std::string::npos) << p1.spec.describe();
  EXPECT_NE(p2.spec.describe().find("piece 2 of 2"), std::string::npos);
  // A [[links]] entry may keep its link's capsule.
  const RobotModel mixed =
      load_robot(write_arm("hull_mixed", "one.obj",
                           "collision_model = \"hull\"\n[[links]]\nname = \"l1\"\nreplace = false\ncollision_model = "
                           "\"capsule\"\n"));
  ASSERT_EQ(mixed.link_shapes().size(), 2u);
  EXPECT_EQ(mixed.link_shapes()[0].spec.shape, ShapeSpec::Kind::kCapsule);
  EXPECT_EQ(mixed.link_shapes()[1].spec.shape, ShapeSpec::Kind::kConvex);
}

TEST(ConvexHull, AFlatMeshIsAnErrorNamingTheLinkAndTheFile) {
  try {
    (void)load_robot(write_arm("hull_flat", "flat.obj", "collision_model = \"hull\"\n"));
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("link 'l2'"), std::string::npos) << what;
    EXPECT_NE(what.find("flat.obj"), std::string::npos) << what;
    EXPECT_NE(what.find("plane"), std::string::npos) << what;
  }
  // The capsule model takes the same mesh.
  EXPECT_EQ(load_robot(write_arm("hull_flat_capsule", "flat.obj", "")).link_shapes().size(), 2u);
}

// The shipped mesh robots as hulls: one hull per piece of every mesh (the xArm6's decompositions keep their pieces),
// each holding every vertex of its piece.
TEST(ConvexHull, TheShippedMeshRobotsMakeHulls) {
  const RobotModel panda = load_robot(source_path("robots/franka_panda_hulls.toml"));
  EXPECT_EQ(panda.link_shapes().size(), 10u);
  std::size_t vertices = 0, faces = 0;
  for (const auto& s : panda.link_shapes()) {
    ASSERT_EQ(s.spec.shape, ShapeSpec::Kind::kConvex);
    vertices += s.spec.hull->vertices.size();
    faces += s.spec.hull->faces.size();
  }
  std::printf("franka_panda_hulls: %zu hulls, %zu vertices, %zu faces\n", panda.link_shapes().size(), vertices, faces);
  // Link 1's hull holds every vertex of link1.obj (in the link's frame).
  const MeshData link1 =
      read_mesh(source_path("robots/franka_panda_description/meshes/collision/link1.obj"), Vector3d::Ones());
  const auto& s1 = panda.link_shapes().front();
  const Features f = features(s1.spec, s1.pose);
  for (const auto& p : link1.pieces.front()) {
    EXPECT_TRUE(inside_polytope(f, p) || feature_distance(f, p) < 1e-9);
  }
  // The xArm6 with hulls: as many as its decompositions have pieces.
  const fs::path dir = scratch_dir("hull_xarm6");
  std::ofstream(dir / "xarm6.toml") << "urdf = \"" << source_path("robots/xarm6_description/xarm6_robot.urdf").string()
                                    << "\"\nbase_link = \"link_base\"\ntip_link = \"link6\"\n"
                                       "collision_model = \"hull\"\n";
  const RobotModel xarm = load_robot(dir / "xarm6.toml");
  std::size_t pieces = 0;
  for (const auto& file :
       fs::directory_iterator(source_path("robots/xarm6_description/xarm_description/meshes/xarm6/collision"))) {
    const std::string name = file.path().filename().string();
    if (name.rfind("link", 0) == 0 && name.find("_vhacd.obj") != std::string::npos) {
      pieces += read_mesh(file.path(), Vector3d::Ones()).pieces.size();
    }
  }
  std::size_t xv = 0, xf = 0;
  for (const auto& s : xarm.link_shapes()) {
    ASSERT_EQ(s.spec.shape, ShapeSpec::Kind::kConvex);
    xv += s.spec.hull->vertices.size();
    xf += s.spec.hull->faces.size();
  }
  std::printf("xarm6 (hull): %zu hulls, %zu vertices, %zu faces\n", xarm.link_shapes().size(), xv, xf);
  EXPECT_GT(xarm.link_shapes().size(), 6u);
  EXPECT_EQ(xarm.link_shapes().size(), pieces);
}

}  // namespace
}  // namespace redres

#include "redres/model/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>

namespace redres {

std::size_t MeshData::vertex_count() const {
  std::size_t n = 0;
  for (const auto& p : pieces) n += p.size();
  return n;
}

std::size_t DrawMesh::triangles() const {
  std::size_t n = 0;
  for (const Part& p : parts) n += p.indices.size() / 3;
  return n;
}

namespace {

// The smallest circle enclosing 2-D points (Welzl's algorithm, iterative, points shuffled with a fixed seed).
struct Circle {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  double r = 0.0;
  [[nodiscard]] bool holds(const Eigen::Vector2d& p) const { return (p - c).norm() <= r * (1.0 + 1e-12) + 1e-15; }
};

Circle circle_of(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return {(a + b) / 2.0, (a - b).norm() / 2.0}; }

Circle circle_of(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d ab = b - a, ac = c - a;
  const double d = 2.0 * (ab.x() * ac.y() - ab.y() * ac.x());
  if (std::abs(d) < 1e-300) {  // collinear: the widest pair
    Circle best = circle_of(a, b);
    for (const Circle& k : {circle_of(a, c), circle_of(b, c)}) {
      if (k.r > best.r) best = k;
    }
    return best;
  }
  const double b2 = ab.squaredNorm(), c2 = ac.squaredNorm();
  const Eigen::Vector2d u((ac.y() * b2 - ab.y() * c2) / d, (ab.x() * c2 - ac.x() * b2) / d);
  return {a + u, u.norm()};
}

Circle enclosing_circle(std::vector<Eigen::Vector2d> p) {
  std::mt19937 rng(7);
  std::shuffle(p.begin(), p.end(), rng);
  Circle c{p.front(), 0.0};
  for (std::size_t i = 1; i < p.size(); ++i) {
    if (c.holds(p[i])) continue;
    c = {p[i], 0.0};
    for (std::size_t j = 0; j < i; ++j) {
      if (c.holds(p[j])) continue;
      c = circle_of(p[i], p[j]);
      for (std::size_t k = 0; k < j; ++k) {
        if (!c.holds(p[k])) c = circle_of(p[i], p[j], p[k]);
      }
    }
  }
  return c;
}

}  // namespace

ShapeSpec fit_capsule(const std::vector<Eigen::Vector3d>& vertices) {
  if (vertices.empty()) throw std::invalid_argument("fit_capsule: expected at least one vertex");
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& v : vertices) mean += v;
  mean /= static_cast<double>(vertices.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& v : vertices) cov += (v - mean) * (v - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Eigen::Vector3d axis = eig.eigenvectors().col(2).normalized();  // the largest eigenvalue's
  const Eigen::Vector3d e1 = eig.eigenvectors().col(1).normalized(), e2 = axis.cross(e1).normalized();
  std::vector<Eigen::Vector2d> across;
  across.reserve(vertices.size());
  for (const auto& v : vertices) across.emplace_back((v - mean).dot(e1), (v - mean).dot(e2));
  const Circle circle = enclosing_circle(across);
  const double r = circle.r * (1.0 + 1e-12) + 1e-12;  // every vertex inside, rounding included
  // Each vertex at axial t, distance rho from the axis, is inside for segment ends a <= t + s and b >= t - s,
  // s = sqrt(r^2 - rho^2): the shortest segment is a = min(t + s), b = max(t - s).
  double a = 1e300, b = -1e300;
  for (std::size_t k = 0; k < vertices.size(); ++k) {
    const double t = (vertices[k] - mean).dot(axis);
    const double rho = (across[k] - circle.c).norm();
    const double s = std::sqrt(std::max(0.0, r * r - rho * rho));
    a = std::min(a, t + s);
    b = std::max(b, t - s);
  }
  const bool sphere = a >= b;  // short: every vertex is within r of one point between them
  const Eigen::Vector3d centre = mean + circle.c.x() * e1 + circle.c.y() * e2;
  ShapeSpec shape;
  shape.radius = r * (1.0 + 1e-12) + 1e-15;  // the ends put their extreme vertices on the surface: keep them inside
  if (sphere) {
    shape.shape = ShapeSpec::Kind::kSphere;
    const Eigen::Vector3d p = centre + 0.5 * (a + b) * axis;
    shape.xyz = {p.x(), p.y(), p.z()};
    return shape;
  }
  shape.shape = ShapeSpec::Kind::kCapsule;
  const Eigen::Vector3d p = centre + a * axis, q = centre + b * axis;
  shape.from = std::array<double, 3>{p.x(), p.y(), p.z()};
  shape.to = std::array<double, 3>{q.x(), q.y(), q.z()};
  return shape;
}

}  // namespace redres

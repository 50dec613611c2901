#include "model/shape_cores.hpp"

#include <cmath>

#include "model/closed_form_distance.hpp"

namespace redres {

namespace {

// A box or cylinder (shape k at T, in the cloud's frame) against a cloud's cells: each cell as its bounding ball
// (grown by g), measured to the shape's nearest point in closed form (project).
struct BallMetric final : OccupancyMap::Metric {
  BallMetric(const ShapeCores& owner, std::size_t shape, const Eigen::Isometry3d& pose, double grow)
      : impl(owner), k(shape), T(pose), g(grow) {}
  const ShapeCores& impl;
  std::size_t k;
  Eigen::Isometry3d T;
  double g;
  [[nodiscard]] double bound(const Eigen::Vector3d& c, double h, double /*best*/) const override {
    // A hull by its bounding ball (its exact projection is a GJK run; cell() makes it).
    if (impl.hull[k]) return (c - T.translation()).norm() - impl.bound[k] - std::sqrt(3.0) * h - g;
    return (c - impl.project(k, T, c)).norm() - std::sqrt(3.0) * h - g;
  }
  double cell(const Eigen::Vector3d& c, double h, Eigen::Vector3d& on_query, Eigen::Vector3d& on_cloud) const override {
    on_query = impl.project(k, T, c);
    const Eigen::Vector3d v = on_query - c;
    const double n = v.norm(), R = std::sqrt(3.0) * h + g;
    on_cloud = n > 0.0 ? Eigen::Vector3d(c + v * (R / n)) : c;
    return n - R;
  }
};

}  // namespace

ShapeDistance ShapeCores::convex_pair(std::size_t a, const Eigen::Isometry3d& Ta, std::size_t b,
                                      const Eigen::Isometry3d& Tb) const {
  ShapeDistance out;
  const convex::Result r = convex::distance(core(a, Ta), core(b, Tb));
  if (!(std::isfinite(r.distance) && r.point_a.allFinite() && r.point_b.allFinite())) {
    out.error = "the convex distance is not finite";
    return out;
  }
  out.ok = true;
  out.distance = r.distance;
  out.point_a = r.point_a;
  out.point_b = r.point_b;
  return out;
}

ShapeDistance ShapeCores::cloud_distance(int a, const Eigen::Isometry3d& Ta, int b, const Eigen::Isometry3d& Tb,
                                         double within) const {
  ShapeDistance out;
  const bool a_cloud = cloud[static_cast<std::size_t>(a)] != nullptr;
  const int k = a_cloud ? b : a;
  const auto ks = static_cast<std::size_t>(k);
  if (cloud[ks]) {
    out.error = "two clouds are not measured against each other";
    return out;
  }
  const OccupancyMap& map = *cloud[static_cast<std::size_t>(a_cloud ? a : b)];
  const Eigen::Isometry3d& Tc = a_cloud ? Ta : Tb;
  const Eigen::Isometry3d local = Tc.inverse() * (a_cloud ? Tb : Ta);  // the shape in the cloud's frame
  Eigen::Vector3d on_shape = Eigen::Vector3d::Zero(), on_cloud = Eigen::Vector3d::Zero();
  double d = 0.0;
  if (round[ks].round) {
    const Eigen::Vector3d z = local.linear().col(2) * round[ks].half_length;
    const RoundMetric m(local.translation() - z, local.translation() + z, round[ks].radius, map.grow());
    d = map.nearest(m, within, on_shape, on_cloud);
  } else {
    const BallMetric m(*this, ks, local, map.grow());
    d = map.nearest(m, within, on_shape, on_cloud);
  }
  out.ok = true;
  out.distance = d;
  if (std::isfinite(d)) {
    on_shape = Tc * on_shape;
    on_cloud = Tc * on_cloud;
  }
  out.point_a = a_cloud ? on_cloud : on_shape;
  out.point_b = a_cloud ? on_shape : on_cloud;
  return out;
}

void ShapeCores::polish(std::size_t a, const Eigen::Isometry3d& Ta, std::size_t b, const Eigen::Isometry3d& Tb,
                        ShapeDistance& out) const {
  Eigen::Vector3d pa = out.point_a, pb = out.point_b;
  double best = (pa - pb).norm();
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d qb = project(b, Tb, pa);
    const Eigen::Vector3d qa = project(a, Ta, qb);
    const double d = (qa - qb).norm();
    if (!(d < best)) break;
    const double gain = best - d;
    best = d;
    pa = qa;
    pb = qb;
    if (gain < 1e-15) break;
  }
  if (best < out.distance) {
    out.distance = best;
    out.point_a = pa;
    out.point_b = pb;
  }
}

}  // namespace redres

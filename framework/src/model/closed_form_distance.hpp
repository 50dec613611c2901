#pragma once
// Distances in closed form, exact to rounding, that DistanceQuery makes without FCL: between two segments' closest
// points (overlapping spheres and capsules), between a sphere or capsule and a box (round_box), and between a sphere
// or capsule and a cloud's cells (RoundMetric, the cells being boxes). Allocation-free. Private to model/.

#include <Eigen/Geometry>

#include "model/occupancy.hpp"

namespace redres {

// Closest points of segments [p0, p1] and [q0, q1] (a point is a segment of length zero): parameters s and t.
void closest_on_segments(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& q0,
                         const Eigen::Vector3d& q1, double& s, double& t);

// Signed distance between a sphere or capsule (axis [p0, p1] in the world, radius r) and a box (pose Tb, half sides
// h): the minimum over the axis of the point-box signed distance, minus r, found exactly. Apart, this is the exact
// distance. Overlapping, it is the axis-based measure also used for two capsules: exact for a sphere and for a
// capsule whose axis stays outside the box; when the axis crosses the box it is the depth of the deepest axis point
// below its nearest face (less than the true penetration), with the normal of that face. Witness points: on the
// round shape and on the box, with round - box = d u.
//
// Along the axis q(s) = q0 + s dq (box frame, s in [0, 1]) the squared distance outside the box is
// g(s) = sum_k max(0, |q_k(s)| - h_k)^2: convex, and a quadratic between the (at most six) values of s where some
// q_k(s) crosses +-h_k, so its minimum is the least of the pieces' clamped vertices. Where g reaches 0 the axis
// touches or enters the box, and the signed distance there is max_k (|q_k(s)| - h_k): the largest of six linear
// functions, convex, whose minimum lies at an end or where two of them cross (at most fifteen candidates).
void round_box(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, double r, const Eigen::Isometry3d& Tb,
               const Eigen::Vector3d& h, double& d, Eigen::Vector3d& on_round, Eigen::Vector3d& on_box,
               Eigen::Vector3d* normal = nullptr);

// A sphere or capsule (axis [p0, p1], radius r, in the cloud's frame) against a cloud's cells grown by g, exactly (the
// cell is a box: round_box).
struct RoundMetric final : OccupancyMap::Metric {
  RoundMetric(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double radius, double grow)
      : p0(from), p1(to), mid(0.5 * (from + to)), reach(0.5 * (to - from).norm() + radius + grow), r(radius), g(grow) {}
  Eigen::Vector3d p0, p1, mid;
  double reach;  // the radius of the ball about mid that holds the shape grown by g
  double r, g;
  [[nodiscard]] double bound(const Eigen::Vector3d& c, double h, double best) const override;
  double cell(const Eigen::Vector3d& c, double h, Eigen::Vector3d& on_query, Eigen::Vector3d& on_cloud) const override;
};

}  // namespace redres

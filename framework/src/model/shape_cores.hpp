#pragma once
// What DistanceQuery keeps of each shape for the measures it makes without FCL (collision.cpp builds it beside the FCL
// geometry): each shape as a core swept by a radius (model/convex_distance.hpp), a box's half sides, a cylinder's,
// a cloud's cells; the exact projection of a point on a shape, GJK's pairs polished by alternating projections, the
// pairs with a convex hull and the pairs with a cloud. Private to model/.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "redres/model/collision.hpp"
#include "redres/model/convex.hpp"

#include "model/convex_distance.hpp"
#include "model/occupancy.hpp"

namespace redres {

struct ShapeCores {
  struct Round {         // a sphere or capsule: a segment (local z axis) swept by a radius
    bool round = false;  // sphere or capsule
    double radius = 0.0;
    double half_length = 0.0;
  };
  std::vector<Round> round;
  std::vector<std::optional<Eigen::Vector3d>> box_half;  // a box's half sides
  std::vector<double> cylinder_radius;                   // a cylinder's radius (0 for other shapes)
  std::vector<double> cylinder_half;                     // a cylinder's half length
  std::vector<double> bound;                             // the radius of the ball about the centre that holds it
  // Clouds (octree, points): the occupied cells, and the bounding box of the grown cells in the cloud's frame.
  std::vector<std::shared_ptr<const OccupancyMap>> cloud;
  std::vector<Eigen::Vector3d> cloud_lo, cloud_hi;
  // Convex hulls, and every primitive as a core for the convex distance (model/convex_distance.hpp): the core's
  // vertices (none for a cylinder, whose support is smooth) and a point inside it, in the shape's frame.
  std::vector<std::shared_ptr<const ConvexHull>> hull;
  std::vector<std::vector<Eigen::Vector3d>> core_vertices;
  std::vector<Eigen::Vector3d> core_centre;
  std::vector<std::vector<Eigen::Vector4d>> core_planes;  // a box's or hull's face planes (unit outward normal, offset)

  // Shape k at pose T as a core swept by its radius.
  [[nodiscard]] convex::Core core(std::size_t k, const Eigen::Isometry3d& T) const {
    convex::Core c;
    c.vertices = core_vertices[k].empty() ? nullptr : core_vertices[k].data();
    c.count = static_cast<int>(core_vertices[k].size());
    c.cylinder_radius = cylinder_radius[k];
    c.cylinder_half = cylinder_half[k];
    c.centre = core_centre[k];
    c.planes = core_planes[k].empty() ? nullptr : core_planes[k].data();
    c.plane_count = static_cast<int>(core_planes[k].size());
    if (hull[k]) {
      c.first_neighbour = hull[k]->first_neighbour.data();
      c.neighbours = hull[k]->neighbours.data();
    }
    c.radius = round[k].round ? round[k].radius : 0.0;
    c.R = T.linear();
    c.t = T.translation();
    return c;
  }
  // A pair with a convex hull (neither a cloud).
  [[nodiscard]] ShapeDistance convex_pair(std::size_t a, const Eigen::Isometry3d& Ta, std::size_t b,
                                          const Eigen::Isometry3d& Tb) const;
  // A pair with a cloud (see DistanceQuery::distance).
  [[nodiscard]] ShapeDistance cloud_distance(int a, const Eigen::Isometry3d& Ta, int b, const Eigen::Isometry3d& Tb,
                                             double within) const;

  // The point of shape k (at T) nearest to the world point `w`: exact, closed form, in the shape's frame.
  [[nodiscard]] Eigen::Vector3d project(std::size_t k, const Eigen::Isometry3d& T, const Eigen::Vector3d& w) const {
    const Eigen::Vector3d p = T.linear().transpose() * (w - T.translation());
    Eigen::Vector3d q = p;
    if (cloud[k]) {
      q = p.cwiseMax(cloud_lo[k]).cwiseMin(cloud_hi[k]);  // the bounding box: for lower bounds only
    } else if (hull[k]) {
      // GJK from the point (a core of one vertex) to the hull: exact; the point itself when inside.
      const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
      convex::Core point;
      point.vertices = &origin;
      point.count = 1;
      point.t = p;
      Eigen::Vector3d on_point, on_hull;
      if (convex::core_distance(point, core(k, Eigen::Isometry3d::Identity()), on_point, on_hull) > 0.0) q = on_hull;
    } else if (box_half[k]) {
      q = p.cwiseMax(-*box_half[k]).cwiseMin(*box_half[k]);
    } else if (cylinder_radius[k] > 0.0) {
      q.z() = std::clamp(p.z(), -cylinder_half[k], cylinder_half[k]);
      const double radial = std::hypot(p.x(), p.y());
      if (radial > cylinder_radius[k]) q.head<2>() *= cylinder_radius[k] / radial;
    } else {
      const Round& r = round[k];
      const Eigen::Vector3d c(0.0, 0.0, std::clamp(p.z(), -r.half_length, r.half_length));
      const Eigen::Vector3d d = p - c;
      const double norm = d.norm();
      if (norm > r.radius) q = c + d * (r.radius / norm);
    }
    return T.translation() + T.linear() * q;
  }
  // Polishes a pair apart from GJK's witness points by alternating exact projections (p <- P_a(q), q <- P_b(p),
  // which only ever shortens |p - q| and converges to a closest pair of two convex shapes): GJK stops within its
  // tolerance of the distance, the polish takes it to rounding (a few iterations from GJK's answer).
  void polish(std::size_t a, const Eigen::Isometry3d& Ta, std::size_t b, const Eigen::Isometry3d& Tb,
              ShapeDistance& out) const;
};

}  // namespace redres

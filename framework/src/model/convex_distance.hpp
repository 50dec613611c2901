#pragma once
// Signed distances between convex shapes given by support functions (docs/collision.md, "Convex hulls"): each shape
// is a core (a polytope: its vertices; or a cylinder, whose support function is smooth) swept by a radius, so a sphere
// is a point and r, a capsule a segment and r, a box its 8 corners, a hull its vertices.
//
// Apart, or overlapping by less than the radii (the cores apart): GJK on the cores, with a fixed-size simplex and the
// closest point of each simplex found by region tests, run until a support point repeats (exact for polytopes, to
// rounding) or the gap closes to 1e-13 of the distance (a cylinder); the distance is the cores' less the radii, exact
// either way. Cores that overlap: the depth along a direction n is the exact overlap of the two shapes' extents along
// it (h_a(n) + h_b(-n)), the translation along n that separates them, at least the penetration depth; the direction
// is the best of libccd's MPR (Minkowski portal refinement; never EPA) and the cores' face normals, which makes the
// depth exact when one core is a point (a sphere in a hull) and when a face of one core is the contact.
// Allocation-free.

#include <Eigen/Geometry>

namespace redres::convex {

/// A core swept by a radius, at a world pose.
struct Core {
  const Eigen::Vector3d* vertices = nullptr;  //!< the polytope's vertices in the shape's frame (null: a cylinder)
  int count = 0;                              //!< how many
  /// A hull's vertex neighbours (ConvexHull::first_neighbour, neighbours): the support point is then found by climbing
  /// from the last one found (exact on a convex polytope: a vertex no neighbour improves on is a maximum). Null: a
  /// loop.
  const int* first_neighbour = nullptr;
  const int* neighbours = nullptr;
  mutable int last = 0;                     //!< where the climb starts (the previous support vertex of this query)
  double cylinder_radius = 0.0;             //!< a cylinder's radius (when vertices is null)
  double cylinder_half = 0.0;               //!< a cylinder's half length (along local z)
  const Eigen::Vector4d* planes = nullptr;  //!< a polytope's face planes in its frame (unit outward n, h: n.x <= h)
  int plane_count = 0;                      //!< how many (none for a point or a segment)
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  //!< a point inside the core, in the shape's frame
  double radius = 0.0;                               //!< the radius the core is swept by
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();   //!< the shape's world pose
  Eigen::Vector3d t = Eigen::Vector3d::Zero();

  /// The core's point farthest along the world direction `d` (a vertex for a polytope: its index, else -1).
  int support(const Eigen::Vector3d& d, Eigen::Vector3d& out) const;
};

/// The outcome: the signed distance (> 0 apart, < 0 overlapping: minus the depth) and witness points on a and b
/// (world) with a - b = distance * u, u the unit normal from b towards a.
struct Result {
  double distance = 0.0;
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();
  bool cores_overlap = false;  //!< the depth came from MPR (the cores overlap)
};

/// The signed distance between a and b.
[[nodiscard]] Result distance(const Core& a, const Core& b);

/// The distance between the cores alone (>= 0; 0 when they overlap), with their closest points (world).
double core_distance(const Core& a, const Core& b, Eigen::Vector3d& on_a, Eigen::Vector3d& on_b);

}  // namespace redres::convex

#pragma once
/// @file
/// Convex hulls of collision meshes (`collision_model = "hull"`, docs/robot_format.md "Meshes"): computed by qhull
/// from a mesh piece's vertices, held by a ShapeSpec of kind convex (docs/collision.md, "Convex hulls").

#include <array>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/model/collision.hpp"

namespace redres {

/// A convex polytope: its vertices (the hull's corners only, in the hull's own frame, whose origin is the centre of
/// their bounding box) and its triangles (vertex indices, counter-clockwise seen from outside).
struct ConvexHull {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> faces;
  /// The vertices' neighbours along the faces' edges: those of vertex k are neighbours[first_neighbour[k] ..
  /// first_neighbour[k + 1]) (the support point is found by climbing them).
  std::vector<int> first_neighbour, neighbours;
  std::filesystem::path source;          //!< the mesh file it was made from (empty for one made from points)
  int piece = 0;                         //!< which piece of the mesh file (0-based)
  int pieces = 1;                        //!< how many pieces the file has
  Eigen::Vector3d half_extent{0, 0, 0};  //!< the vertices' bounding box: half its sides (it is centred on the origin)
  double bound = 0.0;                    //!< the largest distance of a vertex from the origin
};

/// The convex hull of `points` (qhull, triangulated), moved so that its bounding box is centred on the origin:
/// `centre` receives where that origin is in the points' frame. Throws std::invalid_argument, beginning with `what`
/// (e.g. the mesh file and piece), when the points cannot make a solid: fewer than 4 distinct points, all on one
/// plane or line, or not finite.
[[nodiscard]] std::shared_ptr<const ConvexHull> convex_hull(const std::vector<Eigen::Vector3d>& points,
                                                            const std::string& what, Eigen::Vector3d& centre);

/// A ShapeSpec of kind convex for the hull of `points` (convex_hull()), placed at the hull's centre in the points'
/// frame, its source recorded as `file` (piece `piece` of `pieces`).
[[nodiscard]] ShapeSpec convex_shape(const std::vector<Eigen::Vector3d>& points, const std::filesystem::path& file,
                                     int piece = 0, int pieces = 1);

}  // namespace redres

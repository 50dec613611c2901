#pragma once
/// @file
/// Meshes of robot descriptions as data: a collision mesh's vertices (MeshData), a mesh for drawing (DrawMesh), and
/// the capsule fitted to a mesh (docs/robot_format.md, "Meshes"). Finding and reading mesh files is
/// redres/parsers/mesh_file.hpp's.

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/model/collision.hpp"

namespace redres {

/// A mesh as read: its vertices (in the mesh file's frame, scaled), and its pieces: a convex decomposition (a
/// `*_vhacd.obj`) has several, each the vertices of one of the file's objects (an object's material groups together).
struct MeshData {
  std::filesystem::path file;                        //!< where it was read from
  std::vector<std::vector<Eigen::Vector3d>> pieces;  //!< the vertices of each piece (at least one, each non-empty)
  [[nodiscard]] std::size_t vertex_count() const;
};

/// A mesh for drawing (a URDF's visual meshes, `redres view`): its triangles, in parts of one colour each (the
/// file's materials' diffuse colours), in the mesh file's frame, scaled.
struct DrawMesh {
  struct Part {
    std::vector<float> positions;                   //!< x, y, z per vertex
    std::vector<std::uint32_t> indices;             //!< three per triangle
    std::array<float, 3> colour{0.7F, 0.7F, 0.7F};  //!< the material's diffuse colour (grey when it has none)
    bool coloured = false;                          //!< the file gives the colour
  };
  std::vector<Part> parts;
  [[nodiscard]] std::size_t triangles() const;
};

/// The capsule fitted to `vertices`: along their principal axis (the covariance's largest eigenvector), its radius
/// the smallest circle that encloses their projections on the plane across it, its segment the shortest that then
/// encloses every vertex. Every vertex is inside (to rounding). A ShapeSpec of kind capsule with `from` and `to`.
[[nodiscard]] ShapeSpec fit_capsule(const std::vector<Eigen::Vector3d>& vertices);

}  // namespace redres

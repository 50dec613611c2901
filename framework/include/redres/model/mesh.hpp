#pragma once
/// @file
/// Collision meshes of robot descriptions: reading them (STL, OBJ, COLLADA, ... through Assimp), finding them
/// (`package://NAME/...`, `file://...`, paths relative to the description) and turning them into the shapes redres
/// measures distances to (docs/robot_format.md, "Meshes").

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
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

/// Where to look for `package://NAME/...`: the packages a robot file names (`packages = { NAME = "dir" }`, first),
/// then each directory of REDRES_PACKAGE_PATH and ROS_PACKAGE_PATH (colon-separated) that holds NAME (as a
/// directory of that name), then the description's own directory (a `package://NAME/x` with NAME a folder beside
/// the URDF, as pybullet's descriptions use it).
struct PackagePaths {
  std::map<std::string, std::filesystem::path> named;  //!< from the robot file
  /// The environment's search directories, read now.
  static std::vector<std::filesystem::path> from_environment();
};

/// The file a mesh URI names, or throws std::runtime_error saying where it looked: `package://NAME/rest`,
/// `file:///abs/path`, an absolute path, or a path relative to `base_dir` (the URDF's directory).
[[nodiscard]] std::filesystem::path resolve_mesh(const std::string& uri, const std::filesystem::path& base_dir,
                                                 const PackagePaths& packages);

/// Reads a mesh file through Assimp, every node of its scene (with the scene's node transforms) as one piece, its
/// meshes together (an OBJ's material groups are one piece; a convex decomposition's pieces are its objects), each
/// vertex scaled by `scale`. Throws std::runtime_error naming the file when it cannot be read or holds no vertex.
[[nodiscard]] MeshData read_mesh(const std::filesystem::path& file, const Eigen::Vector3d& scale);

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

/// Reads a mesh file for drawing (as read_mesh(), within the same bounds): every mesh of its scene, its node
/// transforms applied, triangulated, one part per material. Throws std::runtime_error naming the file when it
/// cannot be read or holds no triangle.
[[nodiscard]] DrawMesh read_draw_mesh(const std::filesystem::path& file, const Eigen::Vector3d& scale);

/// The capsule fitted to `vertices`: along their principal axis (the covariance's largest eigenvector), its radius
/// the smallest circle that encloses their projections on the plane across it, its segment the shortest that then
/// encloses every vertex. Every vertex is inside (to rounding). A ShapeSpec of kind capsule with `from` and `to`.
[[nodiscard]] ShapeSpec fit_capsule(const std::vector<Eigen::Vector3d>& vertices);

}  // namespace redres

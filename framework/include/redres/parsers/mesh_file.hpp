#pragma once
/// @file
/// Mesh files of robot descriptions (docs/robot_format.md, "Meshes"): finding them (`package://NAME/...`,
/// `file://...`, paths relative to the description) and reading them (STL, OBJ, COLLADA, ... through Assimp) into the
/// mesh data of redres/model/mesh.hpp.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/model/mesh.hpp"

namespace redres {

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

/// Reads a mesh file for drawing (as read_mesh(), within the same bounds): every mesh of its scene, its node
/// transforms applied, triangulated, one part per material. Throws std::runtime_error naming the file when it
/// cannot be read or holds no triangle.
[[nodiscard]] DrawMesh read_draw_mesh(const std::filesystem::path& file, const Eigen::Vector3d& scale);

}  // namespace redres

#pragma once
/// @file
/// The files of cloud obstacles (docs/collision.md, "Point clouds and octrees"): OctoMap's octrees (.bt, .ot) and
/// point clouds (.ply, read through Assimp; .pcd, the Point Cloud Library's, version 0.7; .xyz), each checked as it is
/// read. What they hold becomes the obstacle's occupied cells through the model (occupancy_of_points(),
/// occupancy_of_octree(), redres/model/collision.hpp). Every problem is a std::invalid_argument naming the file, and
/// the line or byte where it went wrong.

#include <filesystem>
#include <vector>

#include <Eigen/Core>

#include "redres/model/collision.hpp"

namespace redres {

/// Reads an octree or point cloud obstacle's file (`spec.file`) into spec.cloud, unless it holds one already; nothing
/// for any other shape. The obstacle plugin reads its clouds with it once, at construction; a DistanceQuery takes only
/// clouds that are read.
void load_cloud(ShapeSpec& spec);

/// The points a `points` file (.ply, .pcd or .xyz) holds, as read (also for tests: brute-force distances).
[[nodiscard]] std::vector<Eigen::Vector3d> read_points(const std::filesystem::path& file);

}  // namespace redres

#pragma once
// The files a cloud obstacle is read from (private to model/): OctoMap's octrees (.bt, .ot) and point clouds (.ply
// through Assimp, .pcd, .xyz), each checked as it is read; load_cloud() (occupancy.cpp) puts them into an
// OccupancyMap. Every problem is a std::invalid_argument naming the file, and the line or byte.

#include <filesystem>
#include <memory>
#include <string>

#include <octomap/OcTree.h>

namespace redres::cloud_detail {

// Throws std::invalid_argument("<file>: <what>").
[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what);

// The file's extension in lower case (".bt", ".ply", ...).
std::string lower_extension(const std::filesystem::path& file);

// The file's bytes, within the input bounds of a cloud file (a regular file of at most 1 GiB).
std::string read_cloud_file(const std::filesystem::path& file);

// OctoMap's files: a text header ("# Octomap OcTree binary file" or "# Octomap OcTree file", comment lines, then
// `id`, `size`, `res` and `data` lines), then the nodes depth first. The header is read here, so that a wrong file is
// named precisely, and the nodes are walked once before OctoMap reads them: its readers recurse without a depth limit
// and read past the end of a truncated file, so only a tree that is whole and at most 16 levels deep reaches them.
std::unique_ptr<octomap::OcTree> read_octree(const std::filesystem::path& file, const std::string& text, bool binary);

}  // namespace redres::cloud_detail

#pragma once
// The occupied cells of a cloud obstacle (an OctoMap octree, read from a `.bt`/`.ot` file or built from a point
// cloud), and the nearest-cell search DistanceQuery makes on it. Private to the framework: OctoMap's headers stay
// out of the public ones.

#include <array>
#include <memory>

#include <octomap/OcTree.h>
#include <Eigen/Core>

#include "redres/model/collision.hpp"

namespace redres {

class OccupancyMap {
 public:
  OccupancyMap(std::unique_ptr<octomap::OcTree> tree, double grow, std::size_t points);

  /// The octree (inner nodes hold the largest occupancy of their children).
  [[nodiscard]] const octomap::OcTree& tree() const noexcept { return *tree_; }
  /// How far the occupied cells are grown (the obstacle's `radius`, m).
  [[nodiscard]] double grow() const noexcept { return grow_; }
  [[nodiscard]] const OccupancyInfo& info() const noexcept { return info_; }
  /// The half edge of the root cell (the tree spans [-root_half, root_half]^3 in the cloud's frame).
  [[nodiscard]] double root_half() const noexcept { return root_half_; }
  /// Whether any cell is occupied (false for an empty tree).
  [[nodiscard]] bool empty() const noexcept { return info_.cells == 0; }

  /// A query's measure of a cube (centre c, half edge h, in the cloud's frame): `bound` a lower bound on the distance
  /// to anything in the cube (it may stop at any bound not below `best`, the search's best so far), `cell` the distance to the occupied cube itself (grown by grow()), with the witness
  /// points on the query and on the grown cube.
  struct Metric {
    virtual ~Metric() = default;
    [[nodiscard]] virtual double bound(const Eigen::Vector3d& c, double h, double best) const = 0;
    virtual double cell(const Eigen::Vector3d& c, double h, Eigen::Vector3d& on_query,
                        Eigen::Vector3d& on_cloud) const = 0;
  };
  /// The nearest occupied cell to a query, by a depth-first search that visits each node's children nearest first and
  /// skips those whose bound is not below the best so far (which starts at `within`). Returns the distance (+inf when
  /// no cell is nearer than `within`) and its witness points (cloud frame). Allocation-free: the stack is 16 levels.
  double nearest(const Metric& m, double within, Eigen::Vector3d& on_query, Eigen::Vector3d& on_cloud) const;

 private:
  std::unique_ptr<octomap::OcTree> tree_;
  double grow_ = 0.0;
  double root_half_ = 0.0;
  OccupancyInfo info_;
};

}  // namespace redres

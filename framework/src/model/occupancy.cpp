// Cloud obstacles: OctoMap's octree of the occupied cells, built from points or from an OctoMap file's nodes (the files
// are read in parsers/cloud_file.cpp), and the nearest-cell search on it.

#include "model/occupancy.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "redres/common/error.hpp"

namespace redres {

OccupancyMap::OccupancyMap(std::unique_ptr<octomap::OcTree> tree, double grow, std::size_t points)
    : tree_(std::move(tree)), grow_(grow) {
  tree_->updateInnerOccupancy();
  root_half_ = tree_->getResolution() * static_cast<double>(1U << (tree_->getTreeDepth() - 1));
  info_.points = points;
  info_.resolution = tree_->getResolution();
  info_.memory_bytes = tree_->memoryUsage();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (auto it = tree_->begin_leafs(), end = tree_->end_leafs(); it != end; ++it) {
    if (!tree_->isNodeOccupied(*it)) continue;
    ++info_.cells;
    const octomap::OcTreeKey key = it.getKey();
    const unsigned depth = it.getDepth();
    const double h = 0.5 * it.getSize();
    const Eigen::Vector3d centre(tree_->keyToCoord(key[0], depth), tree_->keyToCoord(key[1], depth),
                                 tree_->keyToCoord(key[2], depth));
    lo = lo.cwiseMin(centre - Eigen::Vector3d::Constant(h));
    hi = hi.cwiseMax(centre + Eigen::Vector3d::Constant(h));
  }
  if (info_.points == 0) info_.points = info_.cells;
  if (info_.cells > 0) {
    info_.min = lo;
    info_.max = hi;
  }
}

namespace {
struct Search {
  const octomap::OcTree& tree;
  const OccupancyMap::Metric& metric;
  double best;
  Eigen::Vector3d on_query = Eigen::Vector3d::Zero(), on_cloud = Eigen::Vector3d::Zero();

  void visit(const octomap::OcTreeNode* node, const Eigen::Vector3d& c, double h) {
    if (!tree.isNodeOccupied(node)) return;  // an inner node holds its children's largest occupancy
    if (!tree.nodeHasChildren(node)) {
      Eigen::Vector3d a, b;
      const double d = metric.cell(c, h, a, b);
      if (d < best) {
        best = d;
        on_query = a;
        on_cloud = b;
      }
      return;
    }
    std::array<std::pair<double, unsigned>, 8> kids{};
    int n = 0;
    const double hc = 0.5 * h;
    const auto centre = [&](unsigned i) {
      return Eigen::Vector3d(c.x() + ((i & 1U) ? hc : -hc), c.y() + ((i & 2U) ? hc : -hc),
                             c.z() + ((i & 4U) ? hc : -hc));
    };
    for (unsigned i = 0; i < 8; ++i) {
      if (!tree.nodeChildExists(node, i)) continue;
      const double bound = metric.bound(centre(i), hc, best);
      if (bound < best) kids[static_cast<std::size_t>(n++)] = {bound, i};
    }
    for (int i = 1; i < n; ++i) {  // insertion sort of at most 8, nearest first
      for (int j = i; j > 0 && kids[static_cast<std::size_t>(j)] < kids[static_cast<std::size_t>(j - 1)]; --j)
        std::swap(kids[static_cast<std::size_t>(j)], kids[static_cast<std::size_t>(j - 1)]);
    }
    for (int k = 0; k < n; ++k) {
      const auto [bound, i] = kids[static_cast<std::size_t>(k)];
      if (!(bound < best)) break;
      visit(tree.getNodeChild(node, i), centre(i), hc);
    }
  }
};
}  // namespace

double OccupancyMap::nearest(const Metric& m, double within, Eigen::Vector3d& on_query,
                             Eigen::Vector3d& on_cloud) const {
  const octomap::OcTreeNode* root = tree_->getRoot();
  if (root == nullptr || empty()) return std::numeric_limits<double>::infinity();
  Search s{*tree_, m, within};
  if (m.bound(Eigen::Vector3d::Zero(), root_half_, within) < within) s.visit(root, Eigen::Vector3d::Zero(), root_half_);
  if (!(s.best < within)) return std::numeric_limits<double>::infinity();
  on_query = s.on_query;
  on_cloud = s.on_cloud;
  return s.best;
}

namespace {

// The nodes of an OctoMap file are walked before OctoMap reads them: its readers recurse without a depth limit and read
// past the end of a truncated file, so only a tree that is whole and at most 16 levels deep reaches them. Each walk
// returns the bytes the subtree takes, or 0 when it ends early or nests too deep.
// Binary (.bt): two bytes a node, two bits a child (01 occupied leaf, 10 free leaf, 11 inner node, 00 none).
std::size_t binary_subtree(const char* p, std::size_t n, int depth) {
  if (n < 2 || depth > 16) return 0;
  std::size_t used = 2;
  for (int b = 0; b < 2; ++b) {
    const auto bits = static_cast<unsigned char>(p[b]);
    for (int i = 0; i < 4; ++i) {
      if (((bits >> (2 * i)) & 3U) != 3U) continue;
      const std::size_t sub = binary_subtree(p + used, n - used, depth + 1);
      if (sub == 0) return 0;
      used += sub;
    }
  }
  return used;
}
// Full (.ot, an OcTree's): a 4-byte value and a byte of child flags a node.
std::size_t full_subtree(const char* p, std::size_t n, int depth) {
  if (n < 5 || depth > 16) return 0;
  std::size_t used = 5;
  const auto bits = static_cast<unsigned char>(p[4]);
  for (int i = 0; i < 8; ++i) {
    if (((bits >> i) & 1U) == 0) continue;
    const std::size_t sub = full_subtree(p + used, n - used, depth + 1);
    if (sub == 0) return 0;
    used += sub;
  }
  return used;
}

}  // namespace

std::shared_ptr<const OccupancyMap> occupancy_of_points(const std::vector<Eigen::Vector3d>& points, double resolution,
                                                        double grow) {
  REDRES_REQUIRE(resolution > 0.0 && std::isfinite(resolution), "occupancy_of_points", "resolution > 0");
  auto tree = std::make_unique<octomap::OcTree>(resolution);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    octomap::OcTreeKey key;
    const double reach = resolution * 32767.0;  // checked first: OctoMap converts to int before it checks
    if (!(p.cwiseAbs().maxCoeff() < reach) ||
        !tree->coordToKeyChecked(
            octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())), key)) {
      std::ostringstream s;
      s << "point " << i + 1 << " (" << p.transpose() << ") is outside the octree's reach: at resolution " << resolution
        << " m it spans +-" << resolution * 32768.0 << " m";
      throw std::invalid_argument(s.str());
    }
    tree->updateNode(key, true, true);
  }
  auto cloud = std::make_shared<const OccupancyMap>(std::move(tree), grow, points.size());
  if (cloud->empty()) throw std::invalid_argument("has no occupied cell");
  return cloud;
}

std::shared_ptr<const OccupancyMap> occupancy_of_octree(std::string_view nodes, bool binary, double resolution,
                                                        long size, double grow) {
  const std::size_t left = nodes.size();
  const std::size_t used =
      left == 0 ? 0 : (binary ? binary_subtree(nodes.data(), left, 0) : full_subtree(nodes.data(), left, 0));
  if (left > 0 && used == 0)
    throw std::invalid_argument("its nodes end early or nest deeper than 16 levels: the file is cut or corrupt");
  auto tree = std::make_unique<octomap::OcTree>(resolution);
  if (used > 0) {
    std::istringstream in(std::string(nodes.data(), used));
    if (binary) {
      tree->readBinaryData(in);
    } else {
      tree->readData(in);
    }
    if (!in) throw std::invalid_argument("OctoMap could not read its nodes");
  }
  if (size >= 0 && static_cast<long>(tree->size()) != size) {
    throw std::invalid_argument("the header says " + std::to_string(size) + " nodes, the data holds " +
                                std::to_string(tree->size()));
  }
  auto cloud = std::make_shared<const OccupancyMap>(std::move(tree), grow, 0);
  if (cloud->empty()) throw std::invalid_argument("has no occupied cell");
  return cloud;
}

OccupancyInfo occupancy_info(const OccupancyMap& cloud) { return cloud.info(); }

std::vector<std::array<double, 4>> occupied_cells(const OccupancyMap& cloud) {
  std::vector<std::array<double, 4>> out;
  const octomap::OcTree& t = cloud.tree();
  for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it) {
    if (!t.isNodeOccupied(*it)) continue;
    // The centre in double (getCoordinate() rounds it to float).
    const octomap::OcTreeKey key = it.getKey();
    const unsigned depth = it.getDepth();
    out.push_back(
        {t.keyToCoord(key[0], depth), t.keyToCoord(key[1], depth), t.keyToCoord(key[2], depth), it.getSize()});
  }
  return out;
}

}  // namespace redres

// Cloud obstacles: OctoMap's octree of the occupied cells, read from an octree file or built from a point cloud
// (model/cloud_files.hpp reads the files), and the nearest-cell search on it.

#include "model/occupancy.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "model/cloud_files.hpp"
#include "redres/common/error.hpp"

namespace redres {

using cloud_detail::fail;
using cloud_detail::lower_extension;
using cloud_detail::read_cloud_file;
using cloud_detail::read_octree;

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

void load_cloud(ShapeSpec& spec) {
  if (spec.cloud || !spec.is_cloud()) return;
  if (!spec.file || spec.file->empty()) throw std::invalid_argument("a cloud obstacle needs `file`");
  const std::filesystem::path& file = *spec.file;
  const double grow = spec.radius.value_or(0.0);
  if (spec.shape == ShapeSpec::Kind::kOctree) {
    const std::string ext = lower_extension(file);
    if (ext != ".bt" && ext != ".ot")
      fail(file, "an octree is read from an OctoMap .bt or .ot file (saw '" + ext + "')");
    const std::string text = read_cloud_file(file);
    spec.cloud = std::make_shared<const OccupancyMap>(read_octree(file, text, ext == ".bt"), grow, 0);
  } else {
    const std::vector<Eigen::Vector3d> points = read_points(file);
    if (points.empty()) fail(file, "holds no points");
    auto tree = std::make_unique<octomap::OcTree>(*spec.resolution);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d& p = points[i];
      octomap::OcTreeKey key;
      const double reach = *spec.resolution * 32767.0;  // checked first: OctoMap converts to int before it checks
      if (!(p.cwiseAbs().maxCoeff() < reach) ||
          !tree->coordToKeyChecked(
              octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())), key)) {
        std::ostringstream s;
        s << "point " << i + 1 << " (" << p.transpose() << ") is outside the octree's reach: at resolution "
          << *spec.resolution << " m it spans +-" << *spec.resolution * 32768.0 << " m";
        fail(file, s.str());
      }
      tree->updateNode(key, true, true);
    }
    spec.cloud = std::make_shared<const OccupancyMap>(std::move(tree), grow, points.size());
  }
  if (spec.cloud->empty()) fail(file, "has no occupied cell");
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

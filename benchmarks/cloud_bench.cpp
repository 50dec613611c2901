// Cloud obstacles: one distance query between a link shape and the shipped 100,000-point scan
// (configs/clouds/panda_workcell.ply, 1 cm cells), by redres's nearest-first search and, for the ratio in the same
// run, by FCL 0.7's own OcTree distance on the same OctoMap cells (GJK on every cell it visits). The poses are 64
// random capsule placements over the table, some within 0.1 m of the cloud and some beyond it; the bounded search
// (within = 0.1 m, what obstacle_avoidance asks) is timed too. Also: reading the file and building the tree.
// BM_CloudDistance/<how>: time per query.

#include <random>
#include <vector>

#include <benchmark/benchmark.h>
#include <fcl/geometry/octree/octree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>
#include <octomap/OcTree.h>

#include "redres/model/collision.hpp"
#include "redres/parsers/cloud_file.hpp"
#include "test_util.hpp"

namespace {

using redres::ShapeSpec;

ShapeSpec cloud_spec() {
  ShapeSpec s;
  s.shape = ShapeSpec::Kind::kPoints;
  s.file = redres::source_path("configs/clouds/panda_workcell.ply");
  s.resolution = 0.01;
  s.radius = 0.0;  // FCL's cells are not grown: the same obstacle for both
  return s;
}

ShapeSpec link(ShapeSpec::Kind kind) {
  ShapeSpec s;
  s.shape = kind;
  if (kind == ShapeSpec::Kind::kBox) {
    s.size = std::array<double, 3>{0.08, 0.1, 0.2};
  } else {
    s.radius = 0.05;
    s.length = 0.2;
  }
  return s;
}

std::vector<Eigen::Isometry3d> poses() {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Isometry3d> out;
  for (int k = 0; k < 64; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    T.translation() << 0.45 + 0.3 * u(rng), 0.3 * u(rng), 0.72 + 0.12 * u(rng);  // over the table, 0.1 to 0.35 m up
    out.push_back(T);
  }
  return out;
}

void BM_CloudDistance(benchmark::State& state, ShapeSpec::Kind kind, double within) {
  ShapeSpec cloud = cloud_spec();
  redres::load_cloud(cloud);
  const redres::DistanceQuery q({link(kind), cloud});
  const auto at = poses();
  std::size_t k = 0;
  int near = 0;
  for (auto _ : state) {
    const auto d = q.distance(0, at[k], 1, Eigen::Isometry3d::Identity(), within);
    benchmark::DoNotOptimize(d.distance);
    near += d.distance < 0.1 ? 1 : 0;
    k = (k + 1) % at.size();
  }
  state.counters["within_0.1m"] = benchmark::Counter(near, benchmark::Counter::kAvgIterations);
}

void BM_CloudDistanceFcl(benchmark::State& state) {
  const auto points = redres::read_points(redres::source_path("configs/clouds/panda_workcell.ply"));
  auto tree = std::make_shared<octomap::OcTree>(0.01);
  for (const auto& p : points) tree->updateNode(octomap::point3d(p.x(), p.y(), p.z()), true, true);
  tree->updateInnerOccupancy();
  fcl::CollisionObjectd cloud(std::make_shared<fcl::OcTreed>(std::shared_ptr<const octomap::OcTree>(tree)));
  auto capsule = std::make_shared<fcl::Capsuled>(0.05, 0.2);
  const fcl::DistanceRequestd request(true, false, 0.0, 0.0, 1e-12, fcl::GST_LIBCCD);
  const auto at = poses();
  std::size_t k = 0;
  for (auto _ : state) {
    fcl::CollisionObjectd link(capsule, fcl::Transform3d(at[k].matrix()));
    fcl::DistanceResultd result;
    fcl::distance(&link, &cloud, request, result);
    benchmark::DoNotOptimize(result.min_distance);
    k = (k + 1) % at.size();
  }
}

void BM_CloudLoad(benchmark::State& state) {
  for (auto _ : state) {
    ShapeSpec cloud = cloud_spec();
    redres::load_cloud(cloud);
    benchmark::DoNotOptimize(cloud.cloud.get());
  }
}

}  // namespace

BENCHMARK_CAPTURE(BM_CloudDistance, capsule, ShapeSpec::Kind::kCapsule, std::numeric_limits<double>::infinity())
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_CloudDistance, capsule_within_0_1m, ShapeSpec::Kind::kCapsule, 0.1)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_CloudDistance, box, ShapeSpec::Kind::kBox, std::numeric_limits<double>::infinity())
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CloudDistanceFcl)->Name("BM_CloudDistance/capsule_fcl_octree")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CloudLoad)->Unit(benchmark::kMillisecond);

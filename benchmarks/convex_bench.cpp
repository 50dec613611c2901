// Convex hulls (collision_model = "hull"): the cost of one distance query per pair, for the shipped robots' real hulls
// (the Panda's link meshes, the xArm6's convex decomposition pieces) against a capsule, a box, a sphere and another
// hull, beside the capsule-capsule pair (FCL's closed form) as the baseline. Every query has a new pose (256 random
// poses, cycled), the pair apart by about 0.1 m; BM_ConvexOverlap has the cores overlap (GJK, then MPR).
// Compare within one run, as ratios to capsule-capsule: the machine is noisy.

#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "redres/model/collision.hpp"
#include "redres/model/convex.hpp"
#include "redres/parsers/mesh_file.hpp"
#include "test_util.hpp"

namespace {

using redres::ShapeSpec;

// The hull of a shipped mesh's piece.
ShapeSpec real_hull(const std::string& mesh, int piece = 0) {
  const auto file = redres::source_path(mesh);
  const redres::MeshData data = redres::read_mesh(file, Eigen::Vector3d::Ones());
  return redres::convex_shape(data.pieces.at(static_cast<std::size_t>(piece)), file, piece,
                              static_cast<int>(data.pieces.size()));
}

ShapeSpec hull_of(int which) {
  switch (which) {
    case 0: return real_hull("robots/franka_panda_description/meshes/collision/link4.obj");
    case 1: return real_hull("robots/franka_panda_description/meshes/collision/link1.obj");
    default: return real_hull("robots/xarm6_description/xarm_description/meshes/xarm6/collision/link3_vhacd.obj");
  }
}

ShapeSpec primitive(ShapeSpec::Kind kind) {
  ShapeSpec s;
  s.shape = kind;
  if (kind == ShapeSpec::Kind::kBox) {
    s.size = std::array<double, 3>{0.2, 0.3, 0.4};
  } else {
    s.radius = 0.05;
  }
  if (kind == ShapeSpec::Kind::kCapsule) s.length = 0.3;
  return s;
}

// 256 pose pairs: a at the origin turned at random, b turned at random with its centre `reach` m from a's.
std::vector<std::pair<Eigen::Isometry3d, Eigen::Isometry3d>> poses(double reach) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<std::pair<Eigen::Isometry3d, Eigen::Isometry3d>> out;
  const auto turn = [&] {
    Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
    return q.normalized().toRotationMatrix();
  };
  for (int k = 0; k < 256; ++k) {
    Eigen::Isometry3d Ta = Eigen::Isometry3d::Identity(), Tb = Eigen::Isometry3d::Identity();
    Ta.linear() = turn();
    Tb.linear() = turn();
    Tb.translation() = reach * Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    out.emplace_back(Ta, Tb);
  }
  return out;
}

void run(benchmark::State& state, const ShapeSpec& a, const ShapeSpec& b, double reach, const std::string& label) {
  const redres::DistanceQuery q({a, b});
  const auto list = poses(reach);
  std::size_t k = 0;
  int negative = 0;
  long queries = 0;
  for (auto _ : state) {
    const auto& [Ta, Tb] = list[k];
    k = (k + 1) & 255u;
    const redres::ShapeDistance d = q.distance(0, Ta, 1, Tb);
    negative += d.distance < 0.0 ? 1 : 0;
    ++queries;
    benchmark::DoNotOptimize(d.distance);
  }
  state.counters["overlapping"] = static_cast<double>(negative) / static_cast<double>(std::max(queries, 1L));
  std::string text = label;
  if (a.hull) text += " (" + std::to_string(a.hull->vertices.size()) + " vertices)";
  state.SetLabel(text);
}

// The baseline: two capsules (FCL's closed form).
void BM_ConvexBaselineCapsuleCapsule(benchmark::State& state) {
  run(state, primitive(ShapeSpec::Kind::kCapsule), primitive(ShapeSpec::Kind::kCapsule), 0.55, "capsule-capsule");
}
BENCHMARK(BM_ConvexBaselineCapsuleCapsule);

// arg: which hull (0: Panda link4, 1: Panda link1, 2: xArm6 link3 piece 1); the other shape by name.
void BM_ConvexHullCapsule(benchmark::State& state) {
  run(state, hull_of(static_cast<int>(state.range(0))), primitive(ShapeSpec::Kind::kCapsule), 0.55, "hull-capsule");
}
void BM_ConvexHullSphere(benchmark::State& state) {
  run(state, hull_of(static_cast<int>(state.range(0))), primitive(ShapeSpec::Kind::kSphere), 0.45, "hull-sphere");
}
void BM_ConvexHullBox(benchmark::State& state) {
  run(state, hull_of(static_cast<int>(state.range(0))), primitive(ShapeSpec::Kind::kBox), 0.65, "hull-box");
}
void BM_ConvexHullHull(benchmark::State& state) {
  run(state, hull_of(static_cast<int>(state.range(0))), hull_of(static_cast<int>(state.range(0))), 0.55, "hull-hull");
}
// Overlapping cores: GJK finds them meeting, MPR gives the direction.
void BM_ConvexOverlap(benchmark::State& state) {
  run(state, hull_of(static_cast<int>(state.range(0))), hull_of(static_cast<int>(state.range(0))), 0.02,
      "hull-hull overlapping");
}
BENCHMARK(BM_ConvexHullCapsule)->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(BM_ConvexHullSphere)->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(BM_ConvexHullBox)->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(BM_ConvexHullHull)->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(BM_ConvexOverlap)->Arg(0)->Arg(2);

}  // namespace

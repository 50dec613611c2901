// Loading a robot file, from the text to a RobotModel: the hand-written Panda (robots/franka_panda.toml, modified DH
// with capsules written out: the baseline of the ratios), the same arm from its URDF with hand-written capsules
// (robots/franka_panda_urdf.toml), and the two arms as their makers publish them, meshes read through Assimp and
// turned into fitted capsules (robots/franka_panda_meshes.toml, robots/xarm6.toml) or convex hulls by qhull
// (robots/franka_panda_hulls.toml). Also each mesh robot's meshes read alone (no fitting), to split the time.
// BM_LoadRobot/<file>: time per load.

#include <string>

#include <benchmark/benchmark.h>

#include "redres/parsers/mesh_file.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "test_util.hpp"

namespace {

void BM_LoadRobot(benchmark::State& state, const std::string& file) {
  const std::filesystem::path path = redres::source_path(file);
  std::size_t shapes = 0;
  for (auto _ : state) {
    const redres::RobotModel robot = redres::load_robot(path);
    shapes = robot.link_shapes().size();
    benchmark::DoNotOptimize(shapes);
  }
  state.counters["shapes"] = static_cast<double>(shapes);
}

void BM_ReadMeshes(benchmark::State& state, const std::string& dir) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(redres::source_path(dir))) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".obj" || ext == ".stl" || ext == ".STL" || ext == ".dae")) {
      files.push_back(e.path());
    }
  }
  std::size_t vertices = 0;
  for (auto _ : state) {
    vertices = 0;
    for (const auto& f : files) vertices += redres::read_mesh(f, Eigen::Vector3d::Ones()).vertex_count();
    benchmark::DoNotOptimize(vertices);
  }
  state.counters["files"] = static_cast<double>(files.size());
  state.counters["vertices"] = static_cast<double>(vertices);
}

BENCHMARK_CAPTURE(BM_LoadRobot, franka_panda, std::string("robots/franka_panda.toml"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadRobot, franka_panda_urdf, std::string("robots/franka_panda_urdf.toml"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadRobot, franka_panda_meshes, std::string("robots/franka_panda_meshes.toml"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadRobot, franka_panda_hulls, std::string("robots/franka_panda_hulls.toml"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadRobot, xarm6, std::string("robots/xarm6.toml"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadMeshes, franka_panda, std::string("robots/franka_panda_description/meshes/collision"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadMeshes, xarm6, std::string("robots/xarm6_description/xarm_description/meshes"))
    ->Unit(benchmark::kMillisecond);

}  // namespace

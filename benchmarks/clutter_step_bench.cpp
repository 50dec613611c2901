// The whole control step (the scheme's build and the solve) of the Panda on its helix (configs/panda_helix.toml)
// among `count` spheres, `near` of which lie within the influence distance of the arm at its home configuration
// (the rest out of reach, 2 to 4 m away), for each engine (newton, projection, nlopt):
//   BM_ClutterWholeStep/<engine>/<count>/<near>
// Each iteration is one Controller::step at one of 8 states of the scene-free run (so the warm start sees
// neighbouring states). `rows` is the QP's inequality rows (shared rows above obstacle_avoidance's max_rows). The
// ratios that matter are against the 10-sphere scene with the same number near (issue 24's targets); the scene
// includes one sphere 5 m away besides the `count`. failed_fraction is the share of steps not solved.

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <benchmark/benchmark.h>

#include "redres/control/controller.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

std::string sphere(const Eigen::Vector3d& c, double r) {
  return "{ shape = \"sphere\", radius = " + std::to_string(r) + ", xyz = [" + std::to_string(c.x()) + ", " +
         std::to_string(c.y()) + ", " + std::to_string(c.z()) + "] }";
}

void BM_ClutterWholeStep(benchmark::State& state, const char* engine) {
  const int count = static_cast<int>(state.range(0));
  const int near = static_cast<int>(state.range(1));
  // The states of the scene-free run, and the link frames at home to place the near spheres by.
  Scenario plain = load_scenario(source_path("configs/panda_helix.toml"), {"duration=0.2"});
  const RunResult free_run = simulate(plain);
  const RobotModel& robot = *plain.robot;
  KinematicsData kin(robot);
  compute_kinematics(robot, robot.home(), kin, KinematicsLevel::kPosition);
  std::string obstacles = sphere({3.0, 3.0, 3.0}, 0.05);  // at least one obstacle
  for (int k = 0; k < near; ++k) {  // 0.1 m beside links 3, 4, 5, 6 (within d_i = 0.15 of their capsules)
    const Eigen::Vector3d at = kin.link_frames[static_cast<std::size_t>(2 + k % 4)].translation();
    obstacles += ", " + sphere(at + Eigen::Vector3d(0.0, k % 2 == 0 ? 0.2 : -0.2, 0.0), 0.02);
  }
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> far(2.0, 4.0);
  for (int k = near; k < count; ++k) obstacles += ", " + sphere({far(rng), far(rng), far(rng)}, 0.02);
  const auto dir = scratch("clutter_bench");
  std::filesystem::create_directories(dir);
  std::string text = read_text(source_path("configs/panda_helix.toml"));
  const std::string robots = "\"" + source_path("robots").string() + "/";
  for (std::size_t at = text.find("\"../robots/"); at != std::string::npos; at = text.find("\"../robots/"))
    text.replace(at, 11, robots);
  const std::size_t solver = text.find("[solver]");
  text.insert(solver, "[[constraints]]\ntype = \"obstacle_avoidance\"\ninfluence_distance = 0.15\nobstacles = [" +
                          obstacles + "]\n\n");
  std::ofstream(dir / "clutter.toml") << text;
  Scenario s = load_scenario(dir / "clutter.toml", {std::string("solver.engine=\"") + engine + "\""});
  std::filesystem::remove_all(dir);
  const auto controller = Controller::from_scenario(s);
  StepOutput out = controller->make_output();
  const std::size_t states = std::min<std::size_t>(8, free_run.trajectory.size());
  std::vector<Eigen::VectorXd> thetas;
  for (std::size_t r = 0; r < states; ++r) thetas.push_back(recorded_theta(robot, free_run.trajectory, r));
  std::size_t k = 0;
  int failed = 0;
  for (auto _ : state) {
    controller->step(thetas[k], free_run.trajectory.at(k, "t"), out);
    failed += out.info.status == SolverStatus::kSolved ? 0 : 1;
    k = (k + 1) % states;
    benchmark::DoNotOptimize(out.theta_dot.data());
  }
  state.counters["rows"] = controller->qp().m_in();
  state.counters["failed_fraction"] = benchmark::Counter(failed, benchmark::Counter::kAvgIterations);
}

BENCHMARK_CAPTURE(BM_ClutterWholeStep, newton, "newton")
    ->ArgsProduct({{10, 100, 1000, 10000}, {0, 4}})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ClutterWholeStep, projection, "projection")
    ->ArgsProduct({{10, 100, 1000, 10000}, {0, 4}})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ClutterWholeStep, nlopt, "nlopt")
    ->ArgsProduct({{10, 100, 1000, 10000}, {0, 4}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace redres

// The control step of every shipped scenario (configs/*.toml), with its tail: each run steps a Controller made from
// the scenario through the states of the scenario's own kinematic run, in order (so the warm start sees what it
// sees in `redres run`), timing each step with steady_clock; after all runs, each step's time is the minimum over
// the runs (the machine's noise drops out; what is left is the step's own cost), and the counters give
//   per_step  the mean of those minima (s)     p99_9  their 99.9th percentile (s)     max  their largest (s)
// BM_ScenarioStep/<scenario> (the paper's configs, the Panda's, the iiwa's, ...). The ratio that issue 24 names:
// panda_table_pole against panda_helix.
// BM_MotionStep/<config>_<variant>: configs/panda_helix_fast.toml (`fast`) and configs/panda_helix.toml (`helix`)
// with the robot's acceleration and jerk constraints switched on and off (`none`: both listed with active = false;
// `acceleration`, `jerk`, `both`), for the cost per step of each against the run without them (issue 25).
// BM_ChainLevels/<one|three>: a 28-joint chain at one priority level and at three (below).
// BM_HumanoidLevels/<one|three>: a 29-joint humanoid's waist and right arm at one level and at three, the middle one
// unmeetable (below).

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "redres/control/controller.hpp"
#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

void BM_ScenarioFileStep(benchmark::State& state, const std::filesystem::path& file) {
  Scenario s = load_scenario(file);
  const RunResult run = simulate(s);
  const std::size_t steps = run.trajectory.size();
  std::vector<Eigen::VectorXd> thetas;
  std::vector<double> times;
  for (std::size_t r = 0; r < steps; ++r) {
    thetas.push_back(recorded_theta(*s.robot, run.trajectory, r));
    times.push_back(run.trajectory.at(r, "t"));
  }
  const auto controller = Controller::from_scenario(s);
  StepOutput out = controller->make_output();
  std::vector<double> best(steps, 1e300);
  for (auto _ : state) {
    controller->reset();
    for (std::size_t r = 0; r < steps; ++r) {
      const auto start = std::chrono::steady_clock::now();
      controller->step(thetas[r], times[r], out);
      const auto stop = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(out.theta_dot.data());
      best[r] = std::min(best[r], std::chrono::duration<double>(stop - start).count());
    }
  }
  std::vector<double> sorted = best;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0.0;
  for (const double b : sorted) sum += b;
  const auto at = [&](double q) {
    return sorted[std::min(steps - 1, static_cast<std::size_t>(q * (steps - 1) + 0.5))];
  };
  state.counters["per_step"] = sum / static_cast<double>(steps);
  state.counters["p99_9"] = at(0.999);
  state.counters["max"] = sorted.back();
  state.counters["steps"] = static_cast<double>(steps);
}

void BM_ScenarioStep(benchmark::State& state, const std::string& name) {
  BM_ScenarioFileStep(state, source_path("configs/" + name + ".toml"));
}

// panda_helix_fast with the acceleration (jerk) constraint active or not: a copy of the file, its robot path made
// absolute, with both constraints listed.
std::filesystem::path motion_variant(const std::string& config, bool acceleration, bool jerk) {
  std::string text = read_text(source_path("configs/" + config + ".toml"));
  const std::string robot = "\"../robots/franka_panda.toml\"";
  text.replace(text.find(robot), robot.size(), "\"" + source_path("robots/franka_panda.toml").string() + "\"");
  const auto flag = [](bool on) { return on ? "true" : "false"; };
  text += std::string("\n[[constraints]]\ntype = \"joint_acceleration_limits\"\nactive = ") + flag(acceleration) +
          "\n\n[[constraints]]\ntype = \"joint_jerk_limits\"\nactive = " + flag(jerk) + "\n";
  const std::filesystem::path dir = scratch("motion_" + config + "_" + flag(acceleration) + "_" + flag(jerk));
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / (config + ".toml");
  std::ofstream(file) << text;
  return file;
}

void BM_MotionStep(benchmark::State& state, const std::string& config, bool acceleration, bool jerk) {
  BM_ScenarioFileStep(state, motion_variant(config, acceleration, jerk));
}
// The 10x helix, where the limits bind (the exact QP fails and the elastic QP is solved on about 600 steps) ...
// BM_ChainLevels/<one|three>: tests/data/scenarios/chain28_*.toml, a 28-joint chain with its right hand's pose at one
// level, and the same with the left hand held at priority 1 and a soft posture at 2 (issue 42: three levels cost at
// most 3 times one).
void BM_ChainLevels(benchmark::State& state, const char* which) {
  BM_ScenarioFileStep(state, source_path(std::string("tests/data/scenarios/chain28_") + which + ".toml"));
}
BENCHMARK_CAPTURE(BM_ChainLevels, one, "one")->Iterations(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ChainLevels, three, "three")->Iterations(5)->Unit(benchmark::kMillisecond);
// BM_HumanoidLevels/<one|three>: tests/data/scenarios/humanoid29_*.toml, the right hand's pose at one level, and the
// same with the left hand (a side branch, which only the waist moves) sent to a target at priority 1, which it cannot
// reach (the level is relaxed at every step), and a soft posture at 2 (issue 42: three levels cost at most 3 times
// one).
void BM_HumanoidLevels(benchmark::State& state, const char* which) {
  BM_ScenarioFileStep(state, source_path(std::string("tests/data/scenarios/humanoid29_") + which + ".toml"));
}
BENCHMARK_CAPTURE(BM_HumanoidLevels, one, "one")->Iterations(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_HumanoidLevels, three, "three")->Iterations(5)->Unit(benchmark::kMillisecond);

BENCHMARK_CAPTURE(BM_MotionStep, fast_none, "panda_helix_fast", false, false)
    ->Iterations(5)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MotionStep, fast_acceleration, "panda_helix_fast", true, false)
    ->Iterations(5)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MotionStep, fast_jerk, "panda_helix_fast", false, true)
    ->Iterations(5)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MotionStep, fast_both, "panda_helix_fast", true, true)
    ->Iterations(5)
    ->Unit(benchmark::kMillisecond);
// ... and panda_helix at its own speed, where they never bind: the constraints' own cost.
BENCHMARK_CAPTURE(BM_MotionStep, helix_none, "panda_helix", false, false)->Iterations(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MotionStep, helix_acceleration, "panda_helix", true, false)
    ->Iterations(5)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MotionStep, helix_jerk, "panda_helix", false, true)->Iterations(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MotionStep, helix_both, "panda_helix", true, true)->Iterations(5)->Unit(benchmark::kMillisecond);

// BM_LevelsStep/<variant> (issue 29): the Panda's hand on configs/panda_tool_elbow_posture.toml's vertical circle,
// with the joint margins and velocity limits, solved as
//   single      the paper's single QP: task_tracking rows and the velocity norm (the baseline),
//   one_level   the same as tasks: a frame task (equality) and the velocity norm, both at priority 0 (one QP),
//   two_levels  the hand at priority 0, the velocity norm at 1,
//   three_levels the shipped scenario: the hand at 0, the elbow above 0.5 m (inequality) at 1, the posture (soft)
//               and a small velocity norm at 2.
std::filesystem::path levels_variant(const std::string& variant) {
  std::string text = read_text(source_path("configs/panda_tool_elbow_posture.toml"));
  const std::string robot = "\"../robots/franka_panda.toml\"";
  text.replace(text.find(robot), robot.size(), "\"" + source_path("robots/franka_panda.toml").string() + "\"");
  if (variant != "three_levels") {
    // The path and the limits stay; the tasks and objectives are replaced.
    const std::size_t tasks = text.find("[[tasks]]");
    const std::size_t constraints = text.find("[[constraints]]");
    text = text.substr(0, tasks) + text.substr(constraints);
    if (variant == "single") {
      text +=
          "\n[[constraints]]\ntype = \"task_tracking\"\ngain = 8.0\n\n[[objectives]]\ntype = \"min_velocity_norm\"\n";
    } else {
      text +=
          "\n[[tasks]]\nname = \"tool\"\ntype = \"frame\"\nreference = \"path\"\ngain = 8.0\n\n"
          "[[objectives]]\ntype = \"min_velocity_norm\"\npriority = " +
          std::string(variant == "one_level" ? "0" : "1") + "\n";
    }
  }
  const std::filesystem::path dir = scratch("levels_" + variant);
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "panda_levels.toml";
  std::ofstream(file) << text;
  return file;
}

void BM_LevelsStep(benchmark::State& state, const std::string& variant) {
  BM_ScenarioFileStep(state, levels_variant(variant));
}
BENCHMARK_CAPTURE(BM_LevelsStep, single, "single")->Iterations(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LevelsStep, one_level, "one_level")->Iterations(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LevelsStep, two_levels, "two_levels")->Iterations(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LevelsStep, three_levels, "three_levels")->Iterations(5)->Unit(benchmark::kMillisecond);

// Every scenario of configs/ (sorted by name), registered before main() runs.
const bool registered = [] {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(source_path("configs"))) {
    if (entry.path().extension() == ".toml") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  for (const std::string& name : names) {
    benchmark::RegisterBenchmark(("BM_ScenarioStep/" + name).c_str(), BM_ScenarioStep, name)
        ->Iterations(5)
        ->Unit(benchmark::kMillisecond);
  }
  return true;
}();

}  // namespace
}  // namespace redres

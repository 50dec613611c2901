// The full paper run through the library against the hand-written baseline (paper_baseline.cpp), in the same
// process: the TVCMM R of the paper's arm, T = 40 s at tau = 1 ms (40,001 steps).
//   BM_PaperRun/baseline                 the hand-written loop (the letter R evaluated in the loop, as redres does;
//                                        recording theta, x, w of every step)
//   BM_PaperRun/baseline_path_table      the same loop reading r_d and r_d_dot from a table made before it
//   BM_PaperRun/redres_newton            simulate() with newton (recording every column in memory, into the
//                                        storage of the previous run, as the baseline reuses its record)
//   BM_PaperRun/redres_newton_fresh      the same into a new RunResult each time (allocating and first touching
//                                        the 16 MB table)
//   BM_PaperRun/redres_projection        simulate() with the paper's eq. 15
//   BM_PaperRun/redres_newton_no_record  Controller::step and Euler integration only (no recording)
// per_step is the time per step (s). The ratio to the baseline is the framework's cost.

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <unistd.h>

#include <benchmark/benchmark.h>

#include "bench_counters.hpp"
#include "paper_baseline_setup.hpp"
#include "redres/run/simulation.hpp"

namespace redres {
namespace {

Scenario paper_scenario(const char* engine) {
  return load_scenario(std::string(REDRES_SOURCE_DIR) + "/configs/paper_r_tvcmm.toml",
                       {"step=0.001", std::string("solver.engine=") + engine});
}

// in_loop: the letter evaluated in the loop (run_letter_r); otherwise the path from the table (run).
void BM_PaperRun_Baseline(benchmark::State& state, bool in_loop) {
  const Scenario s = paper_scenario("newton");
  const baseline::Case c = baseline::paper_case(s);
  baseline::Record record;
  record.rows.resize(static_cast<std::size_t>(c.steps + 1) * 13);
  for (auto _ : state) {
    record.iterations = 0;
    benchmark::DoNotOptimize(
        in_loop ? baseline::run_letter_r(c.arm, c.letter, c.theta0, c.steps, c.tau, record)
                : baseline::run(c.arm, c.theta0, c.r_d.data(), c.r_d_dot.data(), c.steps, c.tau, record));
  }
  set_per_step(state, c.steps + 1);
}

void BM_PaperRun_Redres(benchmark::State& state, const char* engine, bool fresh) {
  Scenario s = paper_scenario(engine);
  RunResult run;
  for (auto _ : state) {
    if (fresh) run = RunResult{};
    simulate(s, run);
    if (run.failures != 0) state.SkipWithError(run.first_failure.c_str());
    benchmark::DoNotOptimize(run.trajectory.values().data());
  }
  set_per_step(state, s.steps() + 1);
}

void BM_PaperRun_RedresNoRecord(benchmark::State& state) {
  Scenario s = paper_scenario("newton");
  Controller ctrl(*s.robot, *s.scheme, s.engine.make(), s.path.get(), s.duration, s.tau);
  StepOutput out = ctrl.make_output();
  Eigen::VectorXd theta(s.robot->dof());
  const int steps = s.steps();
  for (auto _ : state) {
    theta = s.theta0;
    ctrl.reset();
    for (int k = 0; k <= steps; ++k) {
      ctrl.step(theta, k == steps ? s.duration : k * s.tau, out);
      if (k < steps) theta += s.tau * out.theta_dot;
    }
    benchmark::DoNotOptimize(theta.data());
  }
  set_per_step(state, steps + 1);
}

BENCHMARK_CAPTURE(BM_PaperRun_Baseline, in_loop, true)->Name("BM_PaperRun/baseline")->Unit(benchmark::kMillisecond);
// Whole processes, timed by the wall clock around std::system: the baseline program writing its CSV (t, theta,
// theta_dot, w) against `redres run` of the same run writing its outputs (trajectory.csv with every column,
// summary.json, scenario.toml), or `extra` arguments' (the binary trajectory; no trajectory at all).
void BM_Process(benchmark::State& state, const char* which, const char* extra = "") {
  const std::string dir = "/tmp/redres_bench_process_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  const std::string cmd =
      std::string(which) == "baseline"
          ? std::string("'") + REDRES_BASELINE_PROCESS + "' '" + dir + "/baseline.csv' 0.001 > /dev/null"
          : std::string("cd '") + REDRES_SOURCE_DIR + "' && '" + REDRES_CLI +
                "' run configs/paper_r_tvcmm.toml --set step=0.001 --set solver.engine=newton --out '" + dir +
                "/run' --quiet " + extra;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const int status = std::system(cmd.c_str());
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (status != 0) state.SkipWithError(("exit status " + std::to_string(status) + " of " + cmd).c_str());
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK_CAPTURE(BM_Process, baseline, "baseline")->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_Process, redres_run, "redres_run")->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_Process, redres_run_hdf5, "redres_run", "--format hdf5")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);
BENCHMARK_CAPTURE(BM_Process, redres_run_record_none, "redres_run", "--record none")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

BENCHMARK_CAPTURE(BM_PaperRun_Baseline, table, false)
    ->Name("BM_PaperRun/baseline_path_table")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PaperRun_Redres, redres_newton, "newton", false)
    ->Name("BM_PaperRun/redres_newton")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PaperRun_Redres, redres_newton_fresh, "newton", true)
    ->Name("BM_PaperRun/redres_newton_fresh")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PaperRun_Redres, redres_projection, "projection", false)
    ->Name("BM_PaperRun/redres_projection")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PaperRun_RedresNoRecord)->Name("BM_PaperRun/redres_newton_no_record")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace redres

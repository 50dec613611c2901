// What a failed step costs against a solved one, on the step that no engine solves: the KUKA iiwa of
// tests/data/reproducers/iiwa_pose_step on a helix holding a 6-D pose past a pole, whose step at t = 5.44 s is
// infeasible (its rows miss by 3.2e-6 at best, all three engines agree). Each iteration is one Controller::step
// from a cold start (the failed step resets the warm start anyway):
//   BM_IiwaStep/solved                the step at t = 5.43 s (solved by newton)
//   BM_IiwaStep/failed                the step at t = 5.44 s (newton, then the rows found unmeetable)
//   BM_IiwaStep/failed_projection     the same step with projection at max_iterations = 20,000, what newton's
//                                     fallback spent on it before
// The ratios failed / solved and failed_projection / solved are the cost of a failure.

#include <memory>
#include <string>

#include <benchmark/benchmark.h>

#include "redres/control/controller.hpp"
#include "redres/run/simulation.hpp"

namespace redres {
namespace {

struct IiwaCase {
  Scenario scenario;
  Eigen::VectorXd solved_theta, failed_theta;
  double solved_t = 0.0, failed_t = 0.0;
};

IiwaCase iiwa_case(const std::string& engine) {
  IiwaCase c{load_scenario(std::string(REDRES_SOURCE_DIR) +
                               "/tests/data/reproducers/iiwa_pose_step/scenarios/iiwa_b3_helix_pose.toml",
                           {"solver.engine=\"" + engine + "\""}),
             {},
             {}};
  const RunResult run = simulate(c.scenario);  // stops at the failed step (on_infeasible = "stop")
  const std::size_t last = run.trajectory.size() - 1;
  const int n = c.scenario.robot->dof();
  c.solved_theta.resize(n);
  c.failed_theta.resize(n);
  for (int j = 0; j < n; ++j) {
    const std::string col = "theta_" + std::to_string(j + 1);
    c.solved_theta(j) = run.trajectory.at(last - 1, col);
    c.failed_theta(j) = run.trajectory.at(last, col);
  }
  c.solved_t = run.trajectory.at(last - 1, "t");
  c.failed_t = run.trajectory.at(last, "t");
  return c;
}

void BM_IiwaStep(benchmark::State& state, const char* engine, bool failed) {
  IiwaCase c = iiwa_case(engine);
  const std::unique_ptr<Controller> controller = Controller::from_scenario(c.scenario);
  StepOutput out = controller->make_output();
  const Eigen::VectorXd& theta = failed ? c.failed_theta : c.solved_theta;
  const double t = failed ? c.failed_t : c.solved_t;
  controller->step(theta, t, out);
  if ((out.info.status == SolverStatus::kSolved) == failed) {
    state.SkipWithError(failed ? "the step at t = 5.44 s was solved" : "the step at t = 5.43 s failed");
    return;
  }
  for (auto _ : state) {
    controller->reset();
    controller->step(theta, t, out);
    benchmark::DoNotOptimize(out.theta_dot.data());
  }
  state.counters["iterations_per_step"] = out.info.iterations;
}

BENCHMARK_CAPTURE(BM_IiwaStep, solved, "newton", false)->Name("BM_IiwaStep/solved")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_IiwaStep, failed, "newton", true)->Name("BM_IiwaStep/failed")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_IiwaStep, failed_projection, "projection", true)
    ->Name("BM_IiwaStep/failed_projection")
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace redres

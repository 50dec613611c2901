#include "redres/run/simulation.hpp"

#include <algorithm>
#include <chrono>

#include "run/recording.hpp"

namespace redres {

std::size_t trajectory_width(const Scenario& s) { return run_columns(s, nullptr).size(); }

std::string RunResult::engine() const {
  std::string out;
  for (const auto e : engines) {
    if (!out.empty()) out += '+';
    out += e;
  }
  return out;
}

RunResult simulate(Scenario& s, const ProgressCallback& progress) {
  RunResult run;
  simulate(s, run, progress);
  return run;
}

namespace {

// Integrates one step from theta at t with the step's solution `out`: Euler's method, or Heun's (one more QP, at the
// Euler prediction, into `out2`). A failed step moves nothing. Returns false when the run must stop (a failed second
// stage under on_infeasible = "stop").
bool integrate(const Scenario& s, Controller& ctrl, StepLog& log, RunResult& run, double t, const StepOutput& out,
               StepOutput& out2, Eigen::VectorXd& theta, Eigen::VectorXd& theta_pred) {
  if (!usable(out.info.status)) {
    ++run.held_steps;  // theta_dot = 0 (the controller never hands out an unconverged iterate): theta stays
    return true;
  }
  if (s.integrator == Integrator::kEuler) {
    theta += s.tau * out.theta_dot;
    return true;
  }
  // Heun: average the slopes at theta and at the Euler prediction (one more QP per step, into its own output).
  theta_pred = theta + s.tau * out.theta_dot;
  const double t2 = std::min(s.duration, t + s.tau);
  ctrl.reevaluate(theta_pred, t2, out2);  // the same step: the plugins see the same previous command
  const int failures_before_stage = run.failures;
  log.note(out2, t2);
  if (s.on_infeasible == OnInfeasible::kStop && run.failures > failures_before_stage) {
    run.stopped = true;
    return false;
  }
  if (usable(out2.info.status)) {
    theta += 0.5 * s.tau * (out.theta_dot + out2.theta_dot);
    theta_pred = 0.5 * (out.theta_dot + out2.theta_dot);  // the command applied: the next step's theta_dot_prev
    ctrl.set_applied(theta_pred);
  } else {
    theta += s.tau * out.theta_dot;  // the second stage failed: Euler's step with the first, which solved
  }
  return true;
}

}  // namespace

void simulate(Scenario& s, RunResult& run, const ProgressCallback& progress, const std::atomic<bool>* stop) {
  const int steps = s.steps();
  {
    Trajectory storage = std::move(run.trajectory);  // every field as a new run has it, but the table's storage
    run = RunResult{};
    run.trajectory = std::move(storage);
  }
  std::vector<Recorder> recorders;
  std::vector<std::string> columns = run_columns(s, &recorders);
  REDRES_REQUIRE((steps + 1.0) * static_cast<double>(columns.size()) * 8.0 <= kMaxTableBytes, "simulate",
                 "the run's table fits in kMaxTableBytes (" + std::to_string(steps + 1) + " rows of " +
                     std::to_string(columns.size()) + " columns do not)");
  run.trajectory.reset(std::move(columns), static_cast<std::size_t>(steps) + 1);
  run.engines.reserve(4);

  const std::unique_ptr<Controller> controller = Controller::from_scenario(s);
  Controller& ctrl = *controller;
  run.plugin_data = ctrl.shared_plugin_data();
  RowRecorder rows(s, ctrl, std::move(recorders), run.trajectory.width());
  StepLog log(run, *s.scheme, ctrl.plugin_data());
  StepOutput out = ctrl.make_output(), out2 = ctrl.make_output();
  Eigen::VectorXd theta = s.theta0, theta_pred(s.robot->dof());
  const auto start = std::chrono::steady_clock::now();
  const int report_every = std::max(1, steps / 200);

  for (int k = 0; k <= steps; ++k) {
    const double t = k == steps ? s.duration : k * s.tau;
    ctrl.step(theta, t, out);
    run.trajectory.append_row(rows.write(k, t, theta, out));
    const int failures_before = run.failures;
    log.note(out, t);
    if (run.failures == failures_before) log.check_violations(t);  // one failure per step at most
    if (progress && (k % report_every == 0 || k == steps)) progress(static_cast<double>(k) / steps, t);
    if (k == steps) break;
    if (stop != nullptr && stop->load(std::memory_order_relaxed)) {
      run.interrupted = true;  // the row of this step is the last
      break;
    }
    if (s.on_infeasible == OnInfeasible::kStop && run.failures > failures_before) {
      run.stopped = true;  // the row of the failed step is the last
      break;
    }
    if (!integrate(s, ctrl, log, run, t, out, out2, theta, theta_pred)) break;
  }
  run.trajectory.publish();
  run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace redres

#include "redres/run/simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

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

RunResult simulate(const Scenario& s, const ProgressCallback& progress) {
  RunResult run;
  simulate(s, run, progress);
  return run;
}

namespace {

// Every field of `run` as a new run has it, but the table's storage (reused when it has room).
void reset_run(RunResult& run) {
  Trajectory storage = std::move(run.trajectory);
  run = RunResult{};
  run.trajectory = std::move(storage);
}

// Integrates one step from theta at t with the step's solution `out`: Euler's method, or Heun's (one more QP, at the
// Euler prediction, into `out2`); at the acceleration level the step's constant acceleration exactly. `velocity` is
// the command applied over the previous step on entry and this step's on return (zero for a held step). A held step
// moves nothing; a braked step moves with its braking command (Euler's step: no second stage). Returns false when the
// run must stop (a failed second stage under on_infeasible = "stop").
bool integrate(const Scenario& s, Controller& ctrl, StepLog& log, RunResult& run, double t, const StepOutput& out,
               StepOutput& out2, Eigen::VectorXd& theta, Eigen::VectorXd& theta_pred, Eigen::VectorXd& velocity) {
  if (!moves(out.info.status)) {
    ++run.held_steps;  // theta_dot = 0 (the controller never hands out an unconverged iterate): theta stays
    velocity.setZero();
    return true;
  }
  if (out.info.status == SolverStatus::kBraked) ++run.braked_steps;
  if (s.scheme->level() == SchemeLevel::kAcceleration) {
    theta += (0.5 * s.tau) * (velocity + out.theta_dot);  // (v + v') / 2 over the step: exact for its acceleration
    velocity = out.theta_dot;
    return true;
  }
  velocity = out.theta_dot;  // the command applied over the step (Heun's average below replaces it)
  if (s.integrator == Integrator::kEuler || out.info.status == SolverStatus::kBraked) {
    theta += s.tau * out.theta_dot;
    return true;
  }
  // Heun: average the slopes at theta and at the Euler prediction (one more QP per step, into its own output).
  theta_pred = theta + s.tau * out.theta_dot;
  const double t2 = std::min(s.duration, t + s.tau);
  ctrl.reevaluate(theta_pred, t2, out2);  // the same step: the plugins see the same previous command
  const int failures_before_stage = run.failures;
  log.note(out2, t2);
  if (s.on_infeasible == FailurePolicy::kStop && run.failures > failures_before_stage) {
    run.stopped = true;
    return false;
  }
  if (usable(out2.info.status)) {  // a braked second stage is not averaged in
    theta += 0.5 * s.tau * (out.theta_dot + out2.theta_dot);
    velocity = 0.5 * (out.theta_dot + out2.theta_dot);  // the command applied: the next step's theta_dot_prev
    ctrl.set_applied(velocity);
  } else {
    theta += s.tau * out.theta_dot;  // the second stage failed: Euler's step with the first, which solved
  }
  return true;
}

// The motion the arm is asked for (RunResult's max_joint_acceleration ... steps_over_jerk_limit), from the commands
// applied step after step. Sized at setup; add() allocates nothing.
class MotionStats {
 public:
  MotionStats(const RobotModel& robot, RunResult& run)
      : robot_(robot),
        prev_(Eigen::VectorXd::Zero(robot.dof())),
        acc_(Eigen::VectorXd::Zero(robot.dof())),
        acc_prev_(Eigen::VectorXd::Zero(robot.dof())),
        lo_(robot.dof()),
        hi_(robot.dof()) {
    const auto n = static_cast<std::size_t>(robot.dof());
    run.max_joint_acceleration.assign(n, 0.0);
    run.max_joint_jerk.assign(n, 0.0);
    if (robot.has_acceleration_limits()) run.max_joint_acceleration_violation.assign(n, 0.0);
    if (robot.has_jerk_limits()) run.max_joint_jerk_violation.assign(n, 0.0);
  }

  // `applied` is the command the arm followed over a step that started at theta.
  void add(const Eigen::VectorXd& applied, const Eigen::VectorXd& theta, double tau, RunResult& run) {
    const int n = robot_.dof();
    acc_ = (applied - prev_) / tau;
    for (int j = 0; j < n; ++j) {
      const auto k = static_cast<std::size_t>(j);
      run.max_joint_acceleration[k] = std::max(run.max_joint_acceleration[k], std::abs(acc_(j)));
      run.max_joint_jerk[k] = std::max(run.max_joint_jerk[k], std::abs((acc_(j) - acc_prev_(j)) / tau));
    }
    if (!run.max_joint_acceleration_violation.empty()) {
      robot_.acceleration_limits(theta, lo_, hi_);
      if (over(acc_, run.max_joint_acceleration_violation)) ++run.steps_over_acceleration_limit;
    }
    if (!run.max_joint_jerk_violation.empty()) {
      robot_.jerk_limits(theta, lo_, hi_);
      acc_prev_ = (acc_ - acc_prev_) / tau;  // the jerk, in acc_prev_'s storage for the moment
      if (over(acc_prev_, run.max_joint_jerk_violation)) ++run.steps_over_jerk_limit;
    }
    acc_prev_ = acc_;
    prev_ = applied;
  }

 private:
  // Whether some joint of `value` leaves [lo_, hi_] by more than 1e-9 (1 + |limit|); the largest excursions into
  // `worst`.
  bool over(const Eigen::VectorXd& value, std::vector<double>& worst) const {
    bool any = false;
    for (Eigen::Index j = 0; j < value.size(); ++j) {
      const double up = value(j) - hi_(j), down = lo_(j) - value(j);
      const double excess = std::max({0.0, up, down});
      auto& w = worst[static_cast<std::size_t>(j)];
      w = std::max(w, excess);
      any = any || up > 1e-9 * (1.0 + std::abs(hi_(j))) || down > 1e-9 * (1.0 + std::abs(lo_(j)));
    }
    return any;
  }

  const RobotModel& robot_;
  Eigen::VectorXd prev_, acc_, acc_prev_, lo_, hi_;
};

}  // namespace

namespace {

// After step k's row is recorded: the step's outcome into the log (one failure per step at most) and the progress.
// Whether the run goes on to apply the step's command; false (the row of this step is the last) at the last step, when
// `stop` is set, or at a failed step under on_infeasible = "stop".
bool step_goes_on(const Scenario& s, StepLog& log, RunResult& run, int k, int steps, double t, const StepOutput& out,
                  const ProgressCallback& progress, const std::atomic<bool>* stop) {
  const int failures_before = run.failures;
  log.note(out, t);
  if (run.failures == failures_before) log.check_violations(t);
  const int report_every = std::max(1, steps / 200);
  if (progress && (k % report_every == 0 || k == steps)) progress(static_cast<double>(k) / steps, t);
  if (k == steps) return false;
  if (stop != nullptr && stop->load(std::memory_order_relaxed)) {
    run.interrupted = true;
    return false;
  }
  if (s.on_infeasible == FailurePolicy::kStop && run.failures > failures_before) {
    run.stopped = true;
    return false;
  }
  return true;
}

// The largest value of a column of the run's table (0 for an empty one).
double column_max(const Trajectory& tr, const std::string& name) {
  double m = 0.0;
  for (std::size_t r = 0; r < tr.size(); ++r) m = std::max(m, tr.at(r, name));
  return m;
}

// A run on the MuJoCo plant (docs/plant.md, "The plant"): each control step reads the measured state, solves, and
// holds the command over the plant's MuJoCo steps.
void simulate_kinematic(const Scenario& s, RunResult& run, const ProgressCallback& progress,
                        const std::atomic<bool>* stop);

void simulate_plant(const Scenario& s, RunResult& run, const ProgressCallback& progress,
                    const std::atomic<bool>* stop) {
  const int steps = s.steps();
  const int n = s.robot->dof();
  std::vector<Recorder> recorders;
  std::vector<std::string> columns = run_columns(s, &recorders);
  const std::size_t plant_first = columns.size() - static_cast<std::size_t>(2 * n + 2);
  REDRES_REQUIRE((steps + 1.0) * static_cast<double>(columns.size()) * 8.0 <= kMaxTableBytes, "simulate",
                 "the run's table fits in kMaxTableBytes (" + std::to_string(steps + 1) + " rows of " +
                     std::to_string(columns.size()) + " columns do not)");
  PlantFacts facts;
  {
    // The same scenario on the kinematic plant, for the kinematic-vs-dynamic error.
    RunResult kinematic;
    simulate_kinematic(s, kinematic, {}, stop);
    facts.kinematic_max_position_error = column_max(kinematic.trajectory, "position_error");
  }
  run.trajectory.reset(std::move(columns), static_cast<std::size_t>(steps) + 1);
  run.engines.reserve(4);

  MujocoPlant plant(*s.robot, s.plant, s.tau, scenario_obstacles(s, true), s.theta0);
  const std::unique_ptr<Controller> controller = Controller::from_scenario(s);
  Controller& ctrl = *controller;
  run.plugin_data = ctrl.shared_plugin_data();
  RowRecorder rows(s, ctrl, std::move(recorders), run.trajectory.width());
  StepLog log(run, *s.scheme, ctrl.plugin_data());
  StepOutput out = ctrl.make_output();
  Eigen::VectorXd theta(n), command = Eigen::VectorXd::Zero(n);
  const auto start = std::chrono::steady_clock::now();
  MotionStats motion(*s.robot, run);
  const auto u = [](std::size_t k) { return static_cast<std::ptrdiff_t>(k); };

  for (int k = 0; k <= steps; ++k) {
    const double t = k == steps ? s.duration : k * s.tau;
    theta = plant.theta();
    const auto c0 = std::chrono::steady_clock::now();
    ctrl.step(theta, plant.theta_dot(), t, out);
    facts.controller_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count();
    ++facts.control_steps;
    double* row = rows.write(k, t, theta, out);
    std::copy_n(plant.theta_dot().data(), n, row + u(plant_first));
    std::copy_n(plant.torque().data(), n, row + u(plant_first) + n);
    row[plant_first + 2 * static_cast<std::size_t>(n)] = plant.contacts();
    row[plant_first + 2 * static_cast<std::size_t>(n) + 1] = plant.penetration();
    run.trajectory.append_row(row);
    if (!step_goes_on(s, log, run, k, steps, t, out, progress, stop)) break;
    if (moves(out.info.status)) {
      if (out.info.status == SolverStatus::kBraked) ++run.braked_steps;
      command = out.theta_dot;
    } else {
      ++run.held_steps;  // held: the servo is asked for theta_dot = 0
      command.setZero();
    }
    try {
      plant.advance(command, t);
    } catch (const std::runtime_error& e) {
      // MuJoCo failed (diverged, or an error inside it): the run ends here, with every row up to this step.
      if (run.failures++ == 0) run.first_failure = "t = " + std::to_string(t) + " s: MuJoCo plant: " + e.what();
      run.stopped = true;
      break;
    }
    motion.add(command, theta, s.tau, run);
  }
  run.trajectory.publish();
  run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  facts.actuator = std::string(enum_names(PlantActuator{})[static_cast<std::size_t>(s.plant.actuator)].second);
  facts.timestep = plant.timestep();
  facts.substeps = plant.substeps();
  facts.delay = s.plant.delay;
  facts.max_torque.assign(plant.max_torque().data(), plant.max_torque().data() + n);
  facts.max_torque_rate.assign(plant.max_torque_rate().data(), plant.max_torque_rate().data() + n);
  for (int j = 0; j < n; ++j)
    facts.effort_limit.push_back(s.robot->joint(j).effort_limit.value_or(std::numeric_limits<double>::quiet_NaN()));
  facts.max_contacts = static_cast<int>(column_max(run.trajectory, "contacts"));
  facts.deepest_penetration = column_max(run.trajectory, "penetration");
  facts.contact_pairs = plant.contact_pairs();
  facts.mujoco_seconds = plant.mujoco_seconds();
  facts.mujoco_steps = plant.mujoco_steps();
  facts.mjcf = plant.mjcf();
  run.plant = std::move(facts);
}

}  // namespace

void simulate(const Scenario& s, RunResult& run, const ProgressCallback& progress, const std::atomic<bool>* stop) {
  if (s.plant.kind == PlantKind::kMujoco) {
    reset_run(run);
    simulate_plant(s, run, progress, stop);
    return;
  }
  simulate_kinematic(s, run, progress, stop);
}

namespace {

void simulate_kinematic(const Scenario& s, RunResult& run, const ProgressCallback& progress,
                        const std::atomic<bool>* stop) {
  const int steps = s.steps();
  reset_run(run);
  std::vector<Recorder> recorders;
  std::vector<std::string> columns = run_columns(s, &recorders, PlantKind::kKinematic);
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
  Eigen::VectorXd theta = s.theta0, theta_pred(s.robot->dof()), velocity = Eigen::VectorXd::Zero(s.robot->dof());
  const auto start = std::chrono::steady_clock::now();
  MotionStats motion(*s.robot, run);
  Eigen::VectorXd theta_start(s.robot->dof());

  for (int k = 0; k <= steps; ++k) {
    const double t = k == steps ? s.duration : k * s.tau;
    ctrl.step(theta, t, out);
    run.trajectory.append_row(rows.write(k, t, theta, out));
    if (!step_goes_on(s, log, run, k, steps, t, out, progress, stop)) break;
    theta_start = theta;
    if (!integrate(s, ctrl, log, run, t, out, out2, theta, theta_pred, velocity)) break;
    motion.add(velocity, theta_start, s.tau, run);
  }
  run.trajectory.publish();
  run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

}  // namespace redres

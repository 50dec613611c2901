#include "redres/run/simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "redres/run/plants.hpp"
#include "run/recording.hpp"

namespace redres {

std::size_t trajectory_width(const Scenario& s) {
  return run_columns(s, plant_registry().at(s.plant.kind)).names.size();
}

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

// The motion the arm is asked for (RunResult's max_joint_acceleration ... steps_over_jerk_limit), from the commands
// applied step after step, against the limits the step's controller evaluated. Sized at setup; nothing allocates.
class MotionStats {
 public:
  MotionStats(const RobotModel& robot, RunResult& run)
      : prev_(Eigen::VectorXd::Zero(robot.dof())),
        acc_(Eigen::VectorXd::Zero(robot.dof())),
        acc_prev_(Eigen::VectorXd::Zero(robot.dof())),
        a_lo_(Eigen::VectorXd::Zero(robot.dof())),
        a_hi_(Eigen::VectorXd::Zero(robot.dof())),
        j_lo_(Eigen::VectorXd::Zero(robot.dof())),
        j_hi_(Eigen::VectorXd::Zero(robot.dof())),
        acceleration_(robot.has_acceleration_limits()),
        jerk_(robot.has_jerk_limits()) {
    const auto n = static_cast<std::size_t>(robot.dof());
    run.max_joint_acceleration.assign(n, 0.0);
    run.max_joint_jerk.assign(n, 0.0);
    if (robot.has_acceleration_limits()) run.max_joint_acceleration_violation.assign(n, 0.0);
    if (robot.has_jerk_limits()) run.max_joint_jerk_violation.assign(n, 0.0);
  }

  // The limits at the step's theta, as its controller evaluated them (before a second stage evaluates them at
  // another state).
  void limits_of_step(const Controller& ctrl) {
    if (acceleration_) {
      a_lo_ = ctrl.acceleration_lower();
      a_hi_ = ctrl.acceleration_upper();
    }
    if (jerk_) {
      j_lo_ = ctrl.jerk_lower();
      j_hi_ = ctrl.jerk_upper();
    }
  }

  // `applied` is the command the arm followed over the step whose limits limits_of_step() took.
  void add(const Eigen::VectorXd& applied, double tau, RunResult& run) {
    const int n = static_cast<int>(prev_.size());
    acc_ = (applied - prev_) / tau;
    for (int j = 0; j < n; ++j) {
      const auto k = static_cast<std::size_t>(j);
      run.max_joint_acceleration[k] = std::max(run.max_joint_acceleration[k], std::abs(acc_(j)));
      run.max_joint_jerk[k] = std::max(run.max_joint_jerk[k], std::abs((acc_(j) - acc_prev_(j)) / tau));
    }
    if (!run.max_joint_acceleration_violation.empty() &&
        over(acc_, a_lo_, a_hi_, run.max_joint_acceleration_violation)) {
      ++run.steps_over_acceleration_limit;
    }
    if (!run.max_joint_jerk_violation.empty()) {
      acc_prev_ = (acc_ - acc_prev_) / tau;  // the jerk, in acc_prev_'s storage for the moment
      if (over(acc_prev_, j_lo_, j_hi_, run.max_joint_jerk_violation)) ++run.steps_over_jerk_limit;
    }
    acc_prev_ = acc_;
    prev_ = applied;
  }

 private:
  // Whether some joint of `value` leaves [lo, hi] by more than 1e-9 (1 + |limit|); the largest excursions into
  // `worst`.
  static bool over(const Eigen::VectorXd& value, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                   std::vector<double>& worst) {
    bool any = false;
    for (Eigen::Index j = 0; j < value.size(); ++j) {
      const double up = value(j) - hi(j), down = lo(j) - value(j);
      const double excess = std::max({0.0, up, down});
      auto& w = worst[static_cast<std::size_t>(j)];
      w = std::max(w, excess);
      any = any || up > 1e-9 * (1.0 + std::abs(hi(j))) || down > 1e-9 * (1.0 + std::abs(lo(j)));
    }
    return any;
  }

  Eigen::VectorXd prev_, acc_, acc_prev_;
  Eigen::VectorXd a_lo_, a_hi_, j_lo_, j_hi_;  // the step's limits
  bool acceleration_, jerk_;                   // the robot has them
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

// What the kinematic plant's Heun step asks of the run: the step solved again, noted as every step is.
class LoopStep final : public PlantStep {
 public:
  LoopStep(const Scenario& s, Controller& ctrl, StepLog& log, RunResult& run, StepOutput& out2)
      : s_(s), ctrl_(ctrl), log_(log), run_(run), out2_(out2) {}
  const StepOutput* solve_again(const Eigen::VectorXd& theta, double t) override {
    ctrl_.reevaluate(theta, t, out2_);  // the same step: the plugins see the same previous command
    const int failures_before = run_.failures;
    log_.note(out2_, t);
    if (s_.on_infeasible == FailurePolicy::kStop && run_.failures > failures_before) return nullptr;
    return &out2_;
  }
  void set_applied(const Eigen::VectorXd& theta_dot) override { ctrl_.set_applied(theta_dot); }

 private:
  const Scenario& s_;
  Controller& ctrl_;
  StepLog& log_;
  RunResult& run_;
  StepOutput& out2_;
};

// The one loop (docs/plant.md): a run of `s` on the plant `type`, into `run` (overwritten).
void run_on(const Scenario& s, const PlantType& type, RunResult& run, const ProgressCallback& progress,
            const std::atomic<bool>* stop) {
  const int steps = s.steps();
  const int n = s.robot->dof();
  reset_run(run);
  RunColumns layout = run_columns(s, type);
  REDRES_REQUIRE((steps + 1.0) * static_cast<double>(layout.names.size()) * 8.0 <= kMaxTableBytes, "simulate",
                 "the run's table fits in kMaxTableBytes (" + std::to_string(steps + 1) + " rows of " +
                     std::to_string(layout.names.size()) + " columns do not)");
  const std::size_t plant_first = layout.plant_first;
  run.trajectory.reset(std::move(layout.names), static_cast<std::size_t>(steps) + 1);
  run.engines.reserve(4);

  const std::unique_ptr<Plant> plant = type.make(s);
  const std::unique_ptr<Controller> controller = Controller::from_scenario(s);
  Controller& ctrl = *controller;
  run.plugin_data = ctrl.shared_plugin_data();
  RowRecorder rows(s, ctrl, std::move(layout), run.trajectory.width());
  StepLog log(run, *s.scheme, ctrl.plugin_data());
  StepOutput out = ctrl.make_output(), out2 = ctrl.make_output();
  LoopStep loop_step(s, ctrl, log, run, out2);
  Eigen::VectorXd applied = Eigen::VectorXd::Zero(n);
  std::string failure;
  const auto start = std::chrono::steady_clock::now();
  MotionStats motion(*s.robot, run);
  const bool timed = type.times_controller;

  for (int k = 0; k <= steps; ++k) {
    const double t = k == steps ? s.duration : k * s.tau;
    const Eigen::VectorXd& theta = plant->theta();
    const auto c0 = timed ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
    if (const Eigen::VectorXd* measured = plant->theta_dot()) {
      ctrl.step(theta, *measured, t, out);
    } else {
      ctrl.step(theta, t, out);
    }
    if (timed) run.controller_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count();
    ++run.control_steps;
    double* row = rows.write(k, t, theta, out);
    plant->record(row + static_cast<std::ptrdiff_t>(plant_first));
    run.trajectory.append_row(row);
    if (out.info.status == SolverStatus::kBraked) ++run.braked_steps;  // every braked row, the last one's too
    if (!step_goes_on(s, log, run, k, steps, t, out, progress, stop)) break;
    if (!moves(out.info.status)) ++run.held_steps;  // theta_dot = 0 (never an unconverged iterate)
    motion.limits_of_step(ctrl);                    // before a second stage evaluates the laws at another state
    if (!plant->advance(out, t, loop_step, applied, failure)) {
      if (!failure.empty() && run.failures++ == 0) run.first_failure = "t = " + std::to_string(t) + " s: " + failure;
      run.stopped = true;
      break;
    }
    motion.add(applied, s.tau, run);
  }
  run.trajectory.publish();
  run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  plant->finish(s, run);
}

}  // namespace

void simulate(const Scenario& s, RunResult& run, const ProgressCallback& progress, const std::atomic<bool>* stop) {
  const PlantType& type = plant_registry().at(s.plant.kind);
  double kinematic_error = 0.0;
  if (s.plant.kinematic_comparison && type.name != "kinematic") {
    // The scenario asks for its run on the kinematic plant beside this one: its largest position error.
    RunResult kinematic;
    run_on(s, plant_registry().at("kinematic"), kinematic, {}, stop);
    kinematic_error = column_max(kinematic.trajectory, "position_error");
  }
  run_on(s, type, run, progress, stop);
  if (run.plant) run.plant->kinematic_max_position_error = kinematic_error;
}

}  // namespace redres

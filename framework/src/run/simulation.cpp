#include "redres/run/simulation.hpp"

#include "redres/run/plugin_output.hpp"
#include "redres/run/trajectory_columns.hpp"

#include <algorithm>
#include <chrono>
#include <numbers>
#include <sstream>
#include <string_view>

#include <Eigen/Geometry>

namespace redres {

namespace {

// The rotation vector w (|w| <= pi) written as the equivalent w + 2 pi k w/|w| closest to `previous`, so that the
// recorded columns have no 2 pi jumps where the rotation angle passes pi.
Eigen::Vector3d continuous_rotation_vector(const Eigen::Vector3d& w, const Eigen::Vector3d& previous) {
  const double angle = w.norm();
  if (!(angle > 0.0)) return w;
  const Eigen::Vector3d u = w / angle;
  Eigen::Vector3d best = w;
  for (int k = -3; k <= 3; ++k) {
    const Eigen::Vector3d candidate = (angle + 2.0 * std::numbers::pi * k) * u;
    if ((candidate - previous).squaredNorm() < (best - previous).squaredNorm()) best = candidate;
  }
  return best;
}

// A plugin that records columns: its output part, its data in the controller that runs, its first column.
struct Recorder {
  const PluginOutput* output = nullptr;
  const PluginData* data = nullptr;
  std::size_t first = 0;
  std::size_t objective = 0, constraint = 0;  // which plugin: objective k (constraint = npos) or constraint k
};
constexpr std::size_t kNone = static_cast<std::size_t>(-1);

// The standard columns, then the plugins' own (e.g. collision distances), with where each plugin's start.
std::vector<std::string> run_columns(const Scenario& s, std::vector<Recorder>* recorders) {
  std::vector<std::string> columns = standard_trajectory_columns(*s.robot);
  const auto add_recorder = [&](const Plugin& p, std::size_t objective, std::size_t constraint) {
    if (!p.active()) return;
    const PluginOutput* output = output_of(p);
    if (output == nullptr) return;
    const std::vector<std::string> own = output->recorded_columns();
    if (own.empty()) return;
    if (recorders != nullptr) recorders->push_back({output, nullptr, columns.size(), objective, constraint});
    for (const auto& c : own) {
      // Two plugins may record the same quantity (two obstacle sets): the second gets its name as a prefix.
      const bool taken = std::find(columns.begin(), columns.end(), c) != columns.end();
      columns.push_back(taken ? p.name() + "." + c : c);
    }
  };
  const auto& objectives = s.scheme->objectives();
  const auto& constraints = s.scheme->constraints();
  for (std::size_t k = 0; k < objectives.size(); ++k) add_recorder(*objectives[k], k, kNone);
  for (std::size_t k = 0; k < constraints.size(); ++k) add_recorder(*constraints[k], kNone, k);
  return columns;
}

}  // namespace

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

void simulate(Scenario& s, RunResult& run, const ProgressCallback& progress, const std::atomic<bool>* stop) {
  const RobotModel& robot = *s.robot;
  const int n = robot.dof();
  const int m = robot.reference_dim();
  const int position_rows = robot.position_rows();
  const int steps = s.steps();
  {
    Trajectory storage = std::move(run.trajectory);  // every field as a new run has it, but the table's storage
    run = RunResult{};
    run.trajectory = std::move(storage);
  }
  std::vector<Recorder> recorders;
  std::vector<std::string> columns = run_columns(s, &recorders);
  const std::size_t standard_columns = recorders.empty() ? columns.size() : recorders.front().first;
  REDRES_REQUIRE((steps + 1.0) * static_cast<double>(columns.size()) * 8.0 <= kMaxTableBytes, "simulate",
                 "the run's table fits in kMaxTableBytes (" + std::to_string(steps + 1) + " rows of " +
                     std::to_string(columns.size()) + " columns do not)");
  run.trajectory.reset(std::move(columns), static_cast<std::size_t>(steps) + 1);
  run.engines.reserve(4);
  std::vector<double> row_buffer(run.trajectory.width());

  const std::unique_ptr<Controller> controller = Controller::from_scenario(s);
  Controller& ctrl = *controller;
  const SchemeData& data = ctrl.plugin_data();
  run.plugin_data = ctrl.shared_plugin_data();
  for (Recorder& r : recorders) {
    r.data = r.objective != kNone ? data.objectives[r.objective].get() : data.constraints[r.constraint].get();
  }
  StepOutput out = ctrl.make_output(), out2 = ctrl.make_output();
  Eigen::VectorXd theta = s.theta0, theta_pred(n);
  const bool orientation_rows = robot.has_orientation_rows();
  const bool spatial_orientation = orientation_rows && robot.kind() == ChainKind::kSpatial;
  bool all_position_rows = true, all_orientation_rows = true;
  for (int r = 0; r < m; ++r) (r < position_rows ? all_position_rows : all_orientation_rows) &= robot.tracks(r);
  // The norm of v's entries that are task rows; v(i) is reference row first + i (a subset leaves some rows free).
  const auto tracked_norm = [&robot](const auto& v, int first, int count) {
    double sum = 0.0;
    for (int i = 0; i < count; ++i) {
      if (robot.tracks(first + i)) sum += v(i) * v(i);
    }
    return std::sqrt(sum);
  };
  Eigen::Vector3d wd_prev = Eigen::Vector3d::Zero(), w_prev = Eigen::Vector3d::Zero();
  const std::vector<TrajectoryColumnGroup>& groups = trajectory_column_groups();
  const auto start = std::chrono::steady_clock::now();
  const int report_every = std::max(1, steps / 200);
  std::string_view last_engine;  // the engine of the previous step (the names are static strings)
  const auto note = [&run, &last_engine](const StepOutput& o, double t) {
    if ((run.engines.empty() || o.info.engine.data() != last_engine.data()) &&
        std::find(run.engines.begin(), run.engines.end(), o.info.engine) == run.engines.end()) {
      run.engines.push_back(o.info.engine);
    }
    last_engine = o.info.engine;
    if (o.info.status == SolverStatus::kRelaxed) {
      ++run.relaxed_steps;
      run.max_relaxed_task_error = std::max(run.max_relaxed_task_error, o.task_row_error);
      if (run.first_relaxed.empty()) {
        std::ostringstream msg;
        msg << "t = " << t << " s: " << o.info.diagnosis;
        run.first_relaxed = msg.str();
      }
    }
    if (!usable(o.info.status) && run.failures++ == 0) {
      std::ostringstream msg;
      msg << "t = " << t << " s: " << to_string(o.info.status) << ": " << o.info.diagnosis;
      run.first_failure = msg.str();
    }
  };
  // A state a constraint finds violated (e.g. bodies that overlap) is a failed step too, whatever the solver said.
  const auto check_violations = [&run, &s, &data](double t) {
    const auto& constraints = s.scheme->constraints();
    for (std::size_t k = 0; k < constraints.size(); ++k) {
      const Constraint& c = *constraints[k];
      const PluginData* own = data.constraints[k].get();
      if (!c.active() || !c.violated(own)) continue;
      if (run.failures++ == 0) {
        std::ostringstream msg;
        msg << "t = " << t << " s: constraint '" << c.name() << "': " << c.describe_violation(own);
        run.first_failure = msg.str();
      }
      return;
    }
  };

  for (int k = 0; k <= steps; ++k) {
    const double t = k == steps ? s.duration : k * s.tau;
    ctrl.step(theta, t, out);
    const KinematicsData& kin = ctrl.kinematics();
    const QpProblem& qp = ctrl.qp();
    const Eigen::VectorXd& vlo = ctrl.velocity_lower();  // the laws at theta, as the step evaluated them
    const Eigen::VectorXd& vhi = ctrl.velocity_upper();
    // The row is made in a buffer that stays in the cache, then streamed into the table (Trajectory::append_row).
    // Every standard column is written below; the plugins' columns start at zero.
    double* row = row_buffer.data();
    std::fill(row_buffer.begin() + static_cast<std::ptrdiff_t>(standard_columns), row_buffer.end(), 0.0);
    std::size_t c = 0;
    const auto put = [&row, &c, n](const Eigen::VectorXd& v) {
      std::copy_n(v.data(), n, row + c);
      c += static_cast<std::size_t>(n);
    };
    // The standard columns, group by group as trajectory_column_groups() lists them.
    for (const TrajectoryColumnGroup& group : groups) {
      switch (group.value) {
        case StepValue::kTime: row[c++] = t; break;
        case StepValue::kTheta: put(theta); break;
        case StepValue::kThetaDot: put(out.theta_dot); break;
        case StepValue::kMergedLower: put(qp.lo); break;
        case StepValue::kMergedUpper: put(qp.hi); break;
        case StepValue::kDesired:
          if (spatial_orientation) {
            // Rotation vectors, recorded without 2 pi jumps (the controller itself uses rotations, not these).
            wd_prev = continuous_rotation_vector(ctrl.r_d().tail<3>(),
                                                 k == 0 ? Eigen::Vector3d(ctrl.r_d().tail<3>()) : wd_prev);
            for (int r = 0; r < 3; ++r) row[c++] = ctrl.r_d()(r);
            for (int r = 0; r < 3; ++r) row[c++] = wd_prev(r);
          } else {
            for (int r = 0; r < m; ++r) row[c++] = ctrl.r_d()(r);
          }
          break;
        case StepValue::kActual:
          if (spatial_orientation) {
            w_prev = continuous_rotation_vector(kin.f.tail<3>(), k == 0 ? Eigen::Vector3d(kin.f.tail<3>()) : w_prev);
            for (int r = 0; r < 3; ++r) row[c++] = kin.f(r);
            for (int r = 0; r < 3; ++r) row[c++] = w_prev(r);
          } else {
            for (int r = 0; r < m; ++r) row[c++] = kin.f(r);
          }
          break;
        case StepValue::kPositionError:
          if (all_position_rows) {
            double sum = 0.0;
            for (int r = 0; r < position_rows; ++r) sum += (ctrl.r_d()(r) - kin.f(r)) * (ctrl.r_d()(r) - kin.f(r));
            row[c++] = std::sqrt(sum);
          } else {
            row[c++] = tracked_norm(ctrl.r_d() - kin.f, 0, position_rows);
          }
          break;
        case StepValue::kOrientationError:
          if (!orientation_rows) break;
          // The angle between the desired and the actual orientation: planar |phi_d - phi|; spatial the angle of
          // R_d R' (from the rotations themselves). A subset of the orientation rows: the norm of those rows of the
          // rotation vector of R_d R'.
          if (spatial_orientation) {
            const Eigen::AngleAxisd err(rotation_from_vector(ctrl.r_d().tail<3>()) * kin.ee_pose.linear().transpose());
            row[c++] = all_orientation_rows ? err.angle() : tracked_norm(err.angle() * err.axis(), 3, 3);
          } else {
            row[c++] = std::abs(ctrl.r_d()(2) - kin.f(2));
          }
          break;
        case StepValue::kManipulability: row[c++] = kin.w; break;
        case StepValue::kIterations: row[c++] = out.info.iterations; break;
        case StepValue::kResidual: row[c++] = out.info.residual; break;
        case StepValue::kLawLower: put(vlo); break;
        case StepValue::kLawUpper: put(vhi); break;
        case StepValue::kStatus: row[c++] = static_cast<double>(static_cast<int>(out.info.status)); break;
      }
    }
    for (const Recorder& r : recorders) r.output->record(r.data, row + r.first);
    run.trajectory.append_row(row);
    const int failures_before = run.failures;
    note(out, t);
    if (run.failures == failures_before) check_violations(t);  // one failure per step at most
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
    if (!usable(out.info.status)) {
      ++run.held_steps;  // theta_dot = 0 (the controller never hands out an unconverged iterate): theta stays
      continue;
    }
    if (s.integrator == Integrator::kEuler) {
      theta += s.tau * out.theta_dot;
    } else {
      // Heun: average the slopes at theta and at the Euler prediction (one more QP per step, into its own output).
      theta_pred = theta + s.tau * out.theta_dot;
      const double t2 = std::min(s.duration, t + s.tau);
      ctrl.step(theta_pred, t2, out2);
      const int failures_before_stage = run.failures;
      note(out2, t2);
      if (s.on_infeasible == OnInfeasible::kStop && run.failures > failures_before_stage) {
        run.stopped = true;
        break;
      }
      if (usable(out2.info.status)) {
        theta += 0.5 * s.tau * (out.theta_dot + out2.theta_dot);
      } else {
        theta += s.tau * out.theta_dot;  // the second stage failed: Euler's step with the first, which solved
      }
    }
  }
  run.trajectory.publish();
  run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace redres

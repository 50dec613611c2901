#include "run/recording.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

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

}  // namespace

RunColumns run_columns(const Scenario& s, const PlantType& plant) {
  RunColumns out;
  std::vector<std::string>& columns = out.names;
  columns = standard_trajectory_columns(*s.robot);
  const auto add_recorder = [&](const Plugin& p, std::size_t objective, std::size_t constraint,
                                std::size_t task = kNoPlugin) {
    if (!p.active()) return;
    const PluginOutput* output = output_of(p);
    if (output == nullptr) return;
    const std::vector<std::string> own = output->recorded_columns();
    if (own.empty()) return;
    out.recorders.push_back({output, nullptr, columns.size(), objective, constraint, task});
    for (const auto& c : own) {
      // Two plugins may record the same quantity (two obstacle sets): the second gets its name as a prefix.
      const bool taken = std::find(columns.begin(), columns.end(), c) != columns.end();
      columns.push_back(taken ? p.name() + "." + c : c);
    }
  };
  const auto& objectives = s.scheme->objectives();
  const auto& constraints = s.scheme->constraints();
  for (std::size_t k = 0; k < objectives.size(); ++k) add_recorder(*objectives[k], k, kNoPlugin);
  for (std::size_t k = 0; k < constraints.size(); ++k) add_recorder(*constraints[k], kNoPlugin, k);
  const auto& tasks = s.scheme->tasks();
  for (std::size_t k = 0; k < tasks.size(); ++k) add_recorder(*tasks[k], kNoPlugin, kNoPlugin, k);
  out.levels_first = columns.size();
  if (s.scheme->cascaded()) {
    for (const SchemeLevelSpec& level : s.scheme->levels()) {
      columns.push_back("level_" + std::to_string(level.priority) + "_status");
      columns.push_back("level_" + std::to_string(level.priority) + "_iterations");
    }
  }
  out.plant_first = columns.size();
  if (plant.columns) {
    for (auto& c : plant.columns(s)) columns.push_back(std::move(c));
  }
  return out;
}

RowRecorder::RowRecorder(const Scenario& s, const Controller& ctrl, RunColumns layout, std::size_t width)
    : robot_(s.robot.get()),
      ctrl_(&ctrl),
      recorders_(std::move(layout.recorders)),
      groups_(&trajectory_column_groups()),
      row_(width),
      n_(s.robot->dof()),
      m_(s.robot->reference_dim()),
      position_rows_(s.robot->position_rows()) {
  const SchemeData& data = ctrl.plugin_data();
  for (Recorder& r : recorders_) {
    r.data = r.objective != kNoPlugin    ? data.objectives[r.objective].get()
             : r.constraint != kNoPlugin ? data.constraints[r.constraint].get()
                                         : data.tasks[r.task].get();
  }
  levels_first_ = layout.levels_first;
  standard_columns_ = recorders_.empty() ? width : recorders_.front().first;
  orientation_rows_ = robot_->has_orientation_rows();
  acc_limits_ = robot_->has_acceleration_limits();
  spatial_orientation_ = orientation_rows_ && robot_->kind() == ChainKind::kSpatial;
  for (int r = 0; r < m_; ++r) (r < position_rows_ ? all_position_rows_ : all_orientation_rows_) &= robot_->tracks(r);
}

double* RowRecorder::write(int k, double t, const Eigen::VectorXd& theta, const StepOutput& out) {
  const KinematicsData& kin = ctrl_->kinematics();
  const QpProblem& qp = ctrl_->qp();
  const Eigen::VectorXd& vlo = ctrl_->velocity_lower();  // the laws at theta, as the step evaluated them
  const Eigen::VectorXd& vhi = ctrl_->velocity_upper();
  // The row is made in a buffer that stays in the cache, then streamed into the table (Trajectory::append_row).
  // Every standard column is written below; the plugins' columns start at zero.
  double* row = row_.data();
  std::fill(row_.begin() + static_cast<std::ptrdiff_t>(standard_columns_), row_.end(), 0.0);
  std::size_t c = 0;
  const auto put = [&row, &c, n = n_](const Eigen::VectorXd& v) {
    std::copy_n(v.data(), n, row + c);
    c += static_cast<std::size_t>(n);
  };
  // The standard columns, group by group as trajectory_column_groups() lists them.
  for (const TrajectoryColumnGroup& group : *groups_) {
    switch (group.value) {
      case StepValue::kTime: row[c++] = t; break;
      case StepValue::kTheta: put(theta); break;
      case StepValue::kThetaDot: put(out.theta_dot); break;
      case StepValue::kMergedLower: put(qp.lo); break;
      case StepValue::kMergedUpper: put(qp.hi); break;
      case StepValue::kDesired:
        if (spatial_orientation_) {
          // Rotation vectors, recorded without 2 pi jumps (the controller itself uses rotations, not these).
          wd_prev_ = continuous_rotation_vector(ctrl_->r_d().tail<3>(),
                                                k == 0 ? Eigen::Vector3d(ctrl_->r_d().tail<3>()) : wd_prev_);
          for (int r = 0; r < 3; ++r) row[c++] = ctrl_->r_d()(r);
          for (int r = 0; r < 3; ++r) row[c++] = wd_prev_(r);
        } else {
          for (int r = 0; r < m_; ++r) row[c++] = ctrl_->r_d()(r);
        }
        break;
      case StepValue::kActual:
        if (spatial_orientation_) {
          w_prev_ = continuous_rotation_vector(kin.f.tail<3>(), k == 0 ? Eigen::Vector3d(kin.f.tail<3>()) : w_prev_);
          for (int r = 0; r < 3; ++r) row[c++] = kin.f(r);
          for (int r = 0; r < 3; ++r) row[c++] = w_prev_(r);
        } else {
          for (int r = 0; r < m_; ++r) row[c++] = kin.f(r);
        }
        break;
      case StepValue::kPositionError:
        if (all_position_rows_) {
          double sum = 0.0;
          for (int r = 0; r < position_rows_; ++r) sum += (ctrl_->r_d()(r) - kin.f(r)) * (ctrl_->r_d()(r) - kin.f(r));
          row[c++] = std::sqrt(sum);
        } else {
          row[c++] = tracked_norm(ctrl_->r_d() - kin.f, 0, position_rows_);
        }
        break;
      case StepValue::kOrientationError:
        if (!orientation_rows_) break;
        // The angle between the desired and the actual orientation: planar |phi_d - phi|; spatial the angle of
        // R_d R' (from the rotations themselves). A subset of the orientation rows: the norm of those rows of the
        // rotation vector of R_d R'.
        if (spatial_orientation_) {
          const Eigen::AngleAxisd err =
              orientation_error(rotation_from_vector(ctrl_->r_d().tail<3>()), kin.ee_pose.linear());
          row[c++] = all_orientation_rows_ ? err.angle() : tracked_norm(err.angle() * err.axis(), 3, 3);
        } else {
          row[c++] = std::abs(ctrl_->r_d()(2) - kin.f(2));
        }
        break;
      case StepValue::kManipulability: row[c++] = kin.w; break;
      case StepValue::kIterations: row[c++] = out.info.iterations; break;
      case StepValue::kResidual: row[c++] = out.info.residual; break;
      case StepValue::kLawLower: put(vlo); break;
      case StepValue::kLawUpper: put(vhi); break;
      case StepValue::kStatus: row[c++] = static_cast<double>(static_cast<int>(out.info.status)); break;
      case StepValue::kThetaDdot: put(out.theta_ddot); break;
      case StepValue::kAccelerationLower:
        if (acc_limits_) put(ctrl_->acceleration_lower());  // the laws at theta, as the step evaluated them
        break;
      case StepValue::kAccelerationUpper:
        if (acc_limits_) put(ctrl_->acceleration_upper());
        break;
    }
  }
  for (const Recorder& r : recorders_) r.output->record(r.data, row + r.first);
  for (std::size_t l = 0; l < out.levels.size(); ++l) {
    row[levels_first_ + 2 * l] = static_cast<double>(static_cast<int>(out.levels[l].status));
    row[levels_first_ + 2 * l + 1] = out.levels[l].iterations;
  }
  return row;
}

void StepLog::note(const StepOutput& o, double t) {
  RunResult& run = *run_;
  if ((run.engines.empty() || o.info.engine.data() != last_engine_.data()) &&
      std::find(run.engines.begin(), run.engines.end(), o.info.engine) == run.engines.end()) {
    run.engines.push_back(o.info.engine);
  }
  last_engine_ = o.info.engine;
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
}

void StepLog::check_violations(double t) {
  RunResult& run = *run_;
  const auto& constraints = scheme_->constraints();
  for (std::size_t k = 0; k < constraints.size(); ++k) {
    const Constraint& c = *constraints[k];
    const PluginData* own = data_->constraints[k].get();
    if (!c.active() || !c.violated(own)) continue;
    if (run.failures++ == 0) {
      std::ostringstream msg;
      msg << "t = " << t << " s: constraint '" << c.name() << "': " << c.describe_violation(own);
      run.first_failure = msg.str();
    }
    return;
  }
}

}  // namespace redres

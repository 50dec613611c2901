#pragma once
/// @file
/// `task_tracking`: the end-effector task with position-error feedback (eq. 6), m equality rows
///   J x = r_d_dot + K (r_d - f(theta)),
/// where m is the robot's number of task rows and K = diag(gain). At the acceleration level (x = theta_ddot) the rows
/// are those of the error dynamics e_ddot + 2K e_dot + K^2 e = 0 (critically damped at the same rate K):
///   J x = r_d_ddot - J_dot theta_dot + 2K (r_d_dot - J theta_dot) + K^2 (r_d - f(theta)),
/// with J_dot theta_dot = sum_i theta_dot_i (dJ/dtheta_i) theta_dot. For spatial `pose` tasks the orientation rows use
/// the rotation-vector error log(R_d R') (r_d's orientation entries are a rotation vector). A task that names a subset
/// of rows (`task = ["x", "y", "z", "wx"]`) keeps those rows of the error and of J: S J x = S (r_d_dot + K e).
///
/// It is the frame task (tasks/frame_task.hpp) on the frame "end_effector" with reference "path" and the robot's task
/// rows, by another name: that task computes the rows and puts them into the QP (at the velocity level straight into
/// the QP's rows, FrameTask::write_rows_in_order; otherwise through write_task_terms, the writer of every task). As a constraint it holds at every priority level of a cascade, as a hard equality.
/// Reports to the run summary, for tasks with orientation rows: `max_orientation_error` (rad), the largest
/// orientation error over the run (the angle between the desired and the actual orientation; for a subset, the norm
/// of the rotation-vector error's task rows).

#include "redres/control/plugin.hpp"
#include "redres/run/plugin_output.hpp"
#include "redres/tasks/frame_task.hpp"

namespace redres {

/// The configuration of `task_tracking`.
struct TaskTrackingConfig {
  PerJoint gain = 8.0;  //!< feedback gain K (1/s): one number or one per task row (the paper: 8)

  static const Schema<TaskTrackingConfig>& schema();
};

/// The end-effector task constraint: the end-effector frame task, held as a constraint.
class TaskTracking final : public Configured<Constraint, TaskTrackingConfig>, public PluginOutput {
 public:
  static constexpr const char* kType = "task_tracking";
  TaskTracking(const Config& config, const RobotModel& robot);
  /// Both levels (the acceleration level's rows are in the file comment).
  [[nodiscard]] bool supports(ControlOrder /*order*/) const override { return true; }
  [[nodiscard]] int equality_rows(const RobotModel& robot) const override { return robot.task_dim(); }
  [[nodiscard]] KinematicsLevel kinematics_level() const override { return KinematicsLevel::kJacobian; }
  /// The frame task's data (its rows).
  [[nodiscard]] std::unique_ptr<PluginData> make_data() const override { return task_.make_data(); }
  void start(PluginData* data) const override { task_.start(data); }
  void summarise(const RobotModel& robot, const Trajectory& run, const PluginData* data,
                 std::vector<Metric>& out) const override;
  /// The frame task it is.
  [[nodiscard]] const FrameTask& task() const noexcept { return task_; }

 private:
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const override;

  FrameTask task_;
};

}  // namespace redres

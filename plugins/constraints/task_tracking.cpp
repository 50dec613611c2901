#include "redres/constraints/task_tracking.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "redres/common/hot.hpp"
#include "redres/run/trajectory.hpp"

namespace redres {

const Schema<TaskTrackingConfig>& TaskTrackingConfig::schema() {
  using C = TaskTrackingConfig;
  static const Schema<C> s{
      {field("gain", &C::gain, "1/s", "feedback gain K: one number or one per task row", at_least<PerJoint>(0.0))}};
  return s;
}

namespace {

// The frame task that is the end-effector task: the frame "end_effector" at its origin, following the path, on the
// robot's task rows (a planar robot's "phi" is the frame's "wz"), with the gain per task row.
FrameTaskConfig end_effector_task(const TaskTrackingConfig& config, const RobotModel& robot) {
  FrameTaskConfig task;
  task.frame = "end_effector";
  task.reference = "path";
  for (const std::string& row : robot.task_names()) task.rows.push_back(row == "phi" ? "wz" : row);
  const Eigen::VectorXd gain = config.gain.resolve(robot.task_dim(), "gain", "task row");
  task.gain = PerJoint(std::vector<double>(gain.data(), gain.data() + gain.size()));
  return task;
}

}  // namespace

TaskTracking::TaskTracking(const Config& config, const RobotModel& robot)
    : Configured(kType, config), task_(end_effector_task(config_, robot), robot) {
  task_.set_name(kType);
}

REDRES_HOT void TaskTracking::add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const {
  REDRES_REQUIRE(data != nullptr, "task_tracking", "its data is the one make_data() made");
  // The paper's task goes straight into the QP's rows; any other through the task's rows. The scheme scans the QP.
  if (task_.write_rows_in_order(ctx, data, builder)) return;
  auto& terms = static_cast<TaskData&>(*data);
  task_.evaluate_unchecked(ctx, terms);
  write_task_terms(task_, terms.rows, builder);
}

void TaskTracking::summarise(const RobotModel& robot, const Trajectory& run, const PluginData* /*data*/,
                             std::vector<Metric>& out) const {
  if (!robot.has_orientation_rows()) return;
  // The run records the angle between the desired and the actual orientation at every step.
  const std::size_t c = run.column("orientation_error");
  double worst = 0.0;
  for (std::size_t row = 0; row < run.size(); ++row) worst = std::max(worst, run(row, c));
  out.push_back({"max_orientation_error", {worst}, "rad"});
}

namespace {
const bool kTaskTrackingRegistered = constraint_registry().add_plugin<TaskTracking>(
    "J x = r_d_dot + K (r_d - f(theta)) (eq. 6): the end-effector task with error feedback");
}  // namespace

}  // namespace redres

#include "redres/constraints/task_tracking.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "redres/trajectory.hpp"

namespace redres {

const Schema<TaskTrackingConfig>& TaskTrackingConfig::schema() {
  using C = TaskTrackingConfig;
  static const Schema<C> s{
      {field("gain", &C::gain, "1/s", "feedback gain K: one number or one per task row", at_least<PerJoint>(0.0))}};
  return s;
}

TaskTracking::TaskTracking(const Config& config, const RobotModel& robot)
    : Configured(kType, config), gain_(config_.gain.resolve(robot.task_dim(), "gain", "task row")) {}

void TaskTracking::add_to(const Context& ctx, QpBuilder& builder) const {
  REDRES_REQUIRE(ctx.r_d != nullptr && ctx.r_d_dot != nullptr, "task_tracking",
                 "the context carries the desired r_d and r_d_dot");
  const Eigen::Index m = gain_.size();
  REDRES_REQUIRE(ctx.r_d->size() == m && ctx.r_d_dot->size() == m, "task_tracking",
                 "r_d and r_d_dot have one entry per task row (" + std::to_string(m) + ")");
  const KinematicsData& k = *ctx.kinematics;
  builder.equality_matrix() = k.J;
  auto d = builder.equality_rhs();
  const bool spatial_pose = ctx.robot->kind() == ChainKind::kSpatial && ctx.robot->task() == TaskRows::kPose;
  const Eigen::Index np = spatial_pose ? 3 : m;
  d.head(np) = ctx.r_d_dot->head(np) + gain_.head(np).cwiseProduct(ctx.r_d->head(np) - k.f.head(np));
  if (spatial_pose) {
    const Eigen::AngleAxisd err(rotation_from_vector(ctx.r_d->tail<3>()) * k.ee_pose.linear().transpose());
    d.tail(3) = ctx.r_d_dot->tail<3>() + gain_.tail<3>().cwiseProduct(err.angle() * err.axis());
  }
}

void TaskTracking::summarise(const RobotModel& robot, const Trajectory& run, std::vector<Metric>& out) const {
  if (!robot.has_orientation_rows()) return;
  // The run records the angle between the desired and the actual orientation at every step.
  const std::size_t c = run.column("orientation_error");
  double worst = 0.0;
  for (std::size_t row = 0; row < run.size(); ++row) worst = std::max(worst, run(row, c));
  out.push_back({"max_orientation_error", {worst}, "rad"});
}

namespace {
const bool kRegistered = constraint_registry().add_plugin<TaskTracking>(
    "J x = r_d_dot + K (r_d - f(theta)) (eq. 6): the end-effector task with error feedback");
}  // namespace

}  // namespace redres

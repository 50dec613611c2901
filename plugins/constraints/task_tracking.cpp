#include "redres/constraints/task_tracking.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "redres/run/trajectory.hpp"

namespace redres {

const Schema<TaskTrackingConfig>& TaskTrackingConfig::schema() {
  using C = TaskTrackingConfig;
  static const Schema<C> s{
      {field("gain", &C::gain, "1/s", "feedback gain K: one number or one per task row", at_least<PerJoint>(0.0))}};
  return s;
}

TaskTracking::TaskTracking(const Config& config, const RobotModel& robot)
    : Configured(kType, config), gain_(config_.gain.resolve(robot.task_dim(), "gain", "task row")) {}

void TaskTracking::add_to(const Context& ctx, QpBuilder& builder, PluginData* /*data*/) const {
  REDRES_REQUIRE(ctx.r_d != nullptr && ctx.r_d_dot != nullptr, "task_tracking",
                 "the context carries the desired r_d and r_d_dot");
  const RobotModel& robot = *ctx.robot;
  const Eigen::Index rows = robot.reference_dim();
  REDRES_REQUIRE(ctx.r_d->size() == rows && ctx.r_d_dot->size() == rows, "task_tracking",
                 "r_d and r_d_dot have one entry per reference row (" + std::to_string(rows) + ")");
  const KinematicsData& k = *ctx.kinematics;
  // J: this plugin's rows of the QP's J (column-major, leading dimension m_e), copied column by column.
  auto J = builder.equality_matrix();
  const Eigen::Index m = k.J.rows(), n = k.J.cols(), ld = J.outerStride();
  const double* from = k.J.data();
  double* to = J.data();
  if (ld == m) {
    std::copy_n(from, m * n, to);  // the QP's only equality rows: one block
  } else {
    for (Eigen::Index c = 0; c < n; ++c) std::copy_n(from + c * m, m, to + c * ld);
  }
  // The error e = r_d - f in every reference row; a spatial orientation's is the rotation vector of R_d R'.
  const double* r_d = ctx.r_d->data();
  const double* r_d_dot = ctx.r_d_dot->data();
  const double* f = k.f.data();
  double e[6];
  for (Eigen::Index r = 0; r < rows; ++r) e[r] = r_d[r] - f[r];
  if (robot.kind() == ChainKind::kSpatial && robot.has_orientation_rows()) {
    const Eigen::Vector3d v = orientation_error_vector(rotation_from_vector(ctx.r_d->tail<3>()), k.ee_pose.linear());
    e[3] = v.x();
    e[4] = v.y();
    e[5] = v.z();
  }
  // d = S (r_d_dot + K e): the task rows only (all of them unless the task names a subset).
  double* d = builder.equality_rhs().data();
  const int* task_rows = robot.task_rows().data();
  const double* gain = gain_.data();
  const Eigen::Index task = gain_.size();
  if (ctx.order == ControlOrder::kVelocity) {
    for (Eigen::Index i = 0; i < task; ++i) {
      const int r = task_rows[i];
      d[i] = r_d_dot[r] + gain[i] * e[r];
    }
    return;
  }
  // Acceleration level: d = S (r_d_ddot - J_dot theta_dot + 2K (r_d_dot - J theta_dot) + K^2 e).
  REDRES_REQUIRE(ctx.r_d_ddot != nullptr && ctx.r_d_ddot->size() == rows && ctx.theta_dot != nullptr &&
                     ctx.theta_dot->size() == n && k.dJ.cols() == n * n,
                 "task_tracking", "at the acceleration level the context carries r_d_ddot, theta_dot and dJ");
  const double* v = ctx.theta_dot->data();
  const double* r_d_ddot = ctx.r_d_ddot->data();
  double jv[6] = {0, 0, 0, 0, 0, 0}, jdv[6] = {0, 0, 0, 0, 0, 0};
  for (Eigen::Index c = 0; c < n; ++c) {
    const double* col = from + c * m;  // J theta_dot
    for (Eigen::Index r = 0; r < m; ++r) jv[r] += col[r] * v[c];
  }
  const double* dj = k.dJ.data();
  for (Eigen::Index i = 0; i < n; ++i) {  // sum_i theta_dot_i (dJ/dtheta_i theta_dot)
    if (v[i] == 0.0) continue;
    for (Eigen::Index c = 0; c < n; ++c) {
      const double s = v[i] * v[c];
      const double* col = dj + (i * n + c) * m;
      for (Eigen::Index r = 0; r < m; ++r) jdv[r] += col[r] * s;
    }
  }
  for (Eigen::Index i = 0; i < task; ++i) {
    const int r = task_rows[i];
    // J holds the task rows only: its row i is reference row r.
    d[i] = r_d_ddot[r] - jdv[i] + 2.0 * gain[i] * (r_d_dot[r] - jv[i]) + gain[i] * gain[i] * e[r];
  }
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
const bool kRegistered = constraint_registry().add_plugin<TaskTracking>(
    "J x = r_d_dot + K (r_d - f(theta)) (eq. 6): the end-effector task with error feedback");
}  // namespace

}  // namespace redres

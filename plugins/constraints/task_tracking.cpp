/// `task_tracking`: the end-effector task with position-error feedback (eq. 6), m equality rows
///   J x = r_d_dot + K (r_d - f(theta)),
/// where m is the robot's number of task rows and K = diag(gain). For spatial `pose` tasks the orientation rows use
/// the rotation-vector error log(R_d R') (r_d's orientation entries are a rotation vector).
/// TOML keys: `gain` (1/s; one number, or one per task row; default 8.0 as in the paper).

#include <Eigen/Geometry>

#include "redres/plugin.hpp"

namespace redres {
namespace {

Eigen::Matrix3d rotation_of(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, v / angle).toRotationMatrix();
}

class TaskTracking final : public Constraint {
 public:
  TaskTracking(const TableReader& config, const RobotModel& robot)
      : Constraint(config), gain_(read_per_joint(config, "gain", 8.0, robot.task_dim())) {
    if (!(gain_.array() >= 0.0).all()) config.fail("gain", "expected feedback gains >= 0 (1/s)");
  }

  int equality_rows(const RobotModel& robot) const override { return robot.task_dim(); }
  KinematicsLevel kinematics_level() const override { return KinematicsLevel::kJacobian; }

 private:
  void add_to(const Context& ctx, QpBuilder& builder) const override {
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
      const Eigen::AngleAxisd err(rotation_of(ctx.r_d->tail<3>()) * k.ee_pose.linear().transpose());
      d.tail(3) = ctx.r_d_dot->tail<3>() + gain_.tail<3>().cwiseProduct(err.angle() * err.axis());
    }
  }

  void write_config(toml::table& out) const override { write_per_joint(out, "gain", gain_); }

  Eigen::VectorXd gain_;
};

const bool kRegistered = constraint_registry().add({
    "task_tracking",
    "J x = r_d_dot + K (r_d - f(theta)) (eq. 6): the end-effector task with error feedback",
    {{"gain", "8.0", "feedback gain K (1/s): one number or one per task row"}},
    [](const TableReader& r, const RobotModel& robot) -> std::unique_ptr<Constraint> {
      return std::make_unique<TaskTracking>(r, robot);
    },
});

}  // namespace
}  // namespace redres

/// `joint_angle_margin`: joint position limits with a safety region, converted to velocity bounds (eq. 9 and the
/// text after it):
///   kappa ((theta^- + margin) - theta) <= x <= kappa ((theta^+ - margin) - theta).
/// TOML keys: `kappa` (1/s, default 4.0 as in the paper), `margin` (rad or m; one number or one per joint;
/// default 0.0349 = 2 degrees as in the paper).

#include "redres/plugin.hpp"

namespace redres {
namespace {

class JointAngleMargin final : public Constraint {
 public:
  JointAngleMargin(const TableReader& config, const RobotModel& robot)
      : Constraint(config),
        kappa_(config.number("kappa", 4.0)),
        margin_(read_per_joint(config, "margin", 0.0349, robot.dof())) {
    if (!(kappa_ > 0.0)) config.fail("kappa", "expected kappa > 0 (1/s)");
    for (int j = 0; j < robot.dof(); ++j) {
      const double range = robot.upper_limits()(j) - robot.lower_limits()(j);
      if (!(margin_(j) >= 0.0) || 2.0 * margin_(j) >= range) {
        config.fail("margin", "expected 0 <= margin < half the range of joint '" + robot.joint(j).name + "' (" +
                                  std::to_string(range / 2.0) + "), got " + std::to_string(margin_(j)));
      }
    }
  }

 private:
  void add_to(const Context& ctx, QpBuilder& builder) const override {
    const RobotModel& robot = *ctx.robot;
    const Eigen::VectorXd& theta = ctx.theta();
    for (int j = 0; j < robot.dof(); ++j) {
      builder.intersect_bound(j, kappa_ * ((robot.lower_limits()(j) + margin_(j)) - theta(j)),
                              kappa_ * ((robot.upper_limits()(j) - margin_(j)) - theta(j)));
    }
  }

  void write_config(toml::table& out) const override {
    out.insert("kappa", kappa_);
    write_per_joint(out, "margin", margin_);
  }

  double kappa_;
  Eigen::VectorXd margin_;
};

const bool kRegistered = constraint_registry().add({
    "joint_angle_margin",
    "kappa((theta^- + margin) - theta) <= x <= kappa((theta^+ - margin) - theta) (eq. 9 with a safety region)",
    {{"kappa", "4.0", "gain (1/s), > 0"}, {"margin", "0.0349", "safety region (rad or m): number or per joint"}},
    [](const TableReader& r, const RobotModel& robot) -> std::unique_ptr<Constraint> {
      return std::make_unique<JointAngleMargin>(r, robot);
    },
});

}  // namespace
}  // namespace redres

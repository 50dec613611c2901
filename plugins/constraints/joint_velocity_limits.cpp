/// `joint_velocity_limits`: the robot's per-joint velocity-limit laws as bounds (eq. 8, VJVL),
///   scale theta_dot^-(theta) <= x <= scale theta_dot^+(theta).
/// TOML keys: `scale` (0 < scale <= 1, default 1.0; e.g. 0.9 keeps a 10 % reserve).

#include "redres/plugin.hpp"

namespace redres {
namespace {

class JointVelocityLimits final : public Constraint {
 public:
  explicit JointVelocityLimits(const TableReader& config) : Constraint(config), scale_(config.number("scale", 1.0)) {
    if (!(scale_ > 0.0 && scale_ <= 1.0)) config.fail("scale", "expected 0 < scale <= 1");
  }

 private:
  void add_to(const Context& ctx, QpBuilder& builder) const override {
    const RobotModel& robot = *ctx.robot;
    const Eigen::VectorXd& theta = ctx.theta();
    for (int j = 0; j < robot.dof(); ++j) {
      const VelocityBounds b = robot.joint(j).velocity_limit->bounds(theta(j));
      builder.intersect_bound(j, scale_ * b.lower, scale_ * b.upper);
    }
  }

  void write_config(toml::table& out) const override { out.insert("scale", scale_); }

  double scale_;
};

const bool kRegistered = constraint_registry().add({
    "joint_velocity_limits",
    "scale theta_dot^-(theta) <= x <= scale theta_dot^+(theta): the robot's velocity-limit laws (eq. 8, VJVL)",
    {{"scale", "1.0", "fraction of the law's limits, 0 < scale <= 1"}},
    [](const TableReader& r, const RobotModel& /*robot*/) -> std::unique_ptr<Constraint> {
      return std::make_unique<JointVelocityLimits>(r);
    },
});

}  // namespace
}  // namespace redres

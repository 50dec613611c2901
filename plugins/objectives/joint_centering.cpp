/// `joint_centering`: the repetitive-motion / joint-centring term, zeta += weight * lambda (theta - theta_ref).
/// With min_velocity_norm it pulls the joints towards theta_ref. It is the gradient of
/// lambda |theta - theta_ref|^2 / 2.
/// TOML keys: `lambda` (1/s, default 1.0), `theta_ref` (rad or m per joint, default: the robot's home).

#include "redres/plugin.hpp"

namespace redres {
namespace {

class JointCentering final : public Objective {
 public:
  JointCentering(const TableReader& config, const RobotModel& robot)
      : Objective(config),
        lambda_(config.number("lambda", 1.0)),
        theta_ref_(config.has("theta_ref") ? read_per_joint(config, "theta_ref", 0.0, robot.dof()) : robot.home()) {
    if (!(lambda_ >= 0.0)) config.fail("lambda", "expected lambda >= 0 (1/s)");
  }

  std::optional<double> potential(const Context& ctx) const override {
    return 0.5 * lambda_ * (ctx.theta() - theta_ref_).squaredNorm();
  }

 private:
  void add_to(const Context& ctx, QpBuilder& builder) const override {
    Eigen::VectorXd& z = builder.scratch();
    z = lambda_ * (ctx.theta() - theta_ref_);
    builder.add_linear(z);
  }
  void write_config(toml::table& out) const override {
    out.insert("lambda", lambda_);
    write_per_joint(out, "theta_ref", theta_ref_);
  }

  double lambda_;
  Eigen::VectorXd theta_ref_;
};

const bool kRegistered = objective_registry().add({
    "joint_centering",
    "zeta += lambda (theta - theta_ref): pulls the joints towards theta_ref (repetitive motion)",
    {{"lambda", "1.0", "gain (1/s), >= 0"}, {"theta_ref", "home", "reference configuration (number or per joint)"}},
    [](const TableReader& r, const RobotModel& robot) -> std::unique_ptr<Objective> {
      return std::make_unique<JointCentering>(r, robot);
    },
});

}  // namespace
}  // namespace redres

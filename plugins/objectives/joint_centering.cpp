#include "redres/objectives/joint_centering.hpp"

namespace redres {

const Schema<JointCenteringConfig>& JointCenteringConfig::schema() {
  using C = JointCenteringConfig;
  static const Schema<C> s{{field("lambda", &C::lambda, "1/s", "gain", at_least(0.0)),
                            field("theta_ref", &C::theta_ref, "rad or m",
                                  "reference configuration: one number or one per joint (default: the robot's home)")}};
  return s;
}

JointCentering::JointCentering(const Config& config, const RobotModel& robot)
    : Configured(kType, config),
      theta_ref_(config_.theta_ref ? config_.theta_ref->resolve(robot.dof(), "theta_ref") : robot.home()) {}

std::optional<double> JointCentering::potential(const Context& ctx) const {
  return 0.5 * config_.lambda * (ctx.theta() - theta_ref_).squaredNorm();
}

std::unique_ptr<PluginData> JointCentering::make_data() const {
  return std::make_unique<Workspace>(static_cast<int>(theta_ref_.size()), 1);
}

void JointCentering::add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const {
  REDRES_REQUIRE(data != nullptr, kType, "the controller made this plugin's data");
  Eigen::VectorXd& z = static_cast<Workspace&>(*data)[0];
  z = config_.lambda * (ctx.theta() - theta_ref_);
  builder.add_linear(z);
}

namespace {
const bool kJointCenteringRegistered = objective_registry().add_plugin<JointCentering>(
    "zeta += lambda (theta - theta_ref): pulls the joints towards theta_ref (repetitive motion)");
}  // namespace

}  // namespace redres

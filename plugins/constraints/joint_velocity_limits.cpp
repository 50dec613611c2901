#include "redres/constraints/joint_velocity_limits.hpp"

#include "redres/common/hot.hpp"
#include "redres/model/velocity_limit.hpp"

namespace redres {

const Schema<JointVelocityLimitsConfig>& JointVelocityLimitsConfig::schema() {
  using C = JointVelocityLimitsConfig;
  static const Schema<C> s{{field("scale", &C::scale, "", "fraction of the laws' limits",
                                  rule<double>("in (0, 1]", [](double v) { return v > 0.0 && v <= 1.0; }))}};
  return s;
}

JointVelocityLimits::JointVelocityLimits(const Config& config, const RobotModel& robot)
    : Configured(kType, config), n_(robot.dof()) {}

std::unique_ptr<PluginData> JointVelocityLimits::make_data() const { return std::make_unique<Workspace>(n_, 2); }

REDRES_HOT void JointVelocityLimits::add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const {
  const double scale = config_.scale;
  if (ctx.order == ControlOrder::kVelocity && ctx.velocity_lower != nullptr && ctx.velocity_upper != nullptr) {
    if (scale == 1.0) {
      builder.intersect_bounds(*ctx.velocity_lower, *ctx.velocity_upper);
      return;
    }
    REDRES_REQUIRE(data != nullptr, kType, "the controller made this plugin's data");
    Workspace& w = static_cast<Workspace&>(*data);
    w[0] = scale * *ctx.velocity_lower;
    w[1] = scale * *ctx.velocity_upper;
    builder.intersect_bounds(w[0], w[1]);
    return;
  }
  // Joint by joint: a caller's Context without the laws' values, or the acceleration level, where the velocity after
  // the step keeps them.
  for (int j = 0; j < ctx.robot->dof(); ++j) {
    const VelocityBounds b = ctx.velocity_bounds(j);
    builder.intersect_bound(j, ctx.velocity_to_x(scale * b.lower, j), ctx.velocity_to_x(scale * b.upper, j));
  }
}

namespace {
const bool kJointVelocityLimitsRegistered = constraint_registry().add_plugin<JointVelocityLimits>(
    "scale theta_dot^-(theta) <= x <= scale theta_dot^+(theta): the robot's velocity-limit laws (eq. 8, VJVL)");
}  // namespace

}  // namespace redres

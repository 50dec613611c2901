#include "redres/objectives/min_acceleration_norm.hpp"

namespace redres {

const Schema<MinAccelerationNormConfig>& MinAccelerationNormConfig::schema() {
  using C = MinAccelerationNormConfig;
  static const Schema<C> s{
      {field("damping", &C::damping, "1/s", "damping of the joint velocity at the acceleration level", at_least(0.0))}};
  return s;
}

MinAccelerationNorm::MinAccelerationNorm(const Config& config, const RobotModel& /*robot*/)
    : Configured(kType, config) {}

void MinAccelerationNorm::add_to(const Context& ctx, QpBuilder& builder, PluginData* /*data*/) const {
  builder.add_identity();
  // A Context without the state between steps (one a caller builds) reads as an arm at rest: no linear term.
  if (ctx.order == ControlOrder::kAcceleration) {
    if (config_.damping > 0.0 && ctx.theta_dot != nullptr) builder.add_linear(config_.damping, *ctx.theta_dot);
    return;
  }
  if (ctx.theta_dot_prev != nullptr) builder.add_linear(-1.0, *ctx.theta_dot_prev);
}

namespace {
const bool kMinAccelerationNormRegistered = objective_registry().add_plugin<MinAccelerationNorm>(
    "x'x/2 + damping theta_dot'x at the acceleration level (MAN); |x - theta_dot_prev|^2/2 at the velocity level");
}  // namespace

}  // namespace redres

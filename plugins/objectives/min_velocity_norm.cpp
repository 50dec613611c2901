#include "redres/objectives/min_velocity_norm.hpp"
#include "redres/common/hot.hpp"

namespace redres {

const Schema<MinVelocityNormConfig>& MinVelocityNormConfig::schema() {
  static const Schema<MinVelocityNormConfig> s{};
  return s;
}

MinVelocityNorm::MinVelocityNorm(const Config& config, const RobotModel& /*robot*/) : Configured(kType, config) {}

// W = I has no linear term: zeta stays zero, the gradient of a constant potential.
std::optional<double> MinVelocityNorm::potential(const Context& /*ctx*/) const { return 0.0; }

REDRES_HOT void MinVelocityNorm::add_to(const Context& /*ctx*/, QpBuilder& builder, PluginData* /*data*/) const {
  builder.add_identity();
}

namespace {
const bool kMinVelocityNormRegistered =
    objective_registry().add_plugin<MinVelocityNorm>("x'x/2: W += weight * I (MVN, the paper's p = 0)");
}  // namespace

}  // namespace redres

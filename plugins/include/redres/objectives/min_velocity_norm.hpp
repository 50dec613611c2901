#pragma once
/// @file
/// `min_velocity_norm`: the minimum-velocity-norm term x'x/2 (MVN; with no other objective this is the paper's
/// p = 0 scheme). Adds W += weight * I. No keys of its own.

#include "redres/control/plugin.hpp"

namespace redres {

/// `min_velocity_norm` has no keys of its own.
struct MinVelocityNormConfig {
  static const Schema<MinVelocityNormConfig>& schema();
};

/// The minimum-velocity-norm objective.
class MinVelocityNorm final : public Configured<Objective, MinVelocityNormConfig> {
 public:
  static constexpr const char* kType = "min_velocity_norm";
  MinVelocityNorm(const Config& config, const RobotModel& robot);
  [[nodiscard]] std::optional<double> potential(const Context& ctx) const override;

 private:
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const override;
};

}  // namespace redres

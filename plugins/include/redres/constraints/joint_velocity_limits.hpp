#pragma once
/// @file
/// `joint_velocity_limits`: the robot's per-joint velocity-limit laws as bounds (eq. 8, VJVL),
///   scale theta_dot^-(theta) <= x <= scale theta_dot^+(theta).

#include "redres/control/plugin.hpp"

namespace redres {

/// The configuration of `joint_velocity_limits`.
struct JointVelocityLimitsConfig {
  double scale = 1.0;  //!< fraction of the laws' limits, 0 < scale <= 1 (e.g. 0.9 keeps a 10 % reserve)

  static const Schema<JointVelocityLimitsConfig>& schema();
};

/// The varying joint-velocity limits constraint.
class JointVelocityLimits final : public Configured<Constraint, JointVelocityLimitsConfig> {
 public:
  static constexpr const char* kType = "joint_velocity_limits";
  JointVelocityLimits(const Config& config, const RobotModel& robot);
  /// Both levels: at the acceleration level the laws bound the velocity after the step (Context::velocity_to_x).
  [[nodiscard]] bool supports(ControlOrder /*order*/) const override { return true; }
  /// Its workspace: the scaled bounds of a step (a Workspace of two n-vectors).
  [[nodiscard]] std::unique_ptr<PluginData> make_data() const override;

 private:
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const override;

  int n_;
};

}  // namespace redres

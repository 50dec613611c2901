#pragma once
/// @file
/// `joint_acceleration_limits`: the robot file's per-joint acceleration limits (`acceleration_limit`) as bounds on
/// the step's command, so that no command asks a joint for a velocity jump beyond them (docs/motion.md).
///
/// With v the joint velocity before the step (the previous command at the velocity level; Context::theta_dot at the
/// acceleration level) and [a^-, a^+] the joint's limits at theta (times `scale`), the velocity v' after the step
/// keeps
///   v + tau a^- <= v' <= v + tau a^+,
/// and, with `braking` (the default), the joint can still stop before its position limit at a^-: after the step it
/// moves on at v' for tau and then brakes, so v' tau + v'^2 / (2 |a^-|) <= theta^+ - theta, that is
///   v' <= |a^-| (-tau + sqrt(tau^2 + 2 (theta^+ - theta) / |a^-|))          (about sqrt(2 |a^-| d) for small tau),
/// and the same towards theta^- with a^+. With jerk limits [j^-, j^+] the full deceleration comes only after a ramp
/// of |a^-| / j^+, during which the joint is taken to move on at v' (tau + |a^-| / j^+ in place of tau: conservative).
/// The position bound never asks for more than the limit's deceleration (it
/// yields to v + tau a^-), so the bounds stay consistent: a run that kept them can always keep them. At the
/// acceleration level the same bounds on v' become bounds on x = (v' - v) / tau (and the step moves at (v + v') / 2).

#include "redres/control/plugin.hpp"

namespace redres {

/// The configuration of `joint_acceleration_limits`.
struct JointAccelerationLimitsConfig {
  double scale = 1.0;   //!< fraction of the robot's acceleration limits, 0 < scale <= 1
  bool braking = true;  //!< the position limits as a stopping distance at the acceleration limit

  static const Schema<JointAccelerationLimitsConfig>& schema();
};

/// The joint-acceleration-limits constraint (both levels).
class JointAccelerationLimits final : public Configured<Constraint, JointAccelerationLimitsConfig> {
 public:
  static constexpr const char* kType = "joint_acceleration_limits";
  /// Throws std::invalid_argument naming the first joint of `robot` without an acceleration limit.
  JointAccelerationLimits(const Config& config, const RobotModel& robot);
  [[nodiscard]] bool supports(ControlOrder /*order*/) const override { return true; }
  [[nodiscard]] std::unique_ptr<PluginData> make_data() const override;

 private:
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const override;
  int n_;
  bool jerk_;  // the robot gives jerk limits: braking counts the ramp to full deceleration
};

/// Throws std::invalid_argument naming joint `missing` (when >= 0) as lacking the robot file's `key`, which the
/// constraint `type` needs on every joint (RobotModel::first_without_acceleration_limit() and the like).
void require_motion_limit(const RobotModel& robot, int missing, const char* key, const char* type);

/// The speed v' a joint may have at distance d >= 0 from a limit and still stop before it at deceleration a > 0,
/// moving on at v' for the time c first: c v' + v'^2 / (2 a) = d.
[[nodiscard]] double stopping_speed(double d, double a, double c) noexcept;

}  // namespace redres

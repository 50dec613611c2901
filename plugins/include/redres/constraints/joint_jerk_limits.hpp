#pragma once
/// @file
/// `joint_jerk_limits`: the robot file's per-joint jerk limits (`jerk_limit`) as bounds on the change of the
/// commanded acceleration (docs/motion.md). With the previous acceleration a_prev = (theta_dot_prev -
/// theta_dot_prev2) / tau (zero at the start of a run: the arm was at rest) and [j^-, j^+] the joint's limits at theta
/// (times `scale`), this step's acceleration a = (v' - theta_dot_prev) / tau keeps
///   a_prev + tau j^- <= a <= a_prev + tau j^+.
/// Towards a velocity limit the acceleration is also kept low enough for the jerk limit to bring it to zero in time:
/// v + tau a + a^2 / (2 |j^-|) <= v^+(theta) (and the same towards v^-; the robot's velocity laws, unscaled), the
/// velocity-limit analogue of joint_acceleration_limits' braking term; it yields to the hardest turn the jerk limit
/// allows, so the bounds stay consistent. Both levels: at the velocity level a bound on v' = x, at the acceleration
/// level on x = a.

#include "redres/control/plugin.hpp"

namespace redres {

/// The configuration of `joint_jerk_limits`.
struct JointJerkLimitsConfig {
  double scale = 1.0;  //!< fraction of the robot's jerk limits, 0 < scale <= 1

  static const Schema<JointJerkLimitsConfig>& schema();
};

/// The joint-jerk-limits constraint (both levels).
class JointJerkLimits final : public Configured<Constraint, JointJerkLimitsConfig> {
 public:
  static constexpr const char* kType = "joint_jerk_limits";
  /// Throws std::invalid_argument naming the first joint of `robot` without a jerk limit.
  JointJerkLimits(const Config& config, const RobotModel& robot);
  [[nodiscard]] bool supports(ControlOrder /*order*/) const override { return true; }
  /// Its bounds yield to every other constraint's (docs/motion.md): a joint that must brake harder than the jerk
  /// limit allows, to stay within its position, velocity or acceleration bounds, brakes.
  [[nodiscard]] bool yields_bounds() const override { return true; }
  [[nodiscard]] std::unique_ptr<PluginData> make_data() const override;

 private:
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const override;
  int n_;
};

}  // namespace redres

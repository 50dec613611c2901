#pragma once
/// @file
/// `min_acceleration_norm`: the smallest change of velocity (MAN; docs/motion.md).
/// - At the acceleration level (x = theta_ddot): x'x/2 + damping theta_dot'x, i.e. W += I and zeta += damping
///   theta_dot. With damping = 0 this is the research line's minimum-acceleration-norm scheme; damping > 0 (1/s) also
///   damps the self-motion velocity, which the pure scheme lets grow.
/// - At the velocity level (x = theta_dot): |x - theta_dot_prev|^2 / 2, i.e. W += I and zeta -= theta_dot_prev: the
///   command closest to the previous one (damping is not used there).

#include "redres/control/plugin.hpp"

namespace redres {

/// The configuration of `min_acceleration_norm`.
struct MinAccelerationNormConfig {
  double damping = 0.0;  //!< (1/s) >= 0: adds damping * theta_dot to zeta at the acceleration level

  static const Schema<MinAccelerationNormConfig>& schema();
};

/// The minimum-acceleration-norm objective (both levels).
class MinAccelerationNorm final : public Configured<Objective, MinAccelerationNormConfig> {
 public:
  static constexpr const char* kType = "min_acceleration_norm";
  MinAccelerationNorm(const Config& config, const RobotModel& robot);
  [[nodiscard]] bool supports(ControlOrder /*order*/) const override { return true; }

 private:
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const override;
};

}  // namespace redres

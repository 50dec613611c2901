#pragma once
/// @file
/// `push_rod`: the push-rod joint law of eq. 2,
///   theta_dot^{+-}(theta) = s sigma^{+-} sqrt(a^2 + b^2 + 2 a b sin(theta)) / (a b cos(theta)),
/// where a, b are the triangle edges of the joint (m), s the push-rod elongation per motor turn (m/rot) and
/// sigma^{+-} the motor's rotation-rate limits (rot/s). Undefined where cos(theta) = 0, which is rejected at load
/// when the joint range reaches it.

#include <limits>

#include "redres/model/velocity_limit.hpp"

namespace redres {

/// The configuration of `push_rod`. Every key is required.
struct PushRodLawConfig {
  double a = std::numeric_limits<double>::quiet_NaN();          //!< triangle edge a (m), > 0
  double b = std::numeric_limits<double>::quiet_NaN();          //!< triangle edge b (m), > 0
  double s = std::numeric_limits<double>::quiet_NaN();          //!< elongation per motor turn (m/rot), > 0
  double sigma_min = std::numeric_limits<double>::quiet_NaN();  //!< negative rotation-rate limit (rot/s), < 0
  double sigma_max = std::numeric_limits<double>::quiet_NaN();  //!< positive rotation-rate limit (rot/s), > 0

  static const Schema<PushRodLawConfig>& schema();
};

/// The push-rod law (eq. 2).
class PushRodLaw final : public Configured<VelocityLimitLaw, PushRodLawConfig> {
 public:
  static constexpr const char* kType = "push_rod";
  explicit PushRodLaw(const Config& config) : Configured(kType, config) {}
  [[nodiscard]] VelocityBounds bounds(double theta) const override;
  [[nodiscard]] std::string describe() const override;
  [[nodiscard]] std::optional<UndefinedAt> undefined_in(double lo, double hi) const override;
};

}  // namespace redres

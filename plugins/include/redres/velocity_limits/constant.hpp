#pragma once
/// @file
/// `constant`: theta_dot^- = lower, theta_dot^+ = upper, independent of theta.

#include <limits>

#include "redres/model/velocity_limit.hpp"

namespace redres {

/// The configuration of `constant`. Both keys are required.
struct ConstantLawConfig {
  double lower = std::numeric_limits<double>::quiet_NaN();  //!< lower limit (rad/s or m/s), < 0
  double upper = std::numeric_limits<double>::quiet_NaN();  //!< upper limit, > 0

  static const Schema<ConstantLawConfig>& schema();
};

/// Constant velocity limits.
class ConstantLaw final : public Configured<VelocityLimitLaw, ConstantLawConfig> {
 public:
  static constexpr const char* kType = "constant";
  explicit ConstantLaw(const Config& config) : Configured(kType, config) {}
  [[nodiscard]] VelocityBounds bounds(double /*theta*/) const override { return {config_.lower, config_.upper}; }
  [[nodiscard]] std::string describe() const override;
};

}  // namespace redres

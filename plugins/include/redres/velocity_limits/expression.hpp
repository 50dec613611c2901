#pragma once
/// @file
/// `expression`: the limits are formulas of the joint position `theta`, evaluated with muParser
/// (e.g. upper = "1.5 + 0.5*cos(theta)"). The constants `pi` and `e` are defined. Each law owns its parsers, so
/// evaluating one takes no lock; a law (like the robot holding it) is used by one thread at a time.

#include <string>

#include "redres/common/formula.hpp"
#include "redres/model/velocity_limit.hpp"

namespace redres {

/// The configuration of `expression`. Both keys are required.
struct ExpressionLawConfig {
  std::string lower{};  //!< formula of theta for the lower limit (rad/s or m/s)
  std::string upper{};  //!< formula of theta for the upper limit

  static const Schema<ExpressionLawConfig>& schema();
};

/// Limits given as formulas of theta.
class ExpressionLaw final : public Configured<VelocityLimitLaw, ExpressionLawConfig> {
 public:
  static constexpr const char* kType = "expression";
  explicit ExpressionLaw(const Config& config);
  [[nodiscard]] VelocityBounds bounds(double theta) const override {
    return {lower_.evaluate({theta}), upper_.evaluate({theta})};
  }
  [[nodiscard]] std::string describe() const override;

 private:
  Formula lower_;
  Formula upper_;
};

}  // namespace redres

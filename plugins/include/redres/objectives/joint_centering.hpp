#pragma once
/// @file
/// `joint_centering`: the repetitive-motion / joint-centring term, zeta += weight * lambda (theta - theta_ref),
/// the gradient of lambda |theta - theta_ref|^2 / 2. With min_velocity_norm it pulls the joints towards theta_ref.

#include <optional>

#include "redres/control/plugin.hpp"

namespace redres {

/// The configuration of `joint_centering`.
struct JointCenteringConfig {
  double lambda = 1.0;                  //!< gain (1/s), >= 0
  std::optional<PerJoint> theta_ref{};  //!< reference configuration; default: the robot's home

  static const Schema<JointCenteringConfig>& schema();
};

/// The joint-centring objective.
class JointCentering final : public Configured<Objective, JointCenteringConfig> {
 public:
  static constexpr const char* kType = "joint_centering";
  JointCentering(const Config& config, const RobotModel& robot);
  [[nodiscard]] std::optional<double> potential(const Context& ctx) const override;
  /// Its workspace: the step's linear term (a Workspace of one n-vector).
  [[nodiscard]] std::unique_ptr<PluginData> make_data() const override;

 private:
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const override;

  Eigen::VectorXd theta_ref_;
};

}  // namespace redres

#pragma once
/// @file
/// `joint_angle_margin`: joint position limits with a safety region, converted to velocity bounds (eq. 9 and the
/// text after it):
///   kappa ((theta^- + margin) - theta) <= x <= kappa ((theta^+ - margin) - theta).
/// Reports to the run summary: `max_safety_region_entry` (the deepest entry of any joint into its safety region,
/// rad or m) and `safety_margin` (the margin per joint).

#include "redres/control/plugin.hpp"
#include "redres/run/plugin_output.hpp"

namespace redres {

/// The configuration of `joint_angle_margin`.
struct JointAngleMarginConfig {
  double kappa = 4.0;        //!< gain (1/s) (the paper: 4)
  PerJoint margin = 0.0349;  //!< safety region (rad or m): one number or one per joint (the paper: 2 degrees)

  static const Schema<JointAngleMarginConfig>& schema();
};

/// The joint-angle safety-margin constraint.
class JointAngleMargin final : public Configured<Constraint, JointAngleMarginConfig>, public PluginOutput {
 public:
  static constexpr const char* kType = "joint_angle_margin";
  JointAngleMargin(const Config& config, const RobotModel& robot);
  /// Both levels: at the acceleration level the bounds hold the velocity after the step (Context::velocity_to_x).
  [[nodiscard]] bool supports(ControlOrder /*order*/) const override { return true; }
  /// The margin per joint.
  [[nodiscard]] const Eigen::VectorXd& margin() const noexcept { return margin_; }
  void summarise(const RobotModel& robot, const Trajectory& run, const PluginData* data,
                 std::vector<Metric>& out) const override;
  /// Its workspace: the bounds of a step (a Workspace of two n-vectors).
  [[nodiscard]] std::unique_ptr<PluginData> make_data() const override;

 private:
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const override;

  Eigen::VectorXd margin_;
};

}  // namespace redres

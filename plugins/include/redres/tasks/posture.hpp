#pragma once
/// @file
/// `posture`: the joints towards a configuration, weighted per joint. One row per joint of weight > 0:
///   sqrt(w_j) x_j = sqrt(w_j) K (theta_ref_j - theta_j),
/// so that in soft mode its least squares is sum_j w_j (x_j - K (theta_ref_j - theta_j))^2 / 2 (times the task's
/// weight). Records `<name>_error` (rad or m: |theta_ref - theta| over its joints); the summary has its maximum.

#include <optional>

#include "redres/control/task.hpp"
#include "redres/run/plugin_output.hpp"

namespace redres {

/// The configuration of `posture`.
struct PostureConfig {
  std::optional<PerJoint> target{};  //!< the configuration (default: the robot's home)
  PerJoint weights = 1.0;            //!< per joint, >= 0 (0 leaves the joint out)
  double gain = 1.0;                 //!< K (1/s)

  static const Schema<PostureConfig>& schema();
};

/// The posture task.
class Posture final : public Configured<Task, PostureConfig>, public PluginOutput {
 public:
  static constexpr const char* kType = "posture";
  Posture(const Config& config, const RobotModel& robot);

  [[nodiscard]] int rows() const override { return static_cast<int>(joints_.size()); }
  [[nodiscard]] std::string row_name(int r) const override;
  [[nodiscard]] std::string row_unit(int r) const override;
  void check_mode() const override;

  [[nodiscard]] std::vector<std::string> recorded_columns() const override;
  void record(const PluginData* data, double* values) const override;
  void summarise(const RobotModel& robot, const Trajectory& run, const PluginData* data,
                 std::vector<Metric>& out) const override;

 private:
  void compute(const Context& ctx, TaskData& data) const override;

  std::vector<int> joints_;  // the joints with weight > 0
  std::vector<std::string> names_;
  std::vector<bool> prismatic_;
  Eigen::VectorXd target_, scale_;  // target (n), sqrt(weight) per row
};

}  // namespace redres

#pragma once
/// @file
/// The outputs of a collision constraint (control/collision_rows.hpp): per step, the smallest distance of its pairs
/// and how many are within d_i (two trajectory columns that the plugin names); in the summary, the smallest
/// distance, the steps with active rows, FCL's failures, and the damper's d_s and d_i.

#include <string>
#include <vector>

#include "redres/control/collision_rows.hpp"
#include "redres/run/plugin_output.hpp"

namespace redres {

/// A collision constraint's part in the outputs; its data is a PairData.
class PairOutput : public PluginOutput {
 public:
  /// `self` is the constraint (for its name in the recorded run); `minimum` and `active` name the two columns
  /// (e.g. "min_obstacle_distance", "obstacle_rows_active").
  PairOutput(const Plugin& self, std::string minimum, std::string active);

  [[nodiscard]] std::vector<std::string> recorded_columns() const override { return {minimum_, active_}; }
  void record(const PluginData* data, double* values) const override;
  void summarise(const RobotModel& robot, const Trajectory& run, const PluginData* data,
                 std::vector<Metric>& out) const override;

 private:
  const Plugin* self_;
  std::string minimum_, active_;
};

}  // namespace redres

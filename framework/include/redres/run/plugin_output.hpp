#pragma once
/// @file
/// What a plugin adds to a run's outputs, apart from what it adds to the QP (control/plugin.hpp): columns of
/// trajectory.csv, figures of the run summary, and the obstacles the figures draw. A plugin that adds any derives
/// from PluginOutput besides Objective or Constraint; simulate() and summarise() find it with output_of() at setup.
///
///   class MyConstraint final : public Configured<Constraint, MyConfig>, public PluginOutput { ... };

#include <string>
#include <vector>

#include "redres/control/plugin.hpp"
#include "redres/model/collision.hpp"

namespace redres {

class Trajectory;

/// A named figure that a plugin adds to the run summary (one number, or one per joint).
struct Metric {
  std::string name;            //!< e.g. "max_safety_region_entry"
  std::vector<double> values;  //!< one value, or one per joint
  std::string unit;            //!< e.g. "rad"
  bool per_joint = false;      //!< values has one entry per joint (written as an array even for one joint)
};

/// A plugin's part in the run's outputs. `data` is the plugin's data of the controller that ran (nullptr when the
/// plugin makes none).
class PluginOutput {
 public:
  PluginOutput() = default;
  PluginOutput(const PluginOutput&) = delete;
  PluginOutput& operator=(const PluginOutput&) = delete;
  virtual ~PluginOutput() = default;

  /// Columns this plugin adds to trajectory.csv (default: none), e.g. "min_obstacle_distance". A name that another
  /// plugin took first is written "<plugin>.<column>" (own_column() finds it either way).
  [[nodiscard]] virtual std::vector<std::string> recorded_columns() const { return {}; }
  /// Writes this step's values of recorded_columns() (called after each contribution; allocation-free).
  virtual void record(const PluginData* data, double* values) const {
    (void)data;
    (void)values;
  }
  /// Figures this plugin adds to the run summary, computed from the recorded run (default: none).
  virtual void summarise(const RobotModel& robot, const Trajectory& run, const PluginData* data,
                         std::vector<Metric>& out) const {
    (void)robot;
    (void)run;
    (void)data;
    (void)out;
  }
  /// Obstacles this plugin keeps the robot away from, for summary.json and the figures: world-frame shapes at
  /// t = 0, each with its constant velocity if it moves (default: none).
  virtual void scene_obstacles(std::vector<ShapeSpec>& out) const { (void)out; }
};

/// The output part of `plugin`, or nullptr when it adds nothing to the outputs.
[[nodiscard]] inline const PluginOutput* output_of(const Plugin& plugin) {
  return dynamic_cast<const PluginOutput*>(&plugin);
}

}  // namespace redres

#pragma once
/// @file
/// What simulate() records of each step (private to run/): the row of trajectory.csv (the standard columns of
/// trajectory_column_groups(), then the plugins' outputs' own), and the run's log of outcomes (engines, relaxed
/// steps, failures, violated states).

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "redres/control/controller.hpp"
#include "redres/run/plants.hpp"
#include "redres/run/plugin_output.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"
#include "redres/run/trajectory_columns.hpp"

namespace redres {

/// A plugin that records columns: its output part, its data in the controller that runs, its first column.
struct Recorder {
  const PluginOutput* output = nullptr;
  const PluginData* data = nullptr;
  std::size_t first = 0;
  std::size_t objective = 0, constraint = 0;  //!< which plugin: objective k (constraint = kNoPlugin) or constraint k
  std::size_t task = static_cast<std::size_t>(-1);  //!< or task k (objective = constraint = kNoPlugin)
};
inline constexpr std::size_t kNoPlugin = static_cast<std::size_t>(-1);

/// The columns of a run's table, and where each part starts.
struct RunColumns {
  std::vector<std::string> names;   //!< every column, in order
  std::vector<Recorder> recorders;  //!< the plugins that record columns (their data not yet known)
  std::size_t levels_first = 0;     //!< the first level_<p>_status column (with several priority levels)
  std::size_t plant_first = 0;      //!< the first of the plant's own columns (names.size() when it has none)
};

/// The columns a run of `s` on the plant `plant` records: the standard ones, then the plugins' own (a name that an
/// earlier plugin took is "<plugin>.<column>"), then, for a scheme with several priority levels, level_<p>_status and
/// level_<p>_iterations per level (priority p), then the plant's own (PlantType::columns).
[[nodiscard]] RunColumns run_columns(const Scenario& s, const PlantType& plant);

/// Writes one row per step into a buffer that stays in the cache (the table streams it in). Allocation-free after
/// construction.
class RowRecorder {
 public:
  /// For a run of `s` by `ctrl` (its plugin data), with the columns run_columns() laid out.
  RowRecorder(const Scenario& s, const Controller& ctrl, RunColumns layout, std::size_t width);
  /// The row of step k at time t, after ctrl's step at theta gave `out` (width values).
  /// The row stays writable until the next write() (a plant's columns at its end).
  [[nodiscard]] double* write(int k, double t, const Eigen::VectorXd& theta, const StepOutput& out);

 private:
  // The norm of v's entries that are task rows; v(i) is reference row first + i (a subset leaves some rows free).
  template <class V>
  [[nodiscard]] double tracked_norm(const V& v, int first, int count) const {
    double sum = 0.0;
    for (int i = 0; i < count; ++i) {
      if (robot_->tracks(first + i)) sum += v(i) * v(i);
    }
    return std::sqrt(sum);
  }

  const RobotModel* robot_;
  const Controller* ctrl_;
  std::vector<Recorder> recorders_;
  const std::vector<TrajectoryColumnGroup>* groups_;
  std::vector<double> row_;
  std::size_t standard_columns_ = 0;
  int n_ = 0, m_ = 0, position_rows_ = 0;
  bool orientation_rows_ = false, spatial_orientation_ = false, all_position_rows_ = true, all_orientation_rows_ = true;
  Eigen::Vector3d wd_prev_ = Eigen::Vector3d::Zero(), w_prev_ = Eigen::Vector3d::Zero();
  bool acc_limits_ = false;       // the robot has acceleration limits: their columns are recorded
  std::size_t levels_first_ = 0;  // the first level_<p>_status column (a cascaded scheme)
};

/// The run's log of step outcomes, kept in its RunResult.
class StepLog {
 public:
  StepLog(RunResult& run, const Scheme& scheme, const SchemeData& data) : run_(&run), scheme_(&scheme), data_(&data) {}
  /// Notes a solve's outcome at t: the engine that ran, a relaxed step, a failure (the first one's text).
  void note(const StepOutput& o, double t);
  /// Counts a state that an active constraint finds violated (e.g. bodies that overlap) as a failed step, whatever
  /// the solver said (the first one's text).
  void check_violations(double t);

 private:
  RunResult* run_;
  const Scheme* scheme_;
  const SchemeData* data_;
  std::string_view last_engine_;  // the engine of the previous step (the names are static strings)
};

}  // namespace redres

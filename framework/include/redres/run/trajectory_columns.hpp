#pragma once
/// @file
/// The one list of trajectory.csv's standard columns: each group's name (or prefix), how many columns it has, its
/// unit, its meaning, and which value of the step fills it. simulate() fills the row in this order from it, the CSV
/// header and Python's column names come from the columns it names, and docs/output_formats.md shows its table
/// (trajectory_columns_markdown(), checked by a test). The plugins' own columns follow (run/plugin_output.hpp).

#include <string>
#include <string_view>
#include <vector>

#include "redres/model/robot.hpp"

namespace redres {

/// How many columns a group has.
enum class ColumnCount {
  kOne,                          //!< one column, named `name`
  kPerJoint,                     //!< n columns, `name`1 .. `name`n
  kPerReference,                 //!< one per reference row, `name`<row> (x, y, phi; x, y, z, wx, wy, wz)
  kIfOrientation,                //!< one column, only for tasks with orientation rows
  kPerJointIfAccelerationLimits  //!< n columns, only for robots with acceleration limits on every joint
};

/// Which value of a step fills a group.
enum class StepValue {
  kTime,
  kTheta,
  kThetaDot,
  kMergedLower,
  kMergedUpper,
  kDesired,
  kActual,
  kPositionError,
  kOrientationError,
  kManipulability,
  kIterations,
  kResidual,
  kLawLower,
  kLawUpper,
  kStatus,
  kThetaDdot,
  kAccelerationLower,
  kAccelerationUpper
};

/// One group of standard columns.
struct TrajectoryColumnGroup {
  std::string_view name;     //!< the column, or the prefix of the group's columns
  ColumnCount count;         //!< how many
  std::string_view unit;     //!< e.g. "rad", "m", or ""
  std::string_view meaning;  //!< one line
  StepValue value;           //!< what fills it
};

/// The standard groups, in the order of the columns.
[[nodiscard]] const std::vector<TrajectoryColumnGroup>& trajectory_column_groups();

/// The standard columns of a run of `robot`, in order.
[[nodiscard]] std::vector<std::string> standard_trajectory_columns(const RobotModel& robot);

/// The table of the groups as docs/output_formats.md shows it (column(s), count, unit, meaning).
[[nodiscard]] std::string trajectory_columns_markdown();

}  // namespace redres

#pragma once
/// @file
/// Writing a run: DIR/trajectory.csv (the recorded columns), DIR/frames.csv (where the arm's joint frames were) and
/// DIR/summary.json (the RunSummary), as described in docs/output_formats.md.

#include <cstddef>
#include <filesystem>
#include <string>

#include "redres/record.hpp"
#include "redres/run_summary.hpp"

namespace redres {

/// At most this many rows in frames.csv.
inline constexpr std::size_t kFramesMaxRows = 500;

/// The arm's joint frames over a recorded run, by forward kinematics of its `theta_<j>` columns, for drawing the
/// arm and its collision shapes (frames.csv): columns `t`, then per joint j = 1..n `joint_<j>_x`, `_y`, `_z` (the
/// origin of joint j's frame after its motion, in the world frame) and `joint_<j>_r11` .. `_r33` (its rotation,
/// row by row), then `ee_x`, `ee_y`, `ee_z` (the end effector). Every row of `run` when it has at most `max_rows`
/// (>= 2) rows; else every k-th row, k the smallest stride that keeps at most `max_rows` rows with the last row
/// always kept.
[[nodiscard]] Trajectory joint_frames(const RobotModel& robot, const Trajectory& run,
                                      std::size_t max_rows = kFramesMaxRows);

/// Writes DIR/trajectory.csv (the rows `record` keeps), DIR/frames.csv (joint_frames of `robot`, the run's robot)
/// and DIR/summary.json, creating DIR; std::runtime_error naming the file on failure. With record.none, only
/// summary.json, and a trajectory.csv or frames.csv left in DIR by an earlier run is removed (it would not belong
/// to this summary). Each file is written to a hidden temporary beside it and renamed into place, summary.json
/// last: a failed write leaves DIR as it was, and a reader never sees a half-written file or new tables beside an
/// old summary.
void write_run(const RobotModel& robot, const RunResult& run, const RunSummary& summary,
               const std::filesystem::path& dir, const RecordOptions& record = {});

}  // namespace redres

#pragma once
/// @file
/// Writing a run: DIR/trajectory.csv (the recorded columns), DIR/frames.csv (where the arm's joint frames were) and
/// DIR/summary.json (the RunSummary), as described in docs/output_formats.md.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "redres/common/output_file.hpp"
#include "redres/run/record.hpp"
#include "redres/run/run_summary.hpp"

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
///
/// Every file is a StagedFile (created exclusively, never through a symbolic link); a final name that is a link or
/// a directory is refused.
///
/// DIR/.redres-outputs (kOutputManifest) lists the files the last run wrote into DIR, one per line with the size,
/// modification time and inode each had when written. write_run removes every file an earlier run listed there and
/// this run does not write (the figures of an earlier `--plots`, the tables of a run with `record = "all"` before
/// one with `none`) while it is still that file (a regular file with the same stamp), and never touches anything
/// else: a user's own files in DIR, a file edited since, a name a planted manifest lists, a symbolic link. Returns the
/// names it wrote (the manifest's new content), to which a caller that adds files of its own (figures) appends with
/// add_to_output_manifest().
std::vector<std::string> write_run(const RobotModel& robot, const RunResult& run, const RunSummary& summary,
                                   const std::filesystem::path& dir, const RecordOptions& record = {});

/// The name of the manifest in a run's directory.
inline constexpr const char* kOutputManifest = ".redres-outputs";
/// The names in DIR's manifest; empty when there is none. Names with a '/' or starting with '.' are skipped (a
/// manifest never names anything outside DIR or hidden).
[[nodiscard]] std::vector<std::string> read_output_manifest(const std::filesystem::path& dir);
/// Adds names of files just written into DIR to its manifest, stamped as they are now (a name that is not a regular
/// file is skipped); std::runtime_error on failure.
void add_to_output_manifest(const std::filesystem::path& dir, const std::vector<std::string>& names);
/// Removes DIR/name when DIR's manifest lists it and it is unchanged since (see write_run); whether it did.
bool remove_earlier_output(const std::filesystem::path& dir, const std::string& name);

/// Checks, before a run starts, that `dir` can take its outputs: creates it when missing (with its parents) and
/// writes and removes a probe file. std::runtime_error "<what> DIR: ..." when DIR is a file, cannot be created, or
/// cannot be written, or when one of the names a run writes there (trajectory.csv, frames.csv, summary.json, the
/// manifest) is a symbolic link, a directory or another non-regular file, so that a long run is not lost to a bad
/// --out at its end.
void prepare_output_dir(const std::filesystem::path& dir, const std::string& what = "--out");

}  // namespace redres

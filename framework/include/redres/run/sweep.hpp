#pragma once
/// @file
/// Sweeps: one base scenario run over a grid of variations, each an ordinary run, summarised into one table
/// (sweep.csv, one row per variation). Described in a sweep file (docs/sweeps.md):
///
///   scenario = "../paper_r_tvcmm.toml"      # the base scenario, relative to this file
///   set = ["solver.engine=newton"]          # optional: overrides applied to every variation (as --set)
///   combine = "cross"                        # or "zip": the axes' values side by side (equal lengths)
///   [[vary]]                                 # an axis: any scenario key, with values or a range
///   key = "path.rotation_deg"
///   range = { start = 0, stop = 350, step = 10 }   # start, start + step, ..., up to stop (included)
///   [[vary]]
///   key = "objectives.1.p"
///   values = [0.0, 0.5, 1.0, 2.0, 4.0]
///   [theta0]                                 # optional: initial configurations, crossed with the grid
///   samples = 8                              # uniform within the limits (each joint's range shrunk by margin
///   seed = 1                                 #   on both sides), from this seed; or
///   margin = 0.1                             # list = [[...], [...]] (numbers or formulas)
///   [output]
///   record = "none"                          # with runs = true: the rows of each run's trajectory.csv
///   runs = false                             # also write each run's directory, runs/<index>/
///
/// Variation k of a crossed grid takes, for axis a (the first axis varies slowest), value
/// (k / prod of the later axes' sizes) mod size_a; theta0 variations are the outermost level. The table does
/// not depend on the number of threads nor on the order in which runs finish: rows are in variation order and
/// hold no timing.

#include <atomic>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/common/output_file.hpp"
#include "redres/config/config.hpp"
#include "redres/run/run_output.hpp"

namespace redres {

/// One axis of the grid: a scenario key and its values, as TOML text (what `--set key=value` takes).
struct SweepAxis {
  std::string key;
  std::vector<std::string> values;
};

/// A loaded sweep file.
struct SweepSpec {
  std::string name;                     //!< the sweep's name (default: the file's stem)
  std::string source;                   //!< the sweep file
  std::filesystem::path scenario;       //!< the base scenario file
  std::vector<std::string> set;         //!< overrides applied to every variation, before the axes'
  bool zip = false;                     //!< axes side by side instead of crossed
  std::vector<SweepAxis> axes;          //!< the grid
  std::vector<Eigen::VectorXd> theta0;  //!< initial configurations (empty: the scenario's own)
  RecordOptions record{1, true};        //!< rows of each run's trajectory.csv (with write_runs)
  bool write_runs = false;              //!< write runs/<index>/ for every variation
  /// Number of variations; SIZE_MAX when the product of the axes' sizes does not fit (load_sweep refuses any
  /// count above kMaxSweepVariations, so a loaded spec's count is exact).
  [[nodiscard]] std::size_t size() const;
};

/// One variation: its index and the overrides that make it from the base scenario.
struct Variation {
  std::size_t index = 0;
  std::vector<std::string> overrides;     //!< "key=value", in axis order, then theta0
  std::vector<std::string> values;        //!< each axis's value (TOML text)
  std::optional<Eigen::VectorXd> theta0;  //!< when the sweep varies theta0
};

/// The most variations a sweep file may describe.
inline constexpr std::size_t kMaxSweepVariations = 10000000;

/// What identifies a sweep, as 16 hex digits: a hash (FNV-1a, 64 bits) of what decides its rows, namely the name,
/// how the axes combine, each axis's key and values, the initial configurations, the overrides and the base
/// scenario file's text. Each shard's .json carries it, and `--merge` refuses tables whose identities differ.
[[nodiscard]] std::string sweep_identity(const SweepSpec& spec);

/// Loads a sweep file; the base scenario is loaded once to check it and to sample theta0 within its robot's
/// limits. Every problem is a ConfigError at file:line:col.
[[nodiscard]] SweepSpec load_sweep(const std::filesystem::path& file);

/// Every table of a sweep file with its keys (from the schemas the reader reads them with), for `redres keys` and
/// docs/sweeps.md.
[[nodiscard]] const std::vector<KeyTable>& sweep_key_tables();

/// Variation `index` (< spec.size()).
[[nodiscard]] Variation variation(const SweepSpec& spec, std::size_t index);

/// Which variations a run covers: those with index % count == shard.
struct SweepShard {
  std::size_t shard = 0;
  std::size_t count = 1;
};
/// "i/N" (0 <= i < N); std::invalid_argument otherwise.
[[nodiscard]] SweepShard parse_shard(const std::string& text);

/// The table of a sweep: column names and one row of cells per variation (empty cells where a variation has no
/// value for a column), in variation order.
struct SweepTable {
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
  /// Rows whose status is not "ok".
  [[nodiscard]] std::size_t failed() const;
};

/// Progress of a sweep: variations finished, and the total this run covers.
using SweepProgress = std::function<void(std::size_t done, std::size_t total)>;

/// Runs the variations of `shard` on `jobs` threads (0: one per core) and returns their table. A variation that
/// cannot be loaded or fails is a row with its status ("error" or "failed_steps") and diagnosis, never the end of
/// the sweep. With spec.write_runs, each run's directory is written under out_dir/runs/<index>/. `stop`, when given
/// and set (by a signal handler), ends the sweep early: the runs under way end after their current step (status
/// "interrupted"), the variations not yet started are left out of the table.
[[nodiscard]] SweepTable run_sweep(const SweepSpec& spec, const SweepShard& shard, unsigned jobs,
                                   const std::filesystem::path& out_dir, const SweepProgress& progress = {},
                                   const std::atomic<bool>* stop = nullptr);

/// Writes the table as CSV (RFC 4180 quoting) to `file` through a StagedFile (exclusive, never through a link; a
/// failed write leaves the old file); std::runtime_error naming it on failure.
void write_sweep_csv(const SweepTable& table, const std::filesystem::path& file);
/// The same into a staged file, finished but not installed: a caller installs it with the files that go with it.
void write_sweep_csv(const SweepTable& table, StagedFile& file);
/// Reads a sweep.csv back; ConfigError at file:line for malformed files.
[[nodiscard]] SweepTable read_sweep_csv(const std::filesystem::path& file);
/// Merges shard tables into one: the union of their columns (in order of first appearance), rows sorted by index.
/// A variation in two tables is a std::invalid_argument naming it.
[[nodiscard]] SweepTable merge_sweep_tables(const std::vector<SweepTable>& tables);

}  // namespace redres

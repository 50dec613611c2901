#pragma once
/// @file
/// Which rows of a run go into trajectory.csv (`--record`, `[output] record`): every row, every N-th (and the last),
/// or none. The summary always uses every step: it is computed from the run in memory.

#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>

#include "redres/config/toml_reader.hpp"

namespace redres {

/// The file the recorded tables go to (`--format`, `[output] format`): trajectory.csv and frames.csv, or one binary
/// trajectory.h5 holding both (HDF5, readable by h5py; docs/output_formats.md).
enum class TrajectoryFormat { kCsv, kHdf5 };
inline auto enum_names(TrajectoryFormat) {
  return std::array{std::pair{TrajectoryFormat::kCsv, std::string_view("csv")},
                    std::pair{TrajectoryFormat::kHdf5, std::string_view("hdf5")}};
}

/// The rows of trajectory.csv that a run writes.
struct RecordOptions {
  std::size_t every = 1;                             //!< keep rows 0, N, 2N, ... and the last
  bool none = false;                                 //!< write summary.json only (no trajectory, no frames)
  TrajectoryFormat format = TrajectoryFormat::kCsv;  //!< trajectory.csv + frames.csv, or trajectory.h5
};

/// Whether row r of a table of `rows` rows is recorded with RecordOptions::every = `every`: rows 0, N, 2N, ... and
/// the last (the one rule of trajectory.csv and trajectory.h5).
[[nodiscard]] inline bool recorded_row(std::size_t r, std::size_t rows, std::size_t every) {
  return every <= 1 || r % every == 0 || r + 1 == rows;
}

/// Parses "csv" or "hdf5"; std::invalid_argument saying what is expected otherwise.
[[nodiscard]] TrajectoryFormat parse_format(const std::string& text);

/// Parses "all", "none" or "every=N" (N >= 1); std::invalid_argument saying what is expected otherwise.
[[nodiscard]] RecordOptions parse_record(const std::string& text);

/// Reads `key` of `table` as parse_record does, `fallback` when the key is absent; a bad value is a ConfigError at
/// the key.
[[nodiscard]] RecordOptions read_record(const TableReader& table, std::string_view key, std::string_view fallback);

}  // namespace redres

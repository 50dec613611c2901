#pragma once
/// @file
/// Which rows of a run go into trajectory.csv (`--record`, `[output] record`): every row, every N-th (and the last),
/// or none. The summary always uses every step: it is computed from the run in memory.

#include <cstddef>
#include <string>
#include <string_view>

#include "redres/config/toml_reader.hpp"

namespace redres {

/// The rows of trajectory.csv that a run writes.
struct RecordOptions {
  std::size_t every = 1;  //!< keep rows 0, N, 2N, ... and the last
  bool none = false;      //!< write summary.json only (no trajectory.csv, no frames.csv)
};

/// Parses "all", "none" or "every=N" (N >= 1); std::invalid_argument saying what is expected otherwise.
[[nodiscard]] RecordOptions parse_record(const std::string& text);

/// Reads `key` of `table` as parse_record does, `fallback` when the key is absent; a bad value is a ConfigError at
/// the key.
[[nodiscard]] RecordOptions read_record(const TableReader& table, std::string_view key, std::string_view fallback);

}  // namespace redres

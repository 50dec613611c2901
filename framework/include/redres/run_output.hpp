#pragma once
/// @file
/// Writing a run: DIR/trajectory.csv (the recorded columns) and DIR/summary.json (the RunSummary), as described in
/// docs/output_formats.md.

#include <filesystem>

#include "redres/run_summary.hpp"

namespace redres {

/// Writes DIR/trajectory.csv and DIR/summary.json (creating DIR); std::runtime_error naming the file on failure.
void write_run(const RunResult& run, const RunSummary& summary, const std::filesystem::path& dir);

}  // namespace redres

#pragma once
// What `redres run --view` and `redres compare --view` share with `redres view` (view_command.cpp).

#include <filesystem>
#include <vector>

#include "redres/run/view.hpp"

namespace redres::cli {

/// Writes OUT_DIR/view.html for the runs in `dirs` (replacing only a view.html redres wrote there, unchanged since)
/// and lists it in OUT_DIR's manifest.
ViewReport write_run_view(const std::vector<std::filesystem::path>& dirs, const std::filesystem::path& out_dir,
                          const ViewOptions& options);

/// Prints where the page went (and any notes, to stderr).
void print_view_report(const ViewReport& report, bool quiet);

}  // namespace redres::cli

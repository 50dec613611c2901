#pragma once
/// @file
/// The comparison of runs, side by side: `redres compare`'s comparison.md and comparison.csv, and Python's
/// redres.Comparison, all from one list of columns over the summary's fields (run_summary.hpp).

#include <string>
#include <string_view>
#include <vector>

#include "redres/run/run_summary.hpp"

namespace redres {

/// One column: its heading in comparison.md, its key in comparison.csv (and in Python's table), the summary field
/// it shows, and the significant digits a number is printed with.
struct ComparisonColumn {
  std::string_view heading;  //!< e.g. "max position error (m)"
  std::string_view key;      //!< e.g. "max_position_error"
  std::string_view field;    //!< e.g. "max_position_error" (a key of summary_fields())
  int digits = 6;            //!< significant digits of a number
};

/// The columns, in order.
[[nodiscard]] const std::vector<ComparisonColumn>& comparison_columns();

/// One run's cells as text (numbers with their column's digits).
[[nodiscard]] std::vector<std::string> comparison_cells(const RunSummary& summary);
/// The heading rows of comparison.md (the headings and the separator).
[[nodiscard]] std::string comparison_markdown_heading();
/// One run's row of comparison.md ('|' in a cell escaped).
[[nodiscard]] std::string comparison_markdown_row(const RunSummary& summary);
/// The heading line of comparison.csv.
[[nodiscard]] std::string comparison_csv_heading();
/// One run's line of comparison.csv (cells quoted where CSV needs it).
[[nodiscard]] std::string comparison_csv_row(const RunSummary& summary);
/// The whole comparison.md of these runs.
[[nodiscard]] std::string comparison_markdown(const std::vector<const RunSummary*>& summaries);

}  // namespace redres

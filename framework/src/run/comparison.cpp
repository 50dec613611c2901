#include "redres/run/comparison.hpp"

#include <iomanip>
#include <sstream>
#include <type_traits>

#include "redres/common/csv.hpp"

namespace redres {

const std::vector<ComparisonColumn>& comparison_columns() {
  static const std::vector<ComparisonColumn> columns{
      {"scenario", "scenario", "name", 0},
      {"label", "label", "label", 0},
      {"engine", "engine", "solver.engine", 0},
      {"max position error (m)", "max_position_error", "max_position_error", 4},
      {"w(0)", "w_initial", "manipulability.initial", 6},
      {"w(T)", "w_final", "manipulability.final", 6},
      {"min w", "w_min", "manipulability.min", 6},
      {"mean w", "w_mean", "manipulability.mean", 6},
      {"norm theta_dot(0)", "initial_joint_velocity_norm", "initial_joint_velocity_norm", 4},
      {"norm theta_dot(T)", "final_joint_velocity_norm", "final_joint_velocity_norm", 4},
      {"mean iterations", "mean_iterations", "solver.mean_iterations", 4},
      {"failures", "failures", "solver.failures", 0},
      {"wall time (s)", "wall_time_s", "wall_time_s", 3},
  };
  return columns;
}

namespace {

std::string cell_text(const SummaryValue& value, int digits) {
  return std::visit(
      [digits](const auto& v) -> std::string {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::string>) {
          return v;
        } else if constexpr (std::is_same_v<T, long>) {
          return std::to_string(v);
        } else if constexpr (std::is_same_v<T, double>) {
          std::ostringstream s;
          s << std::setprecision(digits) << v;
          return s.str();
        } else if constexpr (std::is_same_v<T, bool>) {
          return v ? "true" : "false";
        } else {
          return "(" + std::to_string(v.size()) + " values)";
        }
      },
      value);
}

std::string markdown_line(const std::vector<std::string>& cells) {
  std::string line = "|";
  for (std::string c : cells) {
    for (std::size_t at = c.find('|'); at != std::string::npos; at = c.find('|', at + 2)) c.replace(at, 1, "\\|");
    line += " " + c + " |";
  }
  return line + "\n";
}

}  // namespace

std::vector<std::string> comparison_cells(const RunSummary& summary) {
  std::vector<std::string> cells;
  for (const ComparisonColumn& c : comparison_columns())
    cells.push_back(cell_text(summary_value(summary, c.field), c.digits));
  return cells;
}

std::string comparison_markdown_heading() {
  std::vector<std::string> headings;
  std::string rule = "|";
  for (const ComparisonColumn& c : comparison_columns()) {
    headings.emplace_back(c.heading);
    rule += "---|";
  }
  return markdown_line(headings) + rule + "\n";
}

std::string comparison_markdown_row(const RunSummary& summary) { return markdown_line(comparison_cells(summary)); }

std::string comparison_csv_heading() {
  std::string line;
  for (const ComparisonColumn& c : comparison_columns()) line += (line.empty() ? "" : ",") + std::string(c.key);
  return line + "\n";
}

std::string comparison_csv_row(const RunSummary& summary) {
  const std::vector<std::string> cells = comparison_cells(summary);
  std::string line;
  for (std::size_t c = 0; c < cells.size(); ++c) line += (c ? "," : "") + csv_field(cells[c]);
  return line + "\n";
}

std::string comparison_markdown(const std::vector<const RunSummary*>& summaries) {
  std::string md = comparison_markdown_heading();
  for (const RunSummary* s : summaries) md += comparison_markdown_row(*s);
  return md;
}

}  // namespace redres

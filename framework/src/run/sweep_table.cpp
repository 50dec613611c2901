// A sweep's table: made of its rows, written as and read from sweep.csv, and merged from shards' tables
// (redres/run/sweep.hpp).

#include "redres/run/sweep.hpp"

#include "run/sweep_cells.hpp"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <system_error>

#include "common/input_file.hpp"
#include "redres/common/csv.hpp"
#include "redres/common/error.hpp"
#include "redres/common/output_file.hpp"

namespace redres {

namespace sweep_detail {

SweepTable to_table(const std::vector<Cells>& rows) {
  SweepTable t;
  std::map<std::string, std::size_t> index;
  for (const Cells& row : rows) {
    for (const auto& [k, v] : row) {
      if (index.emplace(k, t.columns.size()).second) t.columns.push_back(k);
    }
  }
  for (const Cells& row : rows) {
    std::vector<std::string> cells(t.columns.size());
    for (const auto& [k, v] : row) cells[index.at(k)] = v;
    t.rows.push_back(std::move(cells));
  }
  return t;
}

}  // namespace sweep_detail

using sweep_detail::Cells;
using sweep_detail::to_table;

std::size_t SweepTable::failed() const {
  const auto it = std::find(columns.begin(), columns.end(), "status");
  if (it == columns.end()) return 0;
  const auto c = static_cast<std::size_t>(it - columns.begin());
  return static_cast<std::size_t>(
      std::count_if(rows.begin(), rows.end(), [c](const auto& row) { return row[c] != "ok"; }));
}

void write_sweep_csv(const SweepTable& table, StagedFile& file) {
  std::string text;
  const auto flush = [&] {
    file.write(text);
    text.clear();
  };
  for (std::size_t c = 0; c < table.columns.size(); ++c) (text += c ? "," : "") += csv_field(table.columns[c]);
  text += "\n";
  for (const auto& row : table.rows) {
    for (std::size_t c = 0; c < row.size(); ++c) (text += c ? "," : "") += csv_field(row[c]);
    text += "\n";
    if (text.size() >= (std::size_t{1} << 16)) flush();
  }
  flush();
  file.finish();
}

void write_sweep_csv(const SweepTable& table, const std::filesystem::path& file) {
  StagedFile out(file);
  write_sweep_csv(table, out);
  out.install();
}

SweepTable read_sweep_csv(const std::filesystem::path& file) {
  const std::string text = read_input_file(file, "sweep CSV file");
  std::vector<std::vector<std::string>> records(1);
  std::string cell;
  bool quoted_cell = false, at_start = true;
  std::uint32_t line = 1;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted_cell) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        quoted_cell = false;
      } else {
        if (c == '\n') ++line;
        cell += c;
      }
    } else if (c == '"' && at_start) {
      quoted_cell = true;
      at_start = false;
    } else if (c == ',') {
      records.back().push_back(std::move(cell));
      cell.clear();
      at_start = true;
    } else if (c == '\n') {
      records.back().push_back(std::move(cell));
      cell.clear();
      records.emplace_back();
      at_start = true;
      ++line;
    } else if (c != '\r') {
      cell += c;
      at_start = false;
    }
  }
  if (quoted_cell) throw ConfigError({file.string(), line, 0}, "a quoted cell is not closed");
  if (!cell.empty() || !records.back().empty()) records.back().push_back(std::move(cell));
  if (records.back().empty()) records.pop_back();
  if (records.empty()) throw ConfigError({file.string(), 1, 1}, "expected a header line");
  SweepTable t;
  t.columns = std::move(records.front());
  if (std::find(t.columns.begin(), t.columns.end(), "index") == t.columns.end()) {
    throw ConfigError({file.string(), 1, 1}, "expected a column 'index' (is this a sweep.csv?)");
  }
  for (std::size_t r = 1; r < records.size(); ++r) {
    if (records[r].size() != t.columns.size()) {
      throw ConfigError(
          {file.string(), static_cast<std::uint32_t>(r + 1), 1},
          "expected " + std::to_string(t.columns.size()) + " cells, got " + std::to_string(records[r].size()));
    }
    t.rows.push_back(std::move(records[r]));
  }
  return t;
}

SweepTable merge_sweep_tables(const std::vector<SweepTable>& tables) {
  std::vector<std::pair<std::size_t, Cells>> all;
  std::map<std::size_t, bool> seen;
  for (const SweepTable& t : tables) {
    const auto c_index =
        static_cast<std::size_t>(std::find(t.columns.begin(), t.columns.end(), "index") - t.columns.begin());
    REDRES_REQUIRE(c_index < t.columns.size(), "merge_sweep_tables", "every table has an 'index' column");
    for (const auto& row : t.rows) {
      std::size_t index = 0;
      const std::string& text = row[c_index];
      const auto res = std::from_chars(text.data(), text.data() + text.size(), index);
      if (res.ec != std::errc() || res.ptr != text.data() + text.size()) {
        throw std::invalid_argument("merge: a row has index '" + text + "', expected a number");
      }
      if (!seen.emplace(index, true).second) {
        throw std::invalid_argument("merge: variation " + text + " appears in two tables (a shard merged twice?)");
      }
      Cells cells;
      for (std::size_t c = 0; c < t.columns.size(); ++c) {
        if (!row[c].empty() || c == c_index) cells.emplace_back(t.columns[c], row[c]);
      }
      all.emplace_back(index, std::move(cells));
    }
  }
  // Columns in order of first appearance over the tables, rows by index.
  std::vector<Cells> header_order;
  for (const SweepTable& t : tables) {
    Cells names;
    for (const auto& c : t.columns) names.emplace_back(c, "");
    header_order.push_back(std::move(names));
  }
  SweepTable columns = to_table(header_order);
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  SweepTable out;
  out.columns = columns.columns;
  std::map<std::string, std::size_t> at;
  for (std::size_t c = 0; c < out.columns.size(); ++c) at[out.columns[c]] = c;
  for (const auto& [index, cells] : all) {
    std::vector<std::string> row(out.columns.size());
    for (const auto& [k, v] : cells) row[at.at(k)] = v;
    out.rows.push_back(std::move(row));
  }
  return out;
}

}  // namespace redres

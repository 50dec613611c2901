#include "redres/common/csv.hpp"

#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/input_file.hpp"
#include "redres/common/error.hpp"

namespace redres {

const std::vector<double>& CsvTable::column(const std::string& name) const {
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (names[k] == name) return columns[k];
  }
  throw std::out_of_range("CsvTable::column: no column '" + name + "' in " + path);
}

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

// Splits a line at commas, remembering each field's 1-based column.
std::vector<std::pair<std::string, std::uint32_t>> split(const std::string& line) {
  std::vector<std::pair<std::string, std::uint32_t>> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::string field = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const std::size_t lead = field.find_first_not_of(" \t");
    out.emplace_back(trim(field), static_cast<std::uint32_t>(start + (lead == std::string::npos ? 0 : lead) + 1));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

CsvTable read_csv(const std::filesystem::path& path, const std::vector<std::string>& required) {
  std::istringstream in(read_input_file(path, "CSV file"));
  CsvTable table;
  table.path = path.string();
  std::string line;
  std::uint32_t line_no = 0;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    const auto fields = split(line);
    if (!have_header) {
      for (const auto& [name, col] : fields) {
        if (name.empty()) throw ConfigError({table.path, line_no, col}, "expected a column name in the header");
        table.names.push_back(name);
      }
      table.columns.resize(table.names.size());
      for (const auto& r : required) {
        bool found = false;
        for (const auto& n : table.names) found = found || n == r;
        if (!found) throw ConfigError({table.path, line_no, 1}, "expected a header column named '" + r + "'");
      }
      have_header = true;
      continue;
    }
    if (fields.size() != table.names.size()) {
      throw ConfigError({table.path, line_no, 1}, "expected " + std::to_string(table.names.size()) +
                                                      " comma-separated values, got " + std::to_string(fields.size()));
    }
    for (std::size_t k = 0; k < fields.size(); ++k) {
      const auto& [text, col] = fields[k];
      double v = 0.0;
      const auto res = std::from_chars(text.data(), text.data() + text.size(), v);
      if (text.empty() || res.ec != std::errc() || res.ptr != text.data() + text.size() || !std::isfinite(v)) {
        throw ConfigError({table.path, line_no, col},
                          "column '" + table.names[k] + "': expected a finite number, got '" + text + "'");
      }
      table.columns[k].push_back(v);
    }
  }
  if (!have_header) throw ConfigError({table.path, 0, 0}, "expected a header line, but the file is empty");
  return table;
}

std::string csv_field(const std::string& cell) {
  if (cell.find_first_of(",\"\n\r") == std::string::npos) return cell;
  std::string out = "\"";
  for (const char c : cell) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

}  // namespace redres

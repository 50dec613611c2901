#pragma once
/// @file
/// Numeric CSV files (a header line of column names, then rows of finite numbers), as used for velocity-limit
/// tables and waypoint paths. Errors are ConfigErrors at "file:line:col".

#include <filesystem>
#include <string>
#include <vector>

namespace redres {

/// A numeric CSV file read into columns.
struct CsvTable {
  std::string path;                          //!< the file
  std::vector<std::string> names;            //!< header names
  std::vector<std::vector<double>> columns;  //!< one vector per header name

  /// The column called `name` (throws std::out_of_range if absent).
  [[nodiscard]] const std::vector<double>& column(const std::string& name) const;
};

/// Reads `path`; every name in `required` must be a header column. Blank lines and lines starting with '#' are
/// skipped.
[[nodiscard]] CsvTable read_csv(const std::filesystem::path& path, const std::vector<std::string>& required = {});

/// One field of a CSV line as RFC 4180 writes it: as is, or in double quotes (with each quote doubled) when it holds
/// a comma, a quote or a line break.
[[nodiscard]] std::string csv_field(const std::string& cell);

}  // namespace redres

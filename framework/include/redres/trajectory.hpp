#pragma once
/// @file
/// The recorded run: a table with one row per control step and named columns (docs/output_formats.md), filled by
/// the simulation loop. Storage is reserved before the loop, so recording allocates nothing per step.

#include <cstddef>
#include <string>
#include <vector>

namespace redres {

/// A row-major table of doubles with named columns.
class Trajectory {
 public:
  Trajectory() = default;
  /// Columns, and the number of rows to reserve.
  Trajectory(std::vector<std::string> columns, std::size_t reserve_rows);

  /// Appends a row of zeros and returns a pointer to its first value (width() values).
  double* append_row();
  /// Number of rows.
  [[nodiscard]] std::size_t size() const noexcept { return width_ == 0 ? 0 : values_.size() / width_; }
  /// Number of columns.
  [[nodiscard]] std::size_t width() const noexcept { return width_; }
  /// Column names.
  [[nodiscard]] const std::vector<std::string>& columns() const noexcept { return columns_; }
  /// Index of a column; std::out_of_range naming it when there is none.
  [[nodiscard]] std::size_t column(const std::string& name) const;
  /// Value at (row, column index).
  [[nodiscard]] double operator()(std::size_t row, std::size_t col) const { return values_[row * width_ + col]; }
  /// Value at (row, column name).
  [[nodiscard]] double at(std::size_t row, const std::string& name) const { return (*this)(row, column(name)); }
  /// One row (width() values).
  [[nodiscard]] const double* row(std::size_t r) const { return values_.data() + r * width_; }
  /// All values, row-major.
  [[nodiscard]] const std::vector<double>& values() const noexcept { return values_; }

 private:
  std::vector<std::string> columns_;
  std::size_t width_ = 0;
  std::vector<double> values_;
};

/// The column a plugin recorded as `column`: "<plugin>.<column>" when another plugin took the plain name first.
[[nodiscard]] std::size_t own_column(const Trajectory& run, const std::string& plugin, const std::string& column);

}  // namespace redres

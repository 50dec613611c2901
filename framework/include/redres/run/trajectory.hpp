#pragma once
/// @file
/// The recorded run: a table with one row per control step and named columns (docs/output_formats.md), filled by
/// the simulation loop. Storage is made (and touched) before the loop, so recording allocates nothing per step and
/// takes no page fault.

#include <algorithm>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace redres {

/// A row-major table of doubles with named columns.
class Trajectory {
 public:
  Trajectory() = default;
  /// Columns, and the number of rows to make room for (zeroed now, so that the loop touches no new page).
  Trajectory(std::vector<std::string> columns, std::size_t reserve_rows);
  /// Empties the table and gives it new columns, keeping its storage when that has room for reserve_rows rows: a
  /// repeated run (a sweep's worker, a benchmark) then pays for neither the allocation nor the first touch.
  void reset(std::vector<std::string> columns, std::size_t reserve_rows);

  /// Appends a row of zeros and returns a pointer to its first value (width() values). Allocates only when more
  /// rows are appended than were reserved.
  double* append_row() {
    if ((rows_ + 1) * width_ > values_.size()) grow();
    double* row = values_.data() + rows_ * width_;
    std::fill_n(row, width_, 0.0);
    ++rows_;
    return row;
  }
  /// Appends a copy of `values` (width() values) as a row. The copy bypasses the cache where the CPU allows
  /// (non-temporal stores): a long run's table is written once and not read until the run ends, so caching it would
  /// only cost a read of each line from memory and evict the loop's working set. Call publish() before another
  /// thread reads the table.
  void append_row(const double* values);
  /// Orders the rows appended by append_row(values) before every later store (a store fence), so that a thread that
  /// synchronises with this one afterwards sees them.
  static void publish() noexcept;
  /// Number of rows.
  [[nodiscard]] std::size_t size() const noexcept { return width_ == 0 ? 0 : rows_; }
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
  /// All values, row-major (size() x width()).
  [[nodiscard]] std::span<const double> values() const noexcept { return {values_.data(), rows_ * width_}; }

 private:
  std::vector<std::string> columns_;
  std::size_t width_ = 0;
  std::size_t rows_ = 0;
  std::vector<double> values_;  // room for values_.size() / width_ rows; the first rows_ are the table
  void grow();
};

/// The column a plugin recorded as `column`: "<plugin>.<column>" when another plugin took the plain name first.
[[nodiscard]] std::size_t own_column(const Trajectory& run, const std::string& plugin, const std::string& column);

}  // namespace redres

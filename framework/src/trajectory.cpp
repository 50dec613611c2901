#include "redres/trajectory.hpp"

#include <stdexcept>

namespace redres {

Trajectory::Trajectory(std::vector<std::string> columns, std::size_t reserve_rows)
    : columns_(std::move(columns)), width_(columns_.size()) {
  values_.reserve(reserve_rows * width_);
}

double* Trajectory::append_row() {
  values_.resize(values_.size() + width_, 0.0);
  return values_.data() + values_.size() - width_;
}

std::size_t Trajectory::column(const std::string& name) const {
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    if (columns_[c] == name) return c;
  }
  throw std::out_of_range("trajectory: no column '" + name + "'");
}

std::size_t own_column(const Trajectory& run, const std::string& plugin, const std::string& column) {
  const std::string prefixed = plugin + "." + column;
  for (std::size_t c = 0; c < run.columns().size(); ++c) {
    if (run.columns()[c] == prefixed) return c;
  }
  return run.column(column);
}

}  // namespace redres

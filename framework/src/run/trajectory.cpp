#include "redres/run/trajectory.hpp"

#include <cstdint>
#include <cstring>
#include <stdexcept>

#if defined(__x86_64__) && defined(__SSE2__)
#include <emmintrin.h>
#define REDRES_STREAMING_STORES 1
#endif

namespace redres {

Trajectory::Trajectory(std::vector<std::string> columns, std::size_t reserve_rows) {
  reset(std::move(columns), reserve_rows);
}

void Trajectory::reset(std::vector<std::string> columns, std::size_t reserve_rows) {
  columns_ = std::move(columns);
  width_ = columns_.size();
  rows_ = 0;
  if (values_.size() < reserve_rows * width_) values_.assign(reserve_rows * width_, 0.0);
}

void Trajectory::append_row(const double* values) {
  if ((rows_ + 1) * width_ > values_.size()) grow();
  double* row = values_.data() + rows_ * width_;
#ifdef REDRES_STREAMING_STORES
  std::size_t i = 0;
  const auto stream_one = [&] {
    long long bits = 0;
    std::memcpy(&bits, values + i, sizeof bits);
    _mm_stream_si64(reinterpret_cast<long long*>(row + i), bits);
    ++i;
  };
  if (width_ > 0 && reinterpret_cast<std::uintptr_t>(row) % 16 != 0) stream_one();  // to a 16-byte boundary
  for (; i + 2 <= width_; i += 2) _mm_stream_pd(row + i, _mm_loadu_pd(values + i));
  if (i < width_) stream_one();
#else
  std::copy_n(values, width_, row);
#endif
  ++rows_;
}

void Trajectory::publish() noexcept {
#ifdef REDRES_STREAMING_STORES
  _mm_sfence();
#endif
}

void Trajectory::grow() { values_.resize(std::max<std::size_t>(2 * values_.size(), (rows_ + 1) * width_), 0.0); }

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

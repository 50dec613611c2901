#pragma once
// What the sweep's files share (private to run/): a variation's row as named cells, the table made of such rows, and
// how a sweep writes a number.

#include <charconv>
#include <string>
#include <utility>
#include <vector>

#include "redres/run/sweep.hpp"

namespace redres::sweep_detail {

// The shortest text that reads back as `v` (std::to_chars): how a sweep writes a number.
inline std::string shortest(double v) {
  char buf[64];
  return std::string(buf, std::to_chars(buf, buf + sizeof(buf), v).ptr);
}

// A variation's cells, named.
using Cells = std::vector<std::pair<std::string, std::string>>;

// The table of rows of cells: a column for each name, in order of first appearance; a row's missing names are empty
// cells.
SweepTable to_table(const std::vector<Cells>& rows);

}  // namespace redres::sweep_detail

#pragma once
/// @file
/// Small text helpers for messages (private to the framework).

#include <cstdio>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "redres/common/error.hpp"

namespace redres {

/// "a, b, c" (or joined by `separator`).
[[nodiscard]] inline std::string join(const std::vector<std::string>& names, std::string_view separator = ", ") {
  std::string out;
  for (const auto& name : names) {
    if (!out.empty()) out += separator;
    out += name;
  }
  return out;
}

/// A number as messages print it: up to 10 significant digits.
[[nodiscard]] inline std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

/// An error code in hexadecimal, as EGL's and OpenGL's documentation write them ("0x3003").
[[nodiscard]] inline std::string hex(long value) {
  char text[32];
  std::snprintf(text, sizeof text, "0x%lx", static_cast<unsigned long>(value));
  return text;
}

/// Why `name` cannot name a plugin's or a task's output columns (trajectory.csv's header, whose separator is ',' and
/// whose quote is '"'; a control character or a line break would corrupt it too), or "" when it can.
[[nodiscard]] inline std::string column_name_problem(std::string_view name) {
  if (is_printable_name(name) && name.find_first_of(",\"") == std::string_view::npos) return {};
  std::string shown;  // printable() keeps line breaks and tabs for messages; a name shows them escaped
  for (const char c : printable(name))
    shown += c == '\n' ? std::string("\\n") : c == '\t' ? std::string("\\t") : std::string(1, c);
  return "expected a name of printable characters without ',' or '\"' (it names columns of trajectory.csv), got '" +
         shown + "'";
}

}  // namespace redres

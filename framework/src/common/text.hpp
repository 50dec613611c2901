#pragma once
/// @file
/// Small text helpers for messages (private to the framework).

#include <cstdio>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

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

}  // namespace redres

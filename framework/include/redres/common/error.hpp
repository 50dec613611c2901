#pragma once
/// @file
/// Error types. Bad configuration throws ConfigError; API misuse (wrong size, NaN input) throws
/// std::invalid_argument with the violated condition in the message. Numerical outcomes (not converged,
/// infeasible) are statuses in results, never exceptions.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace redres {

/// Whether `text` is well-formed UTF-8 (no overlong forms, surrogates or code points above U+10FFFF).
[[nodiscard]] bool is_utf8(std::string_view text) noexcept;

/// Whether `name` can name a joint, link or robot: non-empty UTF-8 without control characters (C0, DEL, C1), so
/// that it prints as itself and goes into JSON and CSV unchanged.
[[nodiscard]] bool is_printable_name(std::string_view name) noexcept;

/// `text` safe to print on a terminal: control characters other than newline and tab, and bytes that are not
/// UTF-8, become \xNN escapes (an escape sequence from a file never reaches the terminal raw).
[[nodiscard]] std::string printable(std::string_view text);

/// Where in a configuration file something was found. `line` and `column` are 1-based; 0 means unknown.
struct SourceLocation {
  std::string file;          //!< path of the file as it was opened
  std::uint32_t line = 0;    //!< 1-based line, 0 if unknown
  std::uint32_t column = 0;  //!< 1-based column, 0 if unknown

  /// "file:line:col" (or just "file" when the position is unknown).
  [[nodiscard]] std::string str() const;
};

/// A configuration error. what() starts with "file:line:col: " when the location is known, then says what was
/// expected.
class ConfigError : public std::runtime_error {
 public:
  ConfigError(SourceLocation where, const std::string& message);

  /// The location the error points at.
  [[nodiscard]] const SourceLocation& where() const noexcept { return where_; }
  /// The message without the location prefix.
  [[nodiscard]] const std::string& detail() const noexcept { return detail_; }

 private:
  SourceLocation where_;
  std::string detail_;
};

/// The sum of x * 0 over p[0, size): 0 while every entry is finite, NaN otherwise. The fast scan behind the
/// finiteness checks of the step (a search that names the entry runs only when it is not 0).
/// The terms go to four sums, so that no addition waits for the one before it (the scan is on the step's path); a NaN
/// in any sum makes the total NaN.
[[nodiscard]] inline double finite_probe(const double* p, std::ptrdiff_t size) {
  double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
  std::ptrdiff_t i = 0;
  for (; i + 4 <= size; i += 4) {
    a0 += p[i] * 0.0;
    a1 += p[i + 1] * 0.0;
    a2 += p[i + 2] * 0.0;
    a3 += p[i + 3] * 0.0;
  }
  for (; i < size; ++i) a0 += p[i] * 0.0;
  return (a0 + a1) + (a2 + a3);
}

/// Throws std::invalid_argument("<function>: <condition>"). Use through REDRES_REQUIRE.
[[noreturn]] void throw_invalid_argument(const char* function, const std::string& condition);

}  // namespace redres

/// API-misuse check: throws std::invalid_argument("<function>: <condition>") when `ok` is false. The message
/// expression is evaluated only on failure, so a passing check costs no allocation (real-time path).
#define REDRES_REQUIRE(ok, function, condition)                           \
  do {                                                                    \
    if (!(ok)) ::redres::throw_invalid_argument((function), (condition)); \
  } while (false)

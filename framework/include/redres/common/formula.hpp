#pragma once
/// @file
/// Formulas written by users in configuration files (velocity-limit laws, coefficient schedules, CLI values),
/// evaluated with muParser. Constants `pi` and `e` and muParser's functions (sin, cos, sqrt, min, max, ...) are
/// available.

#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

namespace redres {

/// A compiled formula of named variables. evaluate() is allocation-free and takes no lock: each Formula owns its
/// parser and variable slots, so one instance is evaluated by one thread at a time (every plugin or law instance
/// holds its own; a scenario loaded per thread shares nothing).
class Formula {
 public:
  /// Compiles `text`; throws std::invalid_argument with muParser's message if it does not parse or names an
  /// unknown variable.
  Formula(std::string text, std::vector<std::string> variables);
  ~Formula();
  Formula(Formula&&) noexcept;
  Formula& operator=(Formula&&) noexcept;
  Formula(const Formula&) = delete;
  Formula& operator=(const Formula&) = delete;

  /// Value at the given variable values, in the order of the constructor's `variables`. Returns NaN on a
  /// numerical error inside muParser.
  [[nodiscard]] double evaluate(std::initializer_list<double> values) const;
  /// The formula as written.
  [[nodiscard]] const std::string& text() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Evaluates a constant formula such as "pi/4" (no variables); throws std::invalid_argument on error.
[[nodiscard]] double evaluate_constant(const std::string& text);

}  // namespace redres

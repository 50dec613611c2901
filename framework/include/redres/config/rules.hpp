#pragma once
/// @file
/// The validity rules of Config fields (config.hpp): greater(), at_least(), less(), between() (every entry, for
/// arrays and per-joint values) and rule(), a rule of one's own.

#include <functional>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>

#include "redres/config/field_types.hpp"

namespace redres {

namespace detail {
// Applies a scalar test to a number, every entry of a vector or PerJoint, or the value of an optional.
template <class T, class F>
bool all_of(const T& v, const F& test) {
  if constexpr (std::is_arithmetic_v<T>) {
    return test(static_cast<double>(v));
  } else if constexpr (std::is_same_v<T, PerJoint>) {
    for (double x : v.values) {
      if (!test(x)) return false;
    }
    return true;
  } else {
    for (const auto& x : v) {
      if (!all_of(x, test)) return false;
    }
    return true;
  }
}
template <class T>
std::string number_text(double bound) {
  std::ostringstream s;
  s << bound;
  return s.str();
}
}  // namespace detail

/// value > bound (every entry, for arrays).
template <class T = double>
Rule<T> greater(double bound) {
  return {"> " + detail::number_text<T>(bound),
          [bound](const T& v) { return detail::all_of(v, [bound](double x) { return x > bound; }); }};
}
/// value >= bound.
template <class T = double>
Rule<T> at_least(double bound) {
  return {">= " + detail::number_text<T>(bound),
          [bound](const T& v) { return detail::all_of(v, [bound](double x) { return x >= bound; }); }};
}
/// value < bound.
template <class T = double>
Rule<T> less(double bound) {
  return {"< " + detail::number_text<T>(bound),
          [bound](const T& v) { return detail::all_of(v, [bound](double x) { return x < bound; }); }};
}
/// lo <= value <= hi.
template <class T = double>
Rule<T> between(double lo, double hi) {
  return {"in [" + detail::number_text<T>(lo) + ", " + detail::number_text<T>(hi) + "]",
          [lo, hi](const T& v) { return detail::all_of(v, [lo, hi](double x) { return x >= lo && x <= hi; }); }};
}
/// A rule of one's own.
template <class T>
Rule<T> rule(std::string text, std::function<bool(const T&)> ok) {
  return {std::move(text), std::move(ok)};
}

}  // namespace redres

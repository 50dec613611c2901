#pragma once
/// @file
/// A Config's schema (config.hpp): its fields, each built with field() (a member, its unit, help and rule, with the
/// physical range its unit implies) or entry() (a key with a reader of its own), and the rules across fields.

#include <cmath>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "redres/config/field_types.hpp"
#include "redres/config/toml_reader.hpp"
#include "redres/config/value_io.hpp"

namespace redres {

/// One key of a Config: how to read, write, describe and check it. Built with field().
template <class C>
struct Field {
  std::string name;
  std::string unit;
  std::string help;
  std::string rule;
  std::string type;
  Presence presence = Presence::kOptional;
  std::string group;
  std::function<void(const TableReader&, C&)> read;           //!< reads the key (which is present)
  std::function<void(const C&, toml::table&)> write;          //!< writes the member
  std::function<bool(const C&)> given;                        //!< member holds a value (required keys)
  std::function<std::optional<std::string>(const C&)> check;  //!< nullopt, or what was expected and got
  std::string default_text;  //!< the default as listed when it is not a member's value ("the file's stem")
  bool always = false;       //!< `read` runs when the key is absent too (it applies its own default): entry()

  /// Marks the key as required: no default; a Config built in C++ must set it.
  Field&& required() && {
    presence = Presence::kRequired;
    return std::move(*this);
  }
  /// The default as listed, when the member's value does not show it (a table's: "see [output]").
  Field&& listed_default(std::string text) && {
    default_text = std::move(text);
    return std::move(*this);
  }
  /// Puts the key in a group of alternatives; the schema's group rule says which combinations are valid.
  Field&& in_group(std::string g) && {
    presence = Presence::kGroup;
    group = std::move(g);
    return std::move(*this);
  }
};

/// A Config's field list and the rules that span several fields.
template <class C>
struct Schema {
  std::vector<Field<C>> fields = {};
  /// Rules across fields (e.g. "either file or the arrays"); throws FieldError. May be empty.
  std::function<void(const C&)> validate = {};
  /// Group name -> what to give, for the listing.
  std::vector<std::pair<std::string, std::string>> groups = {};
};

/// The physical range of a quantity by its unit: |value| <= the bound, for every number a key with that unit holds.
/// Values beyond it (a 1e200 m radius, a 1e308 1/s gain) are no robot's and overflow the step's arithmetic, so they
/// are refused at load. docs/scenario_format.md lists the bounds.
[[nodiscard]] inline std::optional<double> physical_bound(std::string_view unit) {
  if (unit == "m" || unit == "m/s" || unit == "rad or m" || unit == "rad/s or m/s" || unit == "m/rot") return 1e3;
  if (unit == "1/s" || unit == "rad" || unit == "deg" || unit == "rot/s" || unit == "rad/s^2 or m/s^2") return 1e6;
  if (unit == "rad/s^3 or m/s^3") return 1e9;
  // A limit law's numbers serve velocity, acceleration and jerk limits; the law's own reading checks the range of
  // the one it is (check_velocity_law), this bound only keeps the arithmetic finite.
  if (unit == "rad/s^k or m/s^k") return 1e9;
  return std::nullopt;
}

namespace detail {
// Whether every number in v (a number, an array, per-joint values, an optional of these) has |x| <= bound; other
// types hold no number and pass.
template <class T>
bool within(const T& v, double bound) {
  if constexpr (std::is_arithmetic_v<T>) {
    return !std::is_floating_point_v<T> || std::abs(static_cast<double>(v)) <= bound;
  } else if constexpr (std::is_same_v<T, PerJoint>) {
    return within(v.values, bound);
  } else if constexpr (std::is_convertible_v<const T&, std::string_view> || std::is_same_v<T, std::filesystem::path>) {
    return true;
  } else if constexpr (requires {
                         v.has_value();
                         *v;
                       }) {
    return !v.has_value() || within(*v, bound);
  } else if constexpr (requires {
                         v.begin();
                         v.end();
                       }) {
    for (const auto& x : v) {
      if (!within(x, bound)) return false;
    }
    return true;
  } else {
    return true;  // a type that holds no number (an enum, a path, a table of its own)
  }
}
}  // namespace detail

/// A field for member `member` of C. `rule` (optional) is a validity rule for the member's value; a unit with a
/// physical range (physical_bound) adds |value| <= that range.
template <class C, class T>
Field<C> field(std::string name, T C::*member, std::string unit, std::string help, Rule<T> rule = {}) {
  Field<C> f;
  f.name = std::move(name);
  f.unit = std::move(unit);
  f.help = std::move(help);
  f.rule = rule.text;
  f.type = config_io::type_name(static_cast<const T*>(nullptr));
  const std::string key = f.name;
  f.read = [member, key](const TableReader& r, C& c) { config_io::read(r, key, c.*member); };
  f.write = [member, key](const C& c, toml::table& t) { config_io::write(t, key, c.*member); };
  f.given = [member](const C& c) { return config_io::given(c.*member); };
  const std::optional<double> bound = physical_bound(f.unit);
  std::string range;
  if (bound) {
    std::ostringstream s;
    s << "|x| <= " << *bound << " " << f.unit;
    range = s.str();
    f.rule = f.rule.empty() ? range : f.rule + "; " + range;
  }
  if (rule.ok || bound) {
    f.check = [member, rule, bound, range](const C& c) -> std::optional<std::string> {
      if (!config_io::given(c.*member)) return std::nullopt;
      if (rule.ok && !rule.ok(c.*member)) return "expected " + rule.text + ", got " + detail::value_text(c.*member);
      if (bound && !detail::within(c.*member, *bound)) {
        return "expected " + range + " (a physical range), got " + detail::value_text(c.*member);
      }
      return std::nullopt;
    };
  }
  return f;
}

/// A key whose reader is its own: reading it needs more than its value (a key read before it, the robot, a
/// registry, another file), or it keeps messages of its own. `read` runs in the schema's order whether the key is
/// present or not, and applies the default itself; `default_text` says what that default is ("" and
/// .required(): the reader refuses a missing key). The key is listed, known and located like any field's.
template <class C>
Field<C> entry(std::string name, std::string type, std::string unit, std::string default_text, std::string help,
               std::function<void(const TableReader&, C&)> read, std::string rule = "") {
  Field<C> f;
  f.name = std::move(name);
  f.type = std::move(type);
  f.unit = std::move(unit);
  f.default_text = std::move(default_text);
  f.help = std::move(help);
  f.rule = std::move(rule);
  f.always = true;
  f.read = std::move(read);
  f.write = [](const C&, toml::table&) {};
  f.given = [](const C&) { return true; };
  return f;
}

}  // namespace redres

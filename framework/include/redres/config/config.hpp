#pragma once
/// @file
/// Typed plugin configurations. Every plugin kind (objective, constraint, velocity-limit law, path, engine) has a
/// plain `Config` struct whose default member initialisers are its defaults, and one field list (its Schema):
/// the TOML key, the member, the unit, a help line, whether it is required, and a validity rule. From that one
/// list the framework derives
///   - the strict TOML reading (unknown keys listed, every error at file:line:col),
///   - the write-back that makes a configuration survive a round trip,
///   - the listing in `redres plugins` (key, default, unit, required / optional / group, rule, help),
///   - the validation of a Config built in C++ (std::invalid_argument naming the key).
/// A default is therefore written once: in the struct.
///
///   struct MyConfig {
///     double gain = 2.0;                       // default
///     static const Schema<MyConfig>& schema(); // defined in the plugin's .cpp:
///   };
///   const Schema<MyConfig>& MyConfig::schema() {
///     static const Schema<MyConfig> s{{field("gain", &MyConfig::gain, "1/s", "feedback gain", greater(0.0))}};
///     return s;
///   }
///
/// Supported member types: double (a number or a constant formula such as "pi/2"), int, bool, std::string,
/// std::filesystem::path (relative to the file that names it), enums with an `enum_names()` overload found by
/// argument-dependent lookup, std::vector of double, int or std::string, std::array<double, N>, PerJoint (one
/// number or one per joint), std::optional of these, a struct S with its own schema (a sub-table), and
/// std::vector<S> (an array of inline tables). A key whose reading needs more than its own value is an entry().

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "redres/config/toml_reader.hpp"

namespace redres {

/// A configuration value that breaks a rule: the key and what was expected. Thrown by validation; the TOML path
/// turns it into a ConfigError at the key's file:line:col, the C++ path into std::invalid_argument.
class FieldError : public std::invalid_argument {
 public:
  /// what() is "[<who>: ]key '<key>': <message>".
  FieldError(std::string key, const std::string& message, const std::string& who = "")
      : std::invalid_argument((who.empty() ? "" : who + ": ") + "key '" + key + "': " + message),
        key_(std::move(key)),
        message_(message) {}
  /// The offending key ("" for the table as a whole).
  [[nodiscard]] const std::string& key() const noexcept { return key_; }
  /// What was expected, without the key.
  [[nodiscard]] const std::string& message() const noexcept { return message_; }

 private:
  std::string key_;
  std::string message_;
};

/// One number for every joint (or task row), or one number per joint. Resolved against the robot by the plugin.
struct PerJoint {
  std::vector<double> values;  //!< one entry (broadcast) or one per joint

  PerJoint() = default;
  PerJoint(double v) : values{v} {}  // NOLINT(google-explicit-constructor): `.margin = 0.02` reads naturally
  PerJoint(std::initializer_list<double> v) : values(v) {}
  explicit PerJoint(std::vector<double> v) : values(std::move(v)) {}

  /// The n values; throws FieldError(key) unless there are 1 or n entries.
  [[nodiscard]] Eigen::VectorXd resolve(int n, const std::string& key, const std::string& what = "joint") const;
};

/// How a key must be given.
enum class Presence {
  kOptional,  //!< has a default
  kRequired,  //!< must be given
  kGroup,     //!< one of a group of alternatives (the schema's group rule says which)
};

/// One key as listed by `redres plugins` and the docs.
struct KeyInfo {
  std::string name;          //!< TOML key
  std::string default_text;  //!< the default as TOML text ("" when required or in a group)
  std::string unit;          //!< e.g. "m", "1/s", "" when dimensionless
  std::string help;          //!< what it means
  std::string rule;          //!< validity rule, e.g. "> 0" ("" when any value of the type is valid)
  std::string type;          //!< "number", "integer", "string", "one of 'a', 'b'", ...
  Presence presence = Presence::kOptional;
  std::string group;  //!< the group's name when presence is kGroup
};

/// One table of an input file and its keys, as `redres keys` and the docs list them.
struct KeyTable {
  std::string file;   //!< "scenario", "robot" or "sweep"
  std::string table;  //!< "" for the file's top level, else e.g. "[output]" or "[[joints]]"
  std::string help;   //!< what the table is for
  std::vector<KeyInfo> keys;
};

/// A validity rule for a value of type T: `ok` returns true when valid; `text` says what is expected.
template <class T>
struct Rule {
  std::string text;                  //!< e.g. "> 0"
  std::function<bool(const T&)> ok;  //!< the test
};

// --- value codecs: reading one key, writing it back, describing its type ------------------------------------------

template <class C>
struct Schema;
template <class C>
void read_config(const TableReader& r, const Schema<C>& schema, C& c);
template <class C>
void write_config(const C& c, const Schema<C>& schema, toml::table& out);

namespace config_io {

void read(const TableReader& r, std::string_view key, double& v);
void read(const TableReader& r, std::string_view key, int& v);
void read(const TableReader& r, std::string_view key, bool& v);
void read(const TableReader& r, std::string_view key, std::string& v);
void read(const TableReader& r, std::string_view key, std::filesystem::path& v);
void read(const TableReader& r, std::string_view key, std::vector<double>& v);
void read(const TableReader& r, std::string_view key, std::vector<int>& v);
void read(const TableReader& r, std::string_view key, std::vector<std::string>& v);
void read(const TableReader& r, std::string_view key, PerJoint& v);

void write(toml::table& t, std::string_view key, double v);
void write(toml::table& t, std::string_view key, int v);
void write(toml::table& t, std::string_view key, bool v);
void write(toml::table& t, std::string_view key, const std::string& v);
void write(toml::table& t, std::string_view key, const std::filesystem::path& v);
void write(toml::table& t, std::string_view key, const std::vector<double>& v);
void write(toml::table& t, std::string_view key, const std::vector<int>& v);
void write(toml::table& t, std::string_view key, const std::vector<std::string>& v);
void write(toml::table& t, std::string_view key, const PerJoint& v);

inline const char* type_name(const double*) { return "number"; }
inline const char* type_name(const int*) { return "integer"; }
inline const char* type_name(const bool*) { return "boolean"; }
inline const char* type_name(const std::string*) { return "string"; }
inline const char* type_name(const std::filesystem::path*) { return "path"; }
inline const char* type_name(const std::vector<double>*) { return "array of numbers"; }
inline const char* type_name(const std::vector<int>*) { return "array of integers"; }
inline const char* type_name(const std::vector<std::string>*) { return "array of strings"; }
inline const char* type_name(const PerJoint*) { return "number or array of numbers"; }

/// Whether a value counts as given (required keys of a Config built in C++): finite, non-empty.
inline bool given(double v) { return std::isfinite(v); }
inline bool given(int) { return true; }
inline bool given(bool) { return true; }
inline bool given(const std::string& v) { return !v.empty(); }
inline bool given(const std::filesystem::path& v) { return !v.empty(); }
template <class T>
bool given(const std::vector<T>& v) {
  return !v.empty();
}
inline bool given(const PerJoint& v) { return !v.values.empty(); }

// Enums: an overload `enum_names(E)` found by ADL returns a container of {E, name} pairs.
template <class E, class = std::enable_if_t<std::is_enum_v<E>>>
std::string_view enum_name(E value) {
  for (const auto& [e, name] : enum_names(E{})) {
    if (e == value) return name;
  }
  return "?";
}
template <class E, class = std::enable_if_t<std::is_enum_v<E>>>
std::string enum_choices() {
  std::string out;
  for (const auto& [e, name] : enum_names(E{})) out += (out.empty() ? "'" : ", '") + std::string(name) + "'";
  return out;
}
template <class E, std::enable_if_t<std::is_enum_v<E>, int> = 0>
void read(const TableReader& r, std::string_view key, E& v) {
  const std::string s = r.string(key);
  for (const auto& [e, name] : enum_names(E{})) {
    if (name == s) {
      v = e;
      return;
    }
  }
  r.fail(key, "expected one of " + enum_choices<E>() + ", got '" + s + "'");
}
template <class E, std::enable_if_t<std::is_enum_v<E>, int> = 0>
void write(toml::table& t, std::string_view key, E v) {
  t.insert_or_assign(key, std::string(enum_name(v)));
}
template <class E, std::enable_if_t<std::is_enum_v<E>, int> = 0>
std::string type_name(const E*) {
  return "one of " + enum_choices<E>();
}
template <class E, std::enable_if_t<std::is_enum_v<E>, int> = 0>
bool given(E) {
  return true;
}

// Fixed-size arrays of numbers.
template <std::size_t N>
void read(const TableReader& r, std::string_view key, std::array<double, N>& v) {
  const std::vector<double> x = r.numbers(key, N);
  for (std::size_t i = 0; i < N; ++i) v[i] = x[i];
}
template <std::size_t N>
void write(toml::table& t, std::string_view key, const std::array<double, N>& v) {
  write(t, key, std::vector<double>(v.begin(), v.end()));
}
template <std::size_t N>
std::string type_name(const std::array<double, N>*) {
  return "array of " + std::to_string(N) + " numbers";
}
template <std::size_t N>
bool given(const std::array<double, N>& v) {
  for (double x : v) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

// Arrays of inline tables: std::vector<S> where S has `static const Schema<S>& schema()`.
template <class S>
using has_schema_t = decltype(S::schema());

template <class S, class = has_schema_t<S>>
void read(const TableReader& r, std::string_view key, std::vector<S>& v) {
  const toml::node* node = r.raw().get(key);
  (void)r.has(key);
  const toml::array* arr = node != nullptr ? node->as_array() : nullptr;
  if (arr == nullptr || arr->empty()) r.fail(key, "expected a non-empty array of inline tables");
  v.clear();
  std::size_t k = 0;
  for (const toml::node& el : *arr) {
    ++k;
    const toml::table* t = el.as_table();
    const std::string what = std::string(key) + "[" + std::to_string(k - 1) + "]";
    if (t == nullptr) {
      throw ConfigError(location_of(r.file(), el),
                        r.context() + ": " + what + ": expected an inline table, got " + describe_type(el));
    }
    const TableReader sub(r.file_ptr(), *t, r.context() + "." + what);
    S s{};
    read_config(sub, S::schema(), s);
    sub.finish();
    v.push_back(std::move(s));
  }
}
template <class S, class = has_schema_t<S>>
void write(toml::table& t, std::string_view key, const std::vector<S>& v) {
  toml::array arr;
  for (const S& s : v) {
    toml::table e;
    write_config(s, S::schema(), e);
    arr.push_back(std::move(e));
  }
  t.insert_or_assign(key, std::move(arr));
}
template <class S, class = has_schema_t<S>>
std::string type_name(const std::vector<S>*) {
  std::string keys;
  for (const auto& f : S::schema().fields) keys += (keys.empty() ? "" : ", ") + f.name;
  return "array of inline tables {" + keys + "}";
}

// A sub-table: a member S with its own schema, read from the table at `key` (a [key] table or an inline one). Its
// messages name the table by its key ("output: key 'plots': ...").
template <class S, class = has_schema_t<S>>
void read(const TableReader& r, std::string_view key, S& v) {
  const TableReader t = r.table(key);
  const TableReader sub(t.file_ptr(), t.raw(), std::string(key));
  read_config(sub, S::schema(), v);
  sub.finish();
}
template <class S, class = has_schema_t<S>>
void write(toml::table& t, std::string_view key, const S& v) {
  toml::table e;
  write_config(v, S::schema(), e);
  t.insert_or_assign(key, std::move(e));
}
template <class S, class = has_schema_t<S>>
std::string type_name(const S*) {
  std::string keys;
  for (const auto& f : S::schema().fields) keys += (keys.empty() ? "" : ", ") + f.name;
  return "table {" + keys + "}";
}
template <class S, class = has_schema_t<S>>
bool given(const S&) {
  return true;
}

// Optional values: absent when nullopt (nothing is written back).
template <class T>
void read(const TableReader& r, std::string_view key, std::optional<T>& v) {
  T x{};
  read(r, key, x);
  v = std::move(x);
}
template <class T>
void write(toml::table& t, std::string_view key, const std::optional<T>& v) {
  if (v) write(t, key, *v);
}
template <class T>
std::string type_name(const std::optional<T>*) {
  return type_name(static_cast<const T*>(nullptr));
}
template <class T>
bool given(const std::optional<T>& v) {
  return v.has_value();
}

}  // namespace config_io

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

/// A value as short TOML text for messages and listings: numbers with 15 significant digits ("0.05", not
/// "0.050000000000000003"), strings quoted, arrays and tables recursively.
[[nodiscard]] std::string node_text(const toml::node& node);

namespace detail {
template <class T>
std::string value_text(const T& v) {
  toml::table t;
  config_io::write(t, "v", v);
  const toml::node* n = t.get("v");
  return n == nullptr ? "(none)" : node_text(*n);
}
}  // namespace detail

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

// --- rules --------------------------------------------------------------------------------------------------------

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

// --- what the framework derives from a schema ---------------------------------------------------------------------

/// Checks a Config: required keys given, every field's rule, then the cross-field rules. Throws FieldError.
template <class C>
void check_config(const C& c, const Schema<C>& schema) {
  for (const auto& f : schema.fields) {
    if (f.presence == Presence::kRequired && !f.given(c)) throw FieldError(f.name, "is required but was not given");
    if (f.check) {
      if (auto why = f.check(c)) throw FieldError(f.name, *why);
    }
  }
  if (schema.validate) schema.validate(c);
}

/// Throws a FieldError from check_config() as a ConfigError at the key's location in `r`.
[[noreturn]] void rethrow_at(const TableReader& r, const FieldError& e);

/// Reads a Config from a table (starting from the defaults in `c`), marking every schema key as known; checks it.
/// Does not call finish(): the caller may read more keys from the same table first.
/// The keys are read in the schema's order, and each is checked as soon as it is read, so that a later key's reader
/// (an entry()) sees checked values.
template <class C>
void read_config(const TableReader& r, const Schema<C>& schema, C& c) {
  for (const auto& f : schema.fields) {
    if (f.always || r.has(f.name)) {
      f.read(r, c);
    } else if (f.presence == Presence::kRequired) {
      r.fail("missing required key '" + f.name + "'" + (f.help.empty() ? "" : " (" + f.help + ")"));
    }
    if (f.check) {
      if (auto why = f.check(c)) rethrow_at(r, FieldError(f.name, *why));
    }
  }
  try {
    if (schema.validate) schema.validate(c);
  } catch (const FieldError& e) {
    rethrow_at(r, e);
  }
}

/// Writes every field of a Config into `out`.
template <class C>
void write_config(const C& c, const Schema<C>& schema, toml::table& out) {
  for (const auto& f : schema.fields) f.write(c, out);
}

/// The keys of a schema, with defaults taken from a default-constructed Config.
template <class C>
std::vector<KeyInfo> describe_keys(const Schema<C>& schema, const C& defaults = C{}) {
  std::vector<KeyInfo> out;
  for (const auto& f : schema.fields) {
    KeyInfo k;
    k.name = f.name;
    k.unit = f.unit;
    k.help = f.help;
    k.rule = f.rule;
    k.type = f.type;
    k.presence = f.presence;
    k.group = f.group;
    if (f.presence == Presence::kOptional && !f.default_text.empty()) {
      k.default_text = f.default_text;
    } else if (f.presence == Presence::kOptional) {
      toml::table t;
      f.write(defaults, t);
      if (const toml::node* n = t.get(f.name)) {
        k.default_text = node_text(*n);
      } else {
        k.default_text = "(none)";
      }
    }
    out.push_back(std::move(k));
  }
  return out;
}

/// Throws std::invalid_argument("<who>: key 'k': ...") when a Config built in C++ breaks its schema.
template <class C>
void require_valid(const C& c, const Schema<C>& schema, const std::string& who) {
  try {
    check_config(c, schema);
  } catch (const FieldError& e) {
    throw FieldError(e.key(), e.message(), who);
  }
}

/// The base of a plugin with Config C: keeps the (checked) Config and writes it back. Use as
///   class MyObjective final : public Configured<Objective, MyConfig> { ... };
/// where the constructor passes the plugin's type name and config: Configured(kType, config).
template <class Base, class C>
class Configured : public Base {
 public:
  using Config = C;
  /// The configuration this instance was built with.
  [[nodiscard]] const Config& settings() const noexcept { return config_; }

 protected:
  Configured(std::string type, const Config& config) : Base(std::move(type)), config_(config) {
    require_valid(config_, Config::schema(), this->type());
  }
  Config config_;

 private:
  void write_config(toml::table& out) const final { redres::write_config(config_, Config::schema(), out); }
};

}  // namespace redres

#pragma once
/// @file
/// The value codecs of Config schemas (config.hpp): reading one key of a TOML table into a member of each supported
/// type, writing it back, naming its type for listings, and whether it counts as given; and a value as short TOML
/// text for messages.

#include <array>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "redres/config/field_types.hpp"
#include "redres/config/toml_reader.hpp"

namespace redres {

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

}  // namespace redres

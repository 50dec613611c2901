#include "redres/config/config.hpp"

#include <sstream>

namespace redres {

Eigen::VectorXd PerJoint::resolve(int n, const std::string& key, const std::string& what) const {
  if (values.size() == 1) return Eigen::VectorXd::Constant(n, values.front());
  if (static_cast<int>(values.size()) == n) return Eigen::Map<const Eigen::VectorXd>(values.data(), n);
  throw FieldError(key, "expected one number or one per " + what + " (" + std::to_string(n) + "), got " +
                            std::to_string(values.size()));
}

std::string node_text(const toml::node& node) {
  if (const auto* f = node.as_floating_point()) {
    std::ostringstream s;
    s.precision(15);
    s << f->get();
    std::string out = s.str();
    if (out.find_first_of(".eEn") == std::string::npos) out += ".0";  // stays a TOML float
    return out;
  }
  if (const auto* a = node.as_array()) {
    std::string out = "[";
    for (std::size_t i = 0; i < a->size(); ++i) out += (i ? ", " : "") + node_text(*a->get(i));
    return out + "]";
  }
  if (const auto* t = node.as_table()) {
    std::string out = "{";
    bool first = true;
    for (const auto& [k, v] : *t) {
      out += (first ? " " : ", ") + std::string(k.str()) + " = " + node_text(v);
      first = false;
    }
    return out + " }";
  }
  std::ostringstream s;
  node.visit([&s](const auto& x) { s << x; });
  return s.str();
}

void rethrow_at(const TableReader& r, const FieldError& e) {
  if (e.key().empty()) r.fail(e.message());
  r.fail(e.key(), e.message());
}

namespace config_io {

void read(const TableReader& r, std::string_view key, double& v) { v = r.number(key); }

void read(const TableReader& r, std::string_view key, int& v) {
  const std::int64_t x = r.integer(key);
  if (x < -2147483647LL || x > 2147483647LL) {
    r.fail(key, "expected an integer in [-2147483647, 2147483647], got " + std::to_string(x));
  }
  v = static_cast<int>(x);
}

void read(const TableReader& r, std::string_view key, bool& v) { v = r.boolean(key, v); }
void read(const TableReader& r, std::string_view key, std::string& v) { v = r.string(key); }
void read(const TableReader& r, std::string_view key, std::filesystem::path& v) { v = r.path(key); }
void read(const TableReader& r, std::string_view key, std::vector<double>& v) { v = r.numbers(key); }
void read(const TableReader& r, std::string_view key, std::vector<std::string>& v) { v = r.strings(key); }

void read(const TableReader& r, std::string_view key, std::vector<int>& v) {
  const toml::node* n = r.raw().get(key);
  (void)r.has(key);
  const toml::array* arr = n != nullptr ? n->as_array() : nullptr;
  if (arr == nullptr) r.fail(key, "expected an array of integers, got " + (n ? describe_type(*n) : "nothing"));
  v.clear();
  for (const auto& el : *arr) {
    const auto* i = el.as_integer();
    if (i == nullptr || i->get() < -2147483647LL || i->get() > 2147483647LL) {
      throw ConfigError(location_of(r.file(), el), r.context() + ": key '" + std::string(key) +
                                                       "': expected an array of integers, got " + describe_type(el) +
                                                       " in it");
    }
    v.push_back(static_cast<int>(i->get()));
  }
}

void read(const TableReader& r, std::string_view key, PerJoint& v) {
  const toml::node* n = r.raw().get(key);
  (void)r.has(key);
  if (n != nullptr && n->is_array()) {
    v.values = r.numbers(key);
    if (v.values.empty()) r.fail(key, "expected a number or a non-empty array of numbers");
  } else {
    v.values = {r.number(key)};
  }
}

void write(toml::table& t, std::string_view key, double v) { t.insert_or_assign(key, v); }
void write(toml::table& t, std::string_view key, int v) { t.insert_or_assign(key, static_cast<std::int64_t>(v)); }
void write(toml::table& t, std::string_view key, bool v) { t.insert_or_assign(key, v); }
void write(toml::table& t, std::string_view key, const std::string& v) { t.insert_or_assign(key, v); }
void write(toml::table& t, std::string_view key, const std::filesystem::path& v) {
  t.insert_or_assign(key, v.string());
}

void write(toml::table& t, std::string_view key, const std::vector<double>& v) {
  toml::array a;
  for (double x : v) a.push_back(x);
  t.insert_or_assign(key, std::move(a));
}

void write(toml::table& t, std::string_view key, const std::vector<int>& v) {
  toml::array a;
  for (int x : v) a.push_back(static_cast<std::int64_t>(x));
  t.insert_or_assign(key, std::move(a));
}

void write(toml::table& t, std::string_view key, const std::vector<std::string>& v) {
  toml::array a;
  for (const auto& x : v) a.push_back(x);
  t.insert_or_assign(key, std::move(a));
}

void write(toml::table& t, std::string_view key, const PerJoint& v) {
  if (v.values.size() == 1) {
    t.insert_or_assign(key, v.values.front());
  } else {
    write(t, key, v.values);
  }
}

}  // namespace config_io
}  // namespace redres

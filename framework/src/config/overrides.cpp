#include "config/overrides.hpp"

#include <charconv>
#include <sstream>

#include "redres/common/error.hpp"

namespace redres {

namespace {

[[noreturn]] void bad_override(const std::string& text, const std::string& why) {
  throw ConfigError({"--set " + text, 0, 0}, why);
}

}  // namespace

void apply_override(toml::table& root, const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) bad_override(text, "expected key.path=value");
  const std::string key = text.substr(0, eq);
  std::string value = text.substr(eq + 1);
  while (!value.empty() && (value.back() == ' ' || value.back() == '\t')) value.pop_back();
  if (value.find_first_of("\n\r") != std::string::npos) bad_override(text, "expected the value on one line");
  // A number too large for its type is out of range, not a string (TOML refuses it, and a bare word is a string).
  {
    const char* first = value.data();
    const char* last = first + value.size();
    if (first != last && (*first == '+' || *first == '-')) ++first;
    double d = 0.0;
    const auto r = std::from_chars(first, last, d);
    if (r.ec == std::errc::result_out_of_range && r.ptr == last) {
      bad_override(text, "'" + value + "' is out of range for a number (a double lies within +-1.8e308)");
    }
  }
  // The value as TOML (numbers, booleans, arrays, quoted strings); a bare word is a string.
  toml::table holder;
  try {
    holder = toml::parse("v = " + value, "--set " + key);
    // One value and nothing after it (a comment or a second key would be dropped without a word).
    // TOML++ counts columns in code points: the value ends at column 5 + its code points.
    std::size_t code_points = 0;
    for (const char ch : value) code_points += (static_cast<unsigned char>(ch) & 0xC0) != 0x80;
    const toml::node* parsed = holder.get("v");
    if (holder.size() != 1 || parsed == nullptr ||
        parsed->source().end.column != static_cast<toml::source_index>(5 + code_points)) {
      bad_override(text, "expected one value after '=', got extra text in '" + value + "'");
    }
  } catch (const toml::parse_error& e) {
    // A value that starts as a string, an array or an inline table was meant as TOML: say what is wrong with it.
    if (!value.empty() && std::string_view("\"'[{").find(value.front()) != std::string_view::npos) {
      bad_override(text, "'" + value + "' is not a TOML value: " + std::string(e.description()));
    }
    std::string quoted = "\"";
    for (char ch : value) {
      if (ch == '"' || ch == '\\') quoted += '\\';
      quoted += ch;
    }
    holder = toml::parse("v = " + quoted + "\"", "--set " + key);
  }
  toml::node& v = *holder.get("v");
  std::vector<std::string> parts;
  std::stringstream in(key);
  for (std::string p; std::getline(in, p, '.');) {
    if (p.empty()) bad_override(text, "empty component in key '" + key + "'");
    parts.push_back(p);
  }
  toml::node* cur = &root;
  for (std::size_t i = 0; i + 1 <= parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool last = i + 1 == parts.size();
    if (auto* t = cur->as_table()) {
      if (last) {
        t->insert_or_assign(part, std::move(v));
        return;
      }
      if (t->get(part) == nullptr) t->insert(part, toml::table{});
      cur = t->get(part);
    } else if (auto* a = cur->as_array()) {
      // An index is digits only: "1xyz" and "1e0" are not indices.
      if (part.size() > 9 || part.find_first_not_of("0123456789") != std::string::npos) {
        bad_override(text,
                     "'" + part + "' is not an index into the array '" + parts[i - 1] + "' (expected digits, 0-based)");
      }
      const std::size_t idx = std::stoul(part);
      if (idx >= a->size()) {
        bad_override(text, "'" + parts[i - 1] + "' has " + std::to_string(a->size()) + " entries; index " + part +
                               " is out of range (indices start at 0)");
      }
      if (last) {
        a->replace(a->begin() + static_cast<std::ptrdiff_t>(idx), std::move(v));
        return;
      }
      cur = a->get(idx);
    } else {
      bad_override(text, "'" + parts[i - 1] + "' is a value, not a table");
    }
  }
}

void apply_overrides(toml::table& root, const std::vector<std::string>& overrides) {
  for (const auto& o : overrides) apply_override(root, o);
}

}  // namespace redres

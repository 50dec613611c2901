#include "redres/overrides.hpp"

#include <sstream>

#include "redres/error.hpp"

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
  const std::string value = text.substr(eq + 1);
  // The value as TOML (numbers, booleans, arrays, quoted strings); a bare word is a string.
  toml::table holder;
  try {
    holder = toml::parse("v = " + value, "--set " + key);
  } catch (const toml::parse_error&) {
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
      std::size_t idx = 0;
      try {
        idx = std::stoul(part);
      } catch (const std::exception&) {
        bad_override(text, "'" + part + "' is not an index into the array '" + parts[i - 1] + "'");
      }
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

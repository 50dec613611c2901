#include "redres/config/toml_reader.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

#include "common/input_file.hpp"
#include "redres/common/formula.hpp"

namespace redres {

namespace {

std::string join(const std::set<std::string, std::less<>>& names) {
  std::string out;
  for (const auto& n : names) {
    if (!out.empty()) out += ", ";
    out += n;
  }
  return out.empty() ? "(none)" : out;
}

std::string quoted_list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) {
    if (!out.empty()) out += ", ";
    out += "'" + n + "'";
  }
  return out;
}

// TOML++ parses dotted keys, table headers and nested arrays and inline tables by recursion: a key of 40,000 parts
// overflows the stack. This scan, run before it, bounds them: it follows the text's strings and comments, counts the
// parts of each run of key-like tokens joined by dots (a float or a time has one dot), and the depth of the brackets
// and braces outside strings.
constexpr int kMaxKeyParts = 64;
constexpr int kMaxNesting = 64;

void check_shape(std::string_view text, const std::filesystem::path& path) {
  enum class State { kNormal, kComment, kBasic, kLiteral, kMultiBasic, kMultiLiteral };
  State state = State::kNormal;
  std::uint32_t line = 1;
  std::size_t line_start = 0;
  int dots = 0;         // dots in the current run of joined tokens
  bool token = false;   // the last significant character ended a key-like token
  bool joined = false;  // a dot follows that token
  int depth = 0;
  const auto fail = [&](std::size_t at, const std::string& message) {
    throw ConfigError({path.string(), line, static_cast<std::uint32_t>(at - line_start + 1)}, message);
  };
  const auto starts = [&](std::size_t i, std::string_view s) { return text.substr(i, s.size()) == s; };
  // A new token continues the run when a dot joins it to the last one, else starts a run.
  const auto begin_token = [&] {
    if (!joined) dots = 0;
    joined = false;
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      line_start = i + 1;
    }
    switch (state) {
      case State::kComment:
        if (c == '\n') state = State::kNormal;
        continue;
      case State::kBasic:
        if (c == '\\') {
          ++i;
        } else if (c == '"' || c == '\n') {
          state = State::kNormal;
          token = true;
        }
        continue;
      case State::kLiteral:
        if (c == '\'' || c == '\n') {
          state = State::kNormal;
          token = true;
        }
        continue;
      case State::kMultiBasic:
        if (c == '\\') {
          if (i + 1 < text.size() && text[i + 1] == '\n') continue;  // a line-ending backslash: the newline counts
          ++i;
        } else if (starts(i, "\"\"\"")) {
          i += 2;
          for (int extra = 0; extra < 2 && i + 1 < text.size() && text[i + 1] == '"'; ++extra) ++i;  // """a""""
          state = State::kNormal;
          token = false;
        }
        continue;
      case State::kMultiLiteral:
        if (starts(i, "'''")) {
          i += 2;
          for (int extra = 0; extra < 2 && i + 1 < text.size() && text[i + 1] == '\''; ++extra) ++i;
          state = State::kNormal;
          token = false;
        }
        continue;
      case State::kNormal: break;
    }
    const bool bare =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    if (bare) {
      if (!token || joined) begin_token();
      token = true;
      continue;
    }
    if (c == ' ' || c == '\t' || c == '\r') continue;  // TOML allows "a . b"
    if (c == '.') {
      if (token && !joined) {
        joined = true;
        if (++dots >= kMaxKeyParts) {
          fail(i, "a dotted key or table header with more than " + std::to_string(kMaxKeyParts) +
                      " parts (the most this reader accepts)");
        }
      } else {
        dots = 0;
        joined = false;
      }
      token = false;
      continue;
    }
    if (c == '"' || c == '\'') {
      begin_token();
      const bool triple = starts(i, c == '"' ? "\"\"\"" : "'''");
      state =
          c == '"' ? (triple ? State::kMultiBasic : State::kBasic) : (triple ? State::kMultiLiteral : State::kLiteral);
      if (triple) i += 2;
      continue;
    }
    // Anything else ends the run.
    dots = 0;
    joined = false;
    token = false;
    if (c == '#') {
      state = State::kComment;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxNesting) {
        fail(i, "arrays, inline tables and table headers nested more than " + std::to_string(kMaxNesting) +
                    " deep (the most this reader accepts)");
      }
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
}

std::shared_ptr<TomlFile> parse(std::string_view text, const std::filesystem::path& path) {
  check_shape(text, path);
  auto file = std::make_shared<TomlFile>();
  file->path = path;
  try {
    file->root = toml::parse(text, path.string());
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw ConfigError({path.string(), b.line, b.column},
                      std::string("TOML syntax error: ") + std::string(e.description()));
  }
  return file;
}

}  // namespace

std::shared_ptr<TomlFile> parse_toml_file(const std::filesystem::path& path) {
  return parse(read_input_file(path, "TOML file"), path);
}

std::shared_ptr<TomlFile> parse_toml_string(std::string_view text, const std::string& name) {
  return parse(text, name);
}

SourceLocation location_of(const TomlFile& file, const toml::node& node) {
  const auto& src = node.source();
  // A value spliced in from elsewhere (e.g. a --set override) keeps the name of where it came from.
  const std::string where = src.path && !src.path->empty() ? *src.path : file.path.string();
  return {where, src.begin.line, src.begin.column};
}

std::string toml_value_text(const toml::node& node) {
  if (const auto* f = node.as_floating_point()) {
    char buf[64];
    std::string text(buf, std::to_chars(buf, buf + sizeof(buf), f->get()).ptr);
    if (text.find_first_of(".eni") == std::string::npos) text += ".0";
    return text;
  }
  toml::table t;
  t.insert("v", node);
  std::ostringstream s;
  s << t;
  const std::string text = s.str();
  const auto eq = text.find("= ");
  std::string out = eq == std::string::npos ? text : text.substr(eq + 2);
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

std::string describe_type(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    default: return "nothing";
  }
}

TableReader::TableReader(std::shared_ptr<const TomlFile> file, const toml::table& table, std::string context)
    : file_(std::move(file)),
      table_(&table),
      context_(std::move(context)),
      asked_(std::make_shared<std::set<std::string, std::less<>>>()) {}

TableReader TableReader::root(std::shared_ptr<const TomlFile> file, std::string context) {
  const toml::table& t = file->root;
  return TableReader(std::move(file), t, std::move(context));
}

std::string TableReader::prefix() const { return context_.empty() ? std::string() : context_ + ": "; }

const toml::node* TableReader::find(std::string_view key) const {
  asked_->emplace(key);
  return table_->get(key);
}

const toml::node& TableReader::need(std::string_view key) const {
  const toml::node* n = find(key);
  if (n == nullptr) fail("missing required key '" + std::string(key) + "'");
  return *n;
}

SourceLocation TableReader::location() const { return location_of(*file_, *table_); }

SourceLocation TableReader::location(std::string_view key) const {
  const toml::node* n = table_->get(key);
  return n != nullptr ? location_of(*file_, *n) : location();
}

void TableReader::fail(std::string_view key, const std::string& message) const {
  throw ConfigError(location(key), prefix() + "key '" + std::string(key) + "': " + message);
}

void TableReader::fail(const std::string& message) const { throw ConfigError(location(), prefix() + message); }

bool TableReader::has(std::string_view key) const { return find(key) != nullptr; }

bool read_number_or_formula(const toml::node& node, double& v) {
  if (const auto* i = node.as_integer()) {
    v = static_cast<double>(i->get());
  } else if (const auto* f = node.as_floating_point()) {
    v = f->get();
  } else if (const auto* text = node.as_string()) {
    v = evaluate_constant(text->get());
  } else {
    return false;
  }
  return true;
}

double TableReader::to_number(std::string_view key, const toml::node& node, const std::string& what) const {
  double v = 0.0;
  bool number = false;
  try {
    // Every number in a file may be a constant formula, as theta0 entries are: "pi/2", "-3*pi/4", "0.25*2".
    number = read_number_or_formula(node, v);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(location_of(*file_, node), prefix() + "key '" + std::string(key) + "': expected " + what +
                                                     " or a constant formula: " + e.what());
  }
  if (!number) {
    throw ConfigError(location_of(*file_, node),
                      prefix() + "key '" + std::string(key) + "': expected " + what + ", got " + describe_type(node));
  }
  if (!std::isfinite(v)) {
    std::ostringstream s;
    s << v;
    throw ConfigError(location_of(*file_, node),
                      prefix() + "key '" + std::string(key) + "': expected a finite number, got " + s.str());
  }
  return v;
}

double TableReader::number(std::string_view key) const { return to_number(key, need(key), "a number"); }

double TableReader::number(std::string_view key, double fallback) const {
  const toml::node* n = find(key);
  return n == nullptr ? fallback : to_number(key, *n, "a number");
}

std::int64_t TableReader::integer(std::string_view key) const {
  const toml::node& n = need(key);
  if (const auto* i = n.as_integer()) return i->get();
  fail(key, "expected an integer, got " + describe_type(n));
}

std::int64_t TableReader::integer(std::string_view key, std::int64_t fallback) const {
  return has(key) ? integer(key) : fallback;
}

std::string TableReader::string(std::string_view key) const {
  const toml::node& n = need(key);
  if (const auto* s = n.as_string()) return s->get();
  fail(key, "expected a string, got " + describe_type(n));
}

std::string TableReader::string(std::string_view key, std::string_view fallback) const {
  return has(key) ? string(key) : std::string(fallback);
}

bool TableReader::boolean(std::string_view key, bool fallback) const {
  const toml::node* n = find(key);
  if (n == nullptr) return fallback;
  if (const auto* b = n->as_boolean()) return b->get();
  fail(key, "expected a boolean (true or false), got " + describe_type(*n));
}

std::vector<double> TableReader::numbers(std::string_view key, std::optional<std::size_t> size) const {
  const toml::node& n = need(key);
  const auto* arr = n.as_array();
  const std::string what = size ? "an array of " + std::to_string(*size) + " numbers" : "an array of numbers";
  if (arr == nullptr) fail(key, "expected " + what + ", got " + describe_type(n));
  if (size && arr->size() != *size) {
    fail(key, "expected " + what + ", got " + std::to_string(arr->size()) + " element(s)");
  }
  std::vector<double> out;
  out.reserve(arr->size());
  for (const auto& el : *arr) out.push_back(to_number(key, el, "a number in " + what));
  return out;
}

std::vector<std::string> TableReader::strings(std::string_view key) const {
  const toml::node& n = need(key);
  const auto* arr = n.as_array();
  if (arr == nullptr) fail(key, "expected an array of strings, got " + describe_type(n));
  std::vector<std::string> out;
  for (const auto& el : *arr) {
    const auto* s = el.as_string();
    if (s == nullptr) {
      throw ConfigError(location_of(*file_, el), prefix() + "key '" + std::string(key) +
                                                     "': expected an array of strings, got " + describe_type(el) +
                                                     " in it");
    }
    out.push_back(s->get());
  }
  return out;
}

std::string TableReader::choice(std::string_view key, const std::vector<std::string>& choices) const {
  std::string v = string(key);
  for (const auto& c : choices) {
    if (c == v) return v;
  }
  fail(key, "expected one of " + quoted_list(choices) + ", got '" + v + "'");
}

std::string TableReader::choice(std::string_view key, const std::vector<std::string>& choices,
                                std::string_view fallback) const {
  return has(key) ? choice(key, choices) : std::string(fallback);
}

TableReader TableReader::table(std::string_view key) const {
  const toml::node& n = need(key);
  const auto* t = n.as_table();
  if (t == nullptr) fail(key, "expected a table, got " + describe_type(n));
  return TableReader(file_, *t, prefix().empty() ? std::string(key) : context_ + "." + std::string(key));
}

std::optional<TableReader> TableReader::optional_table(std::string_view key) const {
  if (!has(key)) return std::nullopt;
  return table(key);
}

std::vector<TableReader> TableReader::tables(std::string_view key) const {
  const toml::node& n = need(key);
  const auto* arr = n.as_array();
  if (arr != nullptr && arr->empty()) fail(key, "expected at least one [[" + std::string(key) + "]] entry, got none");
  if (arr == nullptr || !arr->is_array_of_tables()) {
    fail(key, "expected an array of tables ([[" + std::string(key) + "]]), got " + describe_type(n));
  }
  std::vector<TableReader> out;
  std::size_t i = 0;
  for (const auto& el : *arr) {
    out.emplace_back(file_, *el.as_table(),
                     (context_.empty() ? "" : context_ + ".") + std::string(key) + "[" + std::to_string(i++) + "]");
  }
  return out;
}

std::filesystem::path TableReader::path(std::string_view key) const {
  const std::filesystem::path p = string(key);
  if (p.empty()) fail(key, "expected a non-empty path");
  if (p.is_absolute()) return p;
  return file_->path.parent_path() / p;
}

void TableReader::finish() const {
  for (const auto& [k, v] : *table_) {
    if (asked_->count(k.str()) == 0) {
      const auto& b = k.source().begin;
      const SourceLocation where =
          b.line != 0 ? SourceLocation{file_->path.string(), b.line, b.column} : location_of(*file_, v);
      throw ConfigError(where, "unknown key '" + std::string(k.str()) + "'" +
                                   (context_.empty() ? std::string() : " in " + context_) +
                                   "; known keys: " + join(*asked_));
    }
  }
}

}  // namespace redres

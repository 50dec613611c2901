#pragma once
/// @file
/// Strict, position-aware access to TOML tables. Every error is a ConfigError that starts with
/// "file:line:col:" and says what was expected. Required keys use exact typed access (no silent defaults);
/// optional keys state their default in the call. finish() rejects every key that was never asked for and
/// lists the keys that are known.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "redres/common/error.hpp"

namespace redres {

/// A parsed TOML file. Keeps the tree alive for the readers that point into it.
struct TomlFile {
  std::filesystem::path path;  //!< the path as given (used in messages)
  toml::table root;            //!< the parsed document
};

/// Parses a TOML file; a syntax error or an unreadable file is a ConfigError at the offending position. (Edit the
/// tree in place if needed: copying toml++ nodes drops their source positions.)
[[nodiscard]] std::shared_ptr<TomlFile> parse_toml_file(const std::filesystem::path& path);

/// Parses TOML text; `name` stands in for the file name in messages.
[[nodiscard]] std::shared_ptr<TomlFile> parse_toml_string(std::string_view text, const std::string& name);

/// "file:line:col" of a node in `file`.
[[nodiscard]] SourceLocation location_of(const TomlFile& file, const toml::node& node);

/// Human-readable TOML type of a node ("a string", "an array", ...).
[[nodiscard]] std::string describe_type(const toml::node& node);

/// The one reader of a number that may be written as a constant formula: an integer or a floating-point node is its
/// value, a string is evaluated as a constant formula ("pi/2", "-3*pi/4"; common/formula.hpp). Returns false for any
/// other node (`v` untouched); a formula that does not evaluate is std::invalid_argument with the formula's message.
/// The value may be non-finite: the caller checks, and says where.
[[nodiscard]] bool read_number_or_formula(const toml::node& node, double& v);

/// A TOML value as the text that reads back as it (what `--set key=value` takes): floats in their shortest
/// round-trip form, still floats ("2.0", not "2"); strings quoted; arrays and tables inline.
[[nodiscard]] std::string toml_value_text(const toml::node& node);

/// Reads one table strictly. Cheap to copy; it refers to the TomlFile, which must outlive it.
class TableReader {
 public:
  /// `context` names the table in messages, e.g. "joint 'j3' velocity_limit".
  TableReader(std::shared_ptr<const TomlFile> file, const toml::table& table, std::string context);

  /// The root table of a file.
  static TableReader root(std::shared_ptr<const TomlFile> file, std::string context = "");

  /// True when `key` is present (and marks the key as known).
  [[nodiscard]] bool has(std::string_view key) const;

  /// Required finite number (integers are accepted).
  [[nodiscard]] double number(std::string_view key) const;
  /// Optional finite number.
  [[nodiscard]] double number(std::string_view key, double fallback) const;
  /// Required integer.
  [[nodiscard]] std::int64_t integer(std::string_view key) const;
  /// Optional integer.
  [[nodiscard]] std::int64_t integer(std::string_view key, std::int64_t fallback) const;
  /// Required string.
  [[nodiscard]] std::string string(std::string_view key) const;
  /// Optional string.
  [[nodiscard]] std::string string(std::string_view key, std::string_view fallback) const;
  /// Optional boolean.
  [[nodiscard]] bool boolean(std::string_view key, bool fallback) const;
  /// Required array of finite numbers; `size` (if given) is the exact length expected.
  [[nodiscard]] std::vector<double> numbers(std::string_view key, std::optional<std::size_t> size = {}) const;
  /// Required array of strings.
  [[nodiscard]] std::vector<std::string> strings(std::string_view key) const;
  /// Required string that must be one of `choices`.
  [[nodiscard]] std::string choice(std::string_view key, const std::vector<std::string>& choices) const;
  /// Optional string that must be one of `choices`.
  [[nodiscard]] std::string choice(std::string_view key, const std::vector<std::string>& choices,
                                   std::string_view fallback) const;
  /// Required sub-table.
  [[nodiscard]] TableReader table(std::string_view key) const;
  /// Optional sub-table.
  [[nodiscard]] std::optional<TableReader> optional_table(std::string_view key) const;
  /// Required, non-empty array of tables.
  [[nodiscard]] std::vector<TableReader> tables(std::string_view key) const;
  /// A path-valued string, resolved relative to the directory of the file that names it.
  [[nodiscard]] std::filesystem::path path(std::string_view key) const;

  /// Location of the table itself.
  [[nodiscard]] SourceLocation location() const;
  /// Location of the value at `key` (the table's location when the key is absent).
  [[nodiscard]] SourceLocation location(std::string_view key) const;
  /// Throws a ConfigError at `key` (or at the table when absent): "<context>: key 'k': <message>".
  [[noreturn]] void fail(std::string_view key, const std::string& message) const;
  /// Throws a ConfigError at the table: "<context>: <message>".
  [[noreturn]] void fail(const std::string& message) const;

  /// Rejects keys that were never asked for: "unknown key 'k' in <context>; known keys: a, b".
  void finish() const;

  /// The underlying table and file, for code that needs more than the typed accessors.
  [[nodiscard]] const toml::table& raw() const noexcept { return *table_; }
  [[nodiscard]] const TomlFile& file() const noexcept { return *file_; }
  [[nodiscard]] const std::shared_ptr<const TomlFile>& file_ptr() const noexcept { return file_; }
  [[nodiscard]] const std::string& context() const noexcept { return context_; }

 private:
  const toml::node* find(std::string_view key) const;
  const toml::node& need(std::string_view key) const;
  double to_number(std::string_view key, const toml::node& node, const std::string& what) const;
  std::string prefix() const;

  std::shared_ptr<const TomlFile> file_;
  const toml::table* table_;
  std::string context_;
  std::shared_ptr<std::set<std::string, std::less<>>> asked_;
};

}  // namespace redres

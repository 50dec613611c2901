#pragma once
/// @file
/// String -> factory registries. Each plugin registers itself from its own .cpp (static initialisation of a
/// namespace-scope object); unknown or duplicate names are errors that list the known names.

#include <algorithm>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "redres/toml_reader.hpp"

namespace redres {

/// One configuration key of a plugin, for `redres plugins` and for error messages.
struct KeySpec {
  std::string name;           //!< TOML key
  std::string default_value;  //!< default as TOML text; empty when the key is required
  std::string description;    //!< what it means, with units
};

/// A registry of plugin factories of one kind. `Args` are extra factory arguments besides the config table.
template <class Base, class... Args>
class Registry {
 public:
  /// Builds a plugin from its (strict) configuration table.
  using Factory = std::function<std::unique_ptr<Base>(const TableReader&, Args...)>;

  /// A registered plugin type.
  struct Entry {
    std::string type;           //!< name used as `type = "..."` in TOML; equals the plugin's file name
    std::string summary;        //!< one line
    std::vector<KeySpec> keys;  //!< accepted keys with defaults
    Factory make;               //!< factory
  };

  /// `kind` names the registry in messages ("velocity-limit law", "objective", ...).
  explicit Registry(std::string kind) : kind_(std::move(kind)) {}

  /// Adds a type; a duplicate name is a std::logic_error. Returns true so it can initialise a static.
  bool add(Entry entry) {
    const std::string name = entry.type;
    if (!entries_.emplace(name, std::move(entry)).second) {
      throw std::logic_error("duplicate " + kind_ + " type '" + name + "' registered");
    }
    return true;
  }

  /// The entry for `type`, or nullptr.
  [[nodiscard]] const Entry* find(const std::string& type) const {
    auto it = entries_.find(type);
    return it == entries_.end() ? nullptr : &it->second;
  }

  /// Builds the plugin named by the table's `type` key; an unknown type is a ConfigError listing known types.
  /// The plugin's own factory reads the remaining keys and calls finish().
  [[nodiscard]] std::unique_ptr<Base> create(const TableReader& config, Args... args) const {
    const std::string type = config.string("type");
    const Entry* e = find(type);
    if (e == nullptr) config.fail("type", "unknown " + kind_ + " type '" + type + "'; known types: " + names());
    return e->make(config, args...);
  }

  /// All entries, sorted by type.
  [[nodiscard]] std::vector<const Entry*> entries() const {
    std::vector<const Entry*> out;
    for (const auto& kv : entries_) out.push_back(&kv.second);
    return out;
  }

  /// "a, b, c".
  [[nodiscard]] std::string names() const {
    std::string out;
    for (const auto& kv : entries_) out += (out.empty() ? "" : ", ") + kv.first;
    return out;
  }

  /// The registry's kind, e.g. "velocity-limit law".
  [[nodiscard]] const std::string& kind() const noexcept { return kind_; }

 private:
  std::string kind_;
  std::map<std::string, Entry> entries_;
};

}  // namespace redres

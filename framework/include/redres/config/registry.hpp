#pragma once
/// @file
/// Name -> plugin registries, one per plugin kind. A plugin registers itself from its own .cpp with a typed Config
/// (see config.hpp); from that the registry derives reading the plugin from TOML, building it from a Config value
/// by name, writing its configuration back, and listing its keys.
///
/// Plugins in a shared library loaded at run time (plugin_loader.hpp) register the same way; the registry then
/// remembers the library as the entry's origin, and a name that exists already is recorded as a load error of that
/// library instead of being thrown from its static initialisation.

#include <algorithm>
#include <any>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <vector>

#include "redres/config/config.hpp"
#include "redres/config/toml_reader.hpp"

namespace redres {

/// Where registrations come from (a plugin library being loaded, or the built-in plugins), as the registries see it.
namespace registration {
/// "built-in", or the path of the library being loaded.
[[nodiscard]] std::string origin();
/// A registration refused (e.g. a duplicate name): a std::logic_error for a built-in plugin, else recorded as a load
/// error of the library being loaded.
void refuse(const std::string& why);
/// Counts a plugin that the library being loaded registered.
void added() noexcept;
}  // namespace registration

/// What every registry offers to the plugin loader and `redres plugins`, independent of the plugin kind.
class RegistryBase {
 public:
  explicit RegistryBase(std::string kind);
  RegistryBase(const RegistryBase&) = delete;
  RegistryBase& operator=(const RegistryBase&) = delete;
  virtual ~RegistryBase();

  /// The kind in messages, e.g. "objective", "velocity-limit law".
  [[nodiscard]] const std::string& kind() const noexcept { return kind_; }
  /// Removes the entries that `origin` (a library path) registered; returns how many.
  virtual std::size_t remove_origin(const std::string& origin) = 0;
  /// Every registry of the process, in creation order.
  static std::vector<RegistryBase*>& all();

 private:
  std::string kind_;
};

/// A registry of plugins of one kind. `Args` are what a plugin's constructor takes besides its Config (e.g. the
/// robot).
template <class Base, class... Args>
class Registry : public RegistryBase {
 public:
  /// A registered plugin type.
  struct Entry {
    std::string type;                                         //!< name used as `type = "..."` in TOML
    std::string summary;                                      //!< one line
    std::string origin;                                       //!< "built-in" or the library that registered it
    std::vector<KeyInfo> keys;                                //!< keys with defaults, units, rules, presence
    std::vector<std::pair<std::string, std::string>> groups;  //!< group -> what to give
    const std::type_info* config_type = nullptr;              //!< the Config type
    std::any defaults;                                        //!< a default Config
    std::any example;  //!< a Config for the conformance checks when the defaults cannot build (empty: none)
    std::function<std::any(const TableReader&)> read;          //!< reads and checks a Config (does not finish())
    std::function<void(const std::any&, toml::table&)> write;  //!< writes a Config's keys
    std::function<std::unique_ptr<Base>(const std::any&, Args...)> make;  //!< builds from a Config
  };

  explicit Registry(std::string kind) : RegistryBase(std::move(kind)) {}

  /// Registers `type` with Config type C (which has `static const Schema<C>& schema()`) and a factory
  /// make(const C&, Args...) -> std::unique_ptr<Base>. A duplicate name is a std::logic_error for built-in
  /// plugins and a load error of the library being loaded. Returns whether it was added (to initialise a static).
  template <class C, class Make>
  bool add(std::string type, std::string summary, Make make, std::optional<C> example = std::nullopt) {
    Entry e;
    e.type = std::move(type);
    e.summary = std::move(summary);
    e.origin = registration::origin();
    e.keys = describe_keys<C>(C::schema());
    e.groups = C::schema().groups;
    e.config_type = &typeid(C);
    e.defaults = C{};
    if (example) e.example = *example;
    e.read = [](const TableReader& r) -> std::any {
      C c{};
      read_config(r, C::schema(), c);
      return c;
    };
    e.write = [](const std::any& c, toml::table& out) { write_config(std::any_cast<const C&>(c), C::schema(), out); };
    e.make = [make, type = e.type](const std::any& c, Args... args) -> std::unique_ptr<Base> {
      const C& config = std::any_cast<const C&>(c);
      require_valid(config, C::schema(), type);  // a Config built in C++ obeys the same rules as one read from TOML
      return make(config, args...);
    };
    if (const auto it = entries_.find(e.type); it != entries_.end()) {
      const std::string why =
          "duplicate " + kind() + " type '" + e.type + "': already registered by " + it->second.origin;
      registration::refuse(why);
      return false;
    }
    const std::string name = e.type;
    entries_.emplace(name, std::move(e));
    registration::added();
    return true;
  }

  /// Registers plugin class P: P::kType, P::Config, and a constructor P(const P::Config&, Args...). `example` is a
  /// Config the conformance checks use when the defaults cannot build (a plugin with required keys).
  template <class P>
  bool add_plugin(std::string summary, std::optional<typename P::Config> example = std::nullopt) {
    return add<typename P::Config>(
        P::kType, std::move(summary),
        [](const typename P::Config& c, Args... args) {
          return std::unique_ptr<Base>(std::make_unique<P>(c, args...));
        },
        std::move(example));
  }

  /// Registers an entry made at run time rather than from a C++ Config type (e.g. a plugin class defined in Python):
  /// the caller fills in type, summary, keys, config_type, defaults, read, write and make; `origin` names where it
  /// came from. A name that exists already is a std::invalid_argument naming both origins.
  void add_entry(Entry e, std::string origin) {
    if (const auto it = entries_.find(e.type); it != entries_.end()) {
      throw std::invalid_argument("duplicate " + kind() + " type '" + e.type + "': already registered by " +
                                  it->second.origin);
    }
    e.origin = std::move(origin);
    const std::string name = e.type;
    entries_.emplace(name, std::move(e));
  }

  /// The entry for `type`, or nullptr.
  [[nodiscard]] const Entry* find(const std::string& type) const {
    auto it = entries_.find(type);
    return it == entries_.end() ? nullptr : &it->second;
  }

  /// The entry for `type`; std::invalid_argument listing the known types when there is none.
  [[nodiscard]] const Entry& at(const std::string& type) const {
    const Entry* e = find(type);
    if (e == nullptr)
      throw std::invalid_argument("unknown " + kind() + " type '" + type + "'; known types: " + names_like(type));
    return *e;
  }

  /// Builds `type` from a Config value (std::invalid_argument when the value is not that type's Config, or
  /// breaks its schema).
  [[nodiscard]] std::unique_ptr<Base> create(const std::string& type, const std::any& config, Args... args) const {
    const Entry& e = at(type);
    if (config.type() != *e.config_type) {
      throw std::invalid_argument(kind() + " '" + type +
                                  "': expected its own Config type, got a value of another type");
    }
    return e.make(config, args...);
  }

  /// Builds `type` with its default Config.
  [[nodiscard]] std::unique_ptr<Base> create_default(const std::string& type, Args... args) const {
    const Entry& e = at(type);
    return e.make(e.defaults, args...);
  }

  /// Reads the table's `type` and the type's keys (not finish()ed: the caller may read common keys too), and builds
  /// the plugin. Unknown types and invalid keys are ConfigErrors at file:line:col.
  [[nodiscard]] std::unique_ptr<Base> create(const TableReader& table, Args... args) const {
    const std::string type = table.string("type");
    const Entry* e = find(type);
    if (e == nullptr)
      table.fail("type", "unknown " + kind() + " type '" + type + "'; known types: " + names_like(type));
    const std::any config = e->read(table);
    try {
      return e->make(config, args...);
    } catch (const FieldError& err) {
      rethrow_at(table, err);
    }
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

  /// The names a message about the unknown `type` lists: all of them while there are at most kListed, else the
  /// kListed that share the longest prefix with `type` and how many more there are (a message stays short however
  /// many plugins a library registers).
  [[nodiscard]] std::string names_like(const std::string& type) const {
    static constexpr std::size_t kListed = 24;
    if (entries_.size() <= kListed) return names();
    std::vector<std::pair<std::size_t, std::string>> by_prefix;  // (-shared prefix length, name)
    for (const auto& kv : entries_) {
      std::size_t k = 0;
      while (k < type.size() && k < kv.first.size() && type[k] == kv.first[k]) ++k;
      by_prefix.emplace_back(type.size() - k, kv.first);
    }
    std::partial_sort(by_prefix.begin(), by_prefix.begin() + kListed, by_prefix.end());
    std::vector<std::string> listed;
    for (std::size_t i = 0; i < kListed; ++i) listed.push_back(by_prefix[i].second);
    std::sort(listed.begin(), listed.end());
    std::string out;
    for (const auto& n : listed) out += (out.empty() ? "" : ", ") + n;
    return out + " and " + std::to_string(entries_.size() - kListed) + " more (`redres plugins` lists them all)";
  }

  std::size_t remove_origin(const std::string& origin) override {
    std::size_t n = 0;
    for (auto it = entries_.begin(); it != entries_.end();) {
      if (it->second.origin == origin) {
        it = entries_.erase(it);
        ++n;
      } else {
        ++it;
      }
    }
    return n;
  }

 private:
  std::map<std::string, Entry> entries_;
};

}  // namespace redres

#pragma once
/// @file
/// The one table of plugin kinds: objectives, constraints, tasks, velocity-limit laws, paths and LVI engines. The
/// `redres plugins` listing (text and JSON), the conformance checks, the Python namespaces (`redres.<plural>`) and the
/// layering check (tests/architecture/check_layers.py, which reads the `kind(...)` lines of plugin_kinds.cpp) all read
/// it, so that a new kind is one entry here (and its registry) instead of an edit in each of them.

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "redres/config/config.hpp"
#include "redres/extend/conformance.hpp"

namespace redres {

/// One registered plugin, as the listings show it (whatever its kind).
struct PluginEntryInfo {
  std::string type;                                         //!< `type = "..."` in files
  std::string summary;                                      //!< one line
  std::string origin;                                       //!< "built-in" or the library that registered it
  std::vector<KeyInfo> keys;                                //!< its own keys
  std::vector<std::pair<std::string, std::string>> groups;  //!< key groups: group -> what to give
};

/// A plugin kind.
struct PluginKind {
  std::string name;     //!< the kind in messages and conformance results: "objective", "velocity-limit law"
  std::string id;       //!< the kind as an identifier: "objective", "velocity_limit" (Python's `plugins(kind)`)
  std::string plural;   //!< "objectives": `redres plugins --json`'s key, Python's `redres.<plural>`, plugins/<plural>/
  std::string heading;  //!< `redres plugins`' heading: where files name a plugin of this kind
  std::string common_json;     //!< `redres plugins --json`'s key of the keys every plugin of the kind takes ("": none)
  std::string common_heading;  //!< `redres plugins`' heading of those keys
  /// The keys every plugin of this kind takes besides its own (e.g. an objective's `weight`).
  std::function<std::vector<KeyInfo>()> common_keys;
  /// More keys of the same table that are not the plugins' (the engine's [solver] table: the failure policy), with
  /// their JSON key; listed after the common keys.
  std::string extra_json;
  std::function<std::vector<KeyInfo>()> extra_keys;
  /// Every registered plugin of the kind, in the registry's order.
  std::function<std::vector<PluginEntryInfo>()> entries;
  /// The conformance checks of the kind's plugins whose origin is `origin` ("" for all), appended to `out`.
  std::function<void(const std::string& origin, std::vector<ConformanceResult>& out)> check;
};

/// Every plugin kind, in the order the listings show them.
[[nodiscard]] const std::vector<PluginKind>& plugin_kinds();

}  // namespace redres

// `redres plugins`: every registered plugin of every kind (extend/plugin_kinds.hpp), with its keys:
// type, unit, default or whether it is required (or one of a group), validity rule and meaning. The listing comes
// from each plugin's Config schema, so it cannot drift from what the TOML reader accepts.

#include <iomanip>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "redres/extend/plugin_kinds.hpp"
#include "redres/run/file_keys.hpp"
#include "redres/run/scenario.hpp"

namespace redres::cli {

namespace {

// "= default", "(required)" or "(group g)".
std::string listed_presence(const KeyInfo& k) {
  const std::string text = presence_text(k);
  return k.presence == Presence::kOptional ? text : "(" + text + ")";
}

void print_keys(const std::vector<KeyInfo>& keys) {
  for (const KeyInfo& k : keys) {
    std::cout << "      " << std::left << std::setw(16) << k.name << std::setw(14) << listed_presence(k) << std::right
              << " " << k.help;
    std::string facts = k.type;
    if (!k.unit.empty()) facts += ", " + k.unit;
    if (!k.rule.empty()) facts += ", " + k.rule;
    std::cout << " [" << facts << "]\n";
  }
}

void print_kind(const PluginKind& kind) {
  std::cout << kind.heading << "\n";
  std::vector<KeyInfo> common = kind.common_keys();
  if (kind.extra_keys) {
    for (const KeyInfo& k : kind.extra_keys()) common.push_back(k);
  }
  if (!common.empty()) {
    std::cout << "  " << kind.common_heading << "\n";
    print_keys(common);
  }
  for (const PluginEntryInfo& e : kind.entries()) {
    std::cout << "  " << e.type << (e.origin == "built-in" ? "" : "   (from " + e.origin + ")") << "\n      "
              << e.summary << "\n";
    print_keys(e.keys);
    for (const auto& [group, rule] : e.groups) std::cout << "      group " << group << ": " << rule << "\n";
  }
  std::cout << "\n";
}

nlohmann::json keys_json(const std::vector<KeyInfo>& keys) {
  nlohmann::json out = nlohmann::json::array();
  for (const KeyInfo& k : keys) {
    const char* presence = k.presence == Presence::kRequired ? "required"
                           : k.presence == Presence::kGroup  ? "group"
                                                             : "optional";
    nlohmann::json j = {{"name", k.name}, {"presence", presence}, {"type", k.type},
                        {"unit", k.unit}, {"rule", k.rule},       {"description", k.help}};
    if (k.presence == Presence::kOptional) j["default"] = k.default_text;
    if (k.presence == Presence::kGroup) j["group"] = k.group;
    out.push_back(j);
  }
  return out;
}

nlohmann::json entries_json(const PluginKind& kind) {
  nlohmann::json out = nlohmann::json::array();
  for (const PluginEntryInfo& e : kind.entries()) {
    nlohmann::json groups = nlohmann::json::object();
    for (const auto& [group, rule] : e.groups) groups[group] = rule;
    out.push_back({{"type", e.type},
                   {"summary", e.summary},
                   {"origin", e.origin},
                   {"keys", keys_json(e.keys)},
                   {"groups", groups}});
  }
  return out;
}

}  // namespace

int print_file_keys(const std::string& file, bool json) {
  const std::vector<KeyTable> tables = file_key_tables();
  if (json) {
    nlohmann::json out = nlohmann::json::array();
    for (const KeyTable& t : tables) {
      if (!file.empty() && t.file != file) continue;
      out.push_back({{"file", t.file}, {"table", t.table}, {"description", t.help}, {"keys", keys_json(t.keys)}});
    }
    std::cout << out.dump(2) << "\n";
    return kExitOk;
  }
  for (const KeyTable& t : tables) {
    if (!file.empty() && t.file != file) continue;
    std::cout << t.file << " file" << (t.table.empty() ? ", top level" : ": " + t.table) << " (" << t.help << ")\n";
    print_keys(t.keys);
    std::cout << "\n";
  }
  std::cout << "The plugins' tables ([path], [[objectives]], [[constraints]], the engine's [solver] keys, a joint's "
               "velocity_limit): redres plugins\n";
  return kExitOk;
}

void print_plugins(bool json) {
  if (json) {
    nlohmann::json out = nlohmann::json::object();
    for (const PluginKind& kind : plugin_kinds()) {
      out[kind.plural] = entries_json(kind);
      if (!kind.common_json.empty()) out[kind.common_json] = keys_json(kind.common_keys());
      if (!kind.extra_json.empty()) out[kind.extra_json] = keys_json(kind.extra_keys());
    }
    std::cout << out.dump(2) << "\n";
    return;
  }
  for (const PluginKind& kind : plugin_kinds()) print_kind(kind);
}

}  // namespace redres::cli

// `redres plugins`: every registered objective, constraint, velocity-limit law, path and LVI engine, with its keys:
// type, unit, default or whether it is required (or one of a group), validity rule and meaning. The listing comes
// from each plugin's Config schema, so it cannot drift from what the TOML reader accepts.

#include <iomanip>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/control/path.hpp"
#include "redres/control/plugin.hpp"
#include "redres/control/task.hpp"
#include "redres/model/velocity_limit.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"
#include "redres/qp/lvi.hpp"
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

template <class R>
void print_registry(const R& registry, const std::string& title, const std::vector<KeyInfo>& common,
                    const std::string& common_title) {
  std::cout << title << "\n";
  if (!common.empty()) {
    std::cout << "  " << common_title << "\n";
    print_keys(common);
  }
  for (const auto* e : registry.entries()) {
    std::cout << "  " << e->type << (e->origin == "built-in" ? "" : "   (from " + e->origin + ")") << "\n      "
              << e->summary << "\n";
    print_keys(e->keys);
    for (const auto& [group, rule] : e->groups) std::cout << "      group " << group << ": " << rule << "\n";
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

template <class R>
nlohmann::json registry_json(const R& registry) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto* e : registry.entries()) {
    nlohmann::json groups = nlohmann::json::object();
    for (const auto& [group, rule] : e->groups) groups[group] = rule;
    out.push_back({{"type", e->type},
                   {"summary", e->summary},
                   {"origin", e->origin},
                   {"keys", keys_json(e->keys)},
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
    const nlohmann::json out = {{"objectives", registry_json(objective_registry())},
                                {"objective_common_keys", keys_json(objective_common_keys())},
                                {"constraints", registry_json(constraint_registry())},
                                {"constraint_common_keys", keys_json(constraint_common_keys())},
                                {"tasks", registry_json(task_registry())},
                                {"task_common_keys", keys_json(task_common_keys())},
                                {"velocity_limits", registry_json(velocity_limit_registry())},
                                {"paths", registry_json(path_registry())},
                                {"path_common_keys", keys_json(describe_keys(PathPlacement::schema()))},
                                {"engines", registry_json(engine_registry())},
                                {"solver_common_keys", keys_json(solver_common_keys())},
                                {"solver_policy_keys", keys_json(solver_policy_keys())}};
    std::cout << out.dump(2) << "\n";
    return;
  }
  print_registry(objective_registry(), "objectives ([[objectives]] tables in a scenario)", objective_common_keys(),
                 "keys of every objective:");
  print_registry(constraint_registry(), "constraints ([[constraints]] tables in a scenario; hard, no weight)",
                 constraint_common_keys(), "keys of every constraint:");
  print_registry(task_registry(), "tasks ([[tasks]] tables in a scenario; docs/tasks.md)", task_common_keys(),
                 "keys of every task:");
  print_registry(velocity_limit_registry(), "velocity-limit laws ([joints.velocity_limit] in a robot file)", {}, "");
  print_registry(path_registry(), "paths (the [path] table of a scenario)", describe_keys(PathPlacement::schema()),
                 "keys of every path (placement and timing):");
  std::vector<KeyInfo> solver_keys = solver_common_keys();
  for (const KeyInfo& k : solver_policy_keys()) solver_keys.push_back(k);
  print_registry(engine_registry(), "LVI engines (the [solver] table of a scenario)", solver_keys,
                 "keys of every engine, and the run's policy for a step that is not solved:");
}

}  // namespace redres::cli

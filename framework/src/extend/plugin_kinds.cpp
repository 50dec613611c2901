#include "redres/extend/plugin_kinds.hpp"

#include "extend/kind_checks.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/control/path.hpp"
#include "redres/control/plugin.hpp"
#include "redres/control/task.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"
#include "redres/run/scenario.hpp"

namespace redres {

namespace {

template <class R>
std::function<std::vector<PluginEntryInfo>()> listing(R& (*registry)()) {
  return [registry] {
    std::vector<PluginEntryInfo> out;
    for (const auto* e : registry().entries()) out.push_back({e->type, e->summary, e->origin, e->keys, e->groups});
    return out;
  };
}

std::vector<KeyInfo> none() { return {}; }

std::vector<KeyInfo> path_keys() { return describe_keys(PathPlacement::schema()); }

// One line per kind: kind("name", "plural", ...). The layering check reads the plurals from these lines.
PluginKind kind(std::string name, std::string plural, std::string heading, std::string common_json,
                std::string common_heading, std::function<std::vector<KeyInfo>()> common,
                std::function<std::vector<PluginEntryInfo>()> entries,
                std::function<void(const std::string&, std::vector<ConformanceResult>&)> check) {
  PluginKind k;
  k.name = std::move(name);
  k.plural = std::move(plural);
  k.id = k.plural.substr(0, k.plural.size() - 1);  // "objectives" -> "objective"
  k.heading = std::move(heading);
  k.common_json = std::move(common_json);
  k.common_heading = std::move(common_heading);
  k.common_keys = std::move(common);
  k.entries = std::move(entries);
  k.check = std::move(check);
  return k;
}

std::vector<PluginKind> make_kinds() {
  std::vector<PluginKind> k;
  k.push_back(kind("objective", "objectives", "objectives ([[objectives]] tables in a scenario)",
                   "objective_common_keys", "keys of every objective:", objective_common_keys,
                   listing(objective_registry), kind_checks::objectives));
  k.push_back(kind("constraint", "constraints", "constraints ([[constraints]] tables in a scenario; hard, no weight)",
                   "constraint_common_keys", "keys of every constraint:", constraint_common_keys,
                   listing(constraint_registry), kind_checks::constraints));
  k.push_back(kind("task", "tasks", "tasks ([[tasks]] tables in a scenario; docs/tasks.md)", "task_common_keys",
                   "keys of every task:", task_common_keys, listing(task_registry), kind_checks::tasks));
  k.push_back(kind("velocity-limit law", "velocity_limits",
                   "velocity-limit laws ([joints.velocity_limit] in a robot file)", "", "", none,
                   listing(velocity_limit_registry), kind_checks::velocity_limits));
  k.push_back(kind("path", "paths", "paths (the [path] table of a scenario)", "path_common_keys",
                   "keys of every path (placement and timing):", path_keys, listing(path_registry),
                   kind_checks::paths));
  k.push_back(kind("engine", "engines", "LVI engines (the [solver] table of a scenario)", "solver_common_keys",
                   "keys of every engine, and the run's policy for a step that is not solved:", solver_common_keys,
                   listing(engine_registry), kind_checks::engines));
  k.back().extra_json = "solver_policy_keys";
  k.back().extra_keys = solver_policy_keys;
  return k;
}

}  // namespace

const std::vector<PluginKind>& plugin_kinds() {
  static const std::vector<PluginKind> kinds = make_kinds();
  return kinds;
}

}  // namespace redres

// `redres plugins`: every registered objective, constraint, velocity-limit law and LVI engine, with its keys and
// their defaults.

#include <iomanip>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "redres/lvi.hpp"
#include "redres/plugin.hpp"

namespace redres::cli {

namespace {

template <class R>
void print_registry(const R& registry, const std::string& title, const std::vector<KeySpec>& common) {
  std::cout << title << "\n";
  for (const auto* e : registry.entries()) {
    std::cout << "  " << e->type << "\n      " << e->summary << "\n";
    for (const auto* keys : {&e->keys, &common}) {
      for (const KeySpec& k : *keys) {
        std::cout << "      " << std::left << std::setw(16) << k.name << std::setw(12)
                  << (k.default_value.empty() ? "(required)" : "= " + k.default_value) << std::right << " "
                  << k.description << "\n";
      }
    }
  }
  std::cout << "\n";
}

template <class R>
nlohmann::json registry_json(const R& registry) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto* e : registry.entries()) {
    nlohmann::json keys = nlohmann::json::array();
    for (const KeySpec& k : e->keys) {
      keys.push_back({{"name", k.name}, {"default", k.default_value}, {"description", k.description}});
    }
    out.push_back({{"type", e->type}, {"summary", e->summary}, {"keys", keys}});
  }
  return out;
}

}  // namespace

void add_plugins_command(CLI::App& app, Action& action) {
  auto json = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand("plugins", "List every registered plugin with its keys and defaults");
  cmd->add_flag("--json", *json, "print JSON instead of text");
  cmd->callback([json, &action] {
    action = [json] {
      if (*json) {
        const nlohmann::json out = {{"objectives", registry_json(objective_registry())},
                                    {"constraints", registry_json(constraint_registry())},
                                    {"velocity_limits", registry_json(velocity_limit_registry())},
                                    {"engines", registry_json(engine_registry())}};
        std::cout << out.dump(2) << "\n";
        return kExitOk;
      }
      const std::vector<KeySpec> plugin_common = {
          {"name", "the type", "instance name, used in diagnoses"},
          {"weight", "1.0", "objectives: scales W and zeta; constraints: scales their rows"},
          {"active", "true", "false builds the plugin but leaves it out of the QP"}};
      print_registry(objective_registry(), "objectives ([[objectives]] tables in a scenario)", plugin_common);
      print_registry(constraint_registry(), "constraints ([[constraints]] tables in a scenario)", plugin_common);
      print_registry(velocity_limit_registry(), "velocity-limit laws ([joints.velocity_limit] in a robot file)", {});
      print_registry(engine_registry(), "LVI engines (`engine` in a scenario's [solver] table)",
                     {{"tolerance", "1e-6", "stopping test ||e(u)||_2 <= tolerance"},
                      {"varpi", "1e6", "bound on the duals standing for infinity"},
                      {"max_iterations", "20000", "iteration cap per solve"},
                      {"warm_start", "true", "start each solve from the previous u"}});
      return kExitOk;
    };
  });
}

}  // namespace redres::cli

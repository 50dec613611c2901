// Registers `redres plugins [--json] [--check]` and `redres keys [FILE] [--json]`.

#include <iostream>
#include <memory>

#include "commands.hpp"
#include "redres/extend/conformance.hpp"
#include "redres/run/file_keys.hpp"

namespace redres::cli {

int check_plugins(std::ostream& out) {
  int failures = 0, passed = 0;
  for (const ConformanceResult& r : check_registries()) {
    if (r.ok) {
      ++passed;
      continue;
    }
    ++failures;
    out << "FAIL " << r.kind << " '" << r.type << "': " << r.check << ": " << r.detail << "\n";
  }
  out << "conformance: " << passed << " checks passed, " << failures << " failed\n";
  return failures;
}

void add_plugins_command(CLI::App& app, Action& action) {
  auto json = std::make_shared<bool>(false);
  auto check = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand(
      "plugins", "List every registered plugin with its keys and defaults, or check them all (--check)");
  cmd->add_flag("--json", *json, "print JSON instead of text");
  cmd->add_flag("--check", *check,
                "run the conformance checks (defaults, round trip, documented keys, finite contributions, zeta against "
                "central differences of potential()) on every registered plugin, built-in and loaded; exit 1 on a "
                "failure");
  cmd->callback([json, check, &action] {
    action = [json, check] {
      if (*check) return check_plugins(std::cout) == 0 ? kExitOk : kExitFailedSteps;
      print_plugins(*json);
      return kExitOk;
    };
  });
}

void add_keys_command(CLI::App& app, Action& action) {
  auto json = std::make_shared<bool>(false);
  auto file = std::make_shared<std::string>();
  auto markdown = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand(
      "keys", "List every key of the scenario, robot and sweep files, table by table: type, unit, default, rule");
  cmd->add_option("file", *file, "only this file's keys")->check(CLI::IsMember({"scenario", "robot", "sweep"}));
  cmd->add_flag("--json", *json, "print JSON instead of text");
  cmd->add_flag("--markdown", *markdown, "print the file's Markdown tables, as its page in docs/ shows them")
      ->needs(cmd->get_option("file"));
  cmd->callback([json, file, markdown, &action] {
    action = [json, file, markdown] {
      if (*markdown) {
        std::cout << file_keys_markdown(*file);
        return kExitOk;
      }
      return print_file_keys(*file, *json);
    };
  });
}

}  // namespace redres::cli

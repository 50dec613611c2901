// Registers `redres plugins [--json] [--check]`.

#include <iostream>
#include <memory>

#include "commands.hpp"
#include "redres/extend/conformance.hpp"

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

}  // namespace redres::cli

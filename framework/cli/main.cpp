// redres command-line interface. Only main() catches: configuration errors and API misuse exit with code 2 and a
// message on stderr that starts with "file:line:col:" when a file is at fault.

#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "redres/common/error.hpp"
#include "redres/config/plugin_loader.hpp"

#ifndef REDRES_VERSION
#error "REDRES_VERSION (the project's version) is set by framework/CMakeLists.txt"
#endif

int main(int argc, char** argv) {
  CLI::App app{"redres: redundancy resolution of redundant manipulators (QP from plugins, solved as an LVI)"};
  app.require_subcommand(1);
  app.fallthrough();  // options of the main command (--plugin) may also follow the subcommand
  app.set_version_flag("--version", "redres " REDRES_VERSION);  // project(VERSION) in CMakeLists.txt
  redres::cli::Action action;
  std::vector<std::string> plugin_libraries;
  app.add_option("--plugin", plugin_libraries,
                 "load a plugin library (.so) before the command (repeatable); REDRES_PLUGIN_PATH lists directories "
                 "whose libraries are all loaded");
  redres::cli::add_robot_command(app, action);
  redres::cli::add_plugins_command(app, action);
  redres::cli::add_keys_command(app, action);
  redres::cli::add_run_commands(app, action);
  redres::cli::add_sweep_command(app, action);
  redres::cli::add_view_command(app, action);
  // The first word that is not an option must be a command: an unknown one names itself and lists the known ones
  // (CLI11 would say only "A subcommand is required").
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.empty() || word[0] == '-') {
      if (word == "--plugin") ++i;  // its value
      continue;
    }
    bool known = false;
    std::string names;
    for (const CLI::App* sub : app.get_subcommands({})) {
      known = known || sub->get_name() == word;
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::cerr << "redres: unknown command '" << word << "'; the commands are " << names
                << " (redres --help describes them)\n";
      return redres::cli::kExitBadInput;
    }
    break;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : redres::cli::kExitBadInput;
  }
  try {
    redres::load_plugin_path();
    for (const auto& lib : plugin_libraries) {
      redres::load_plugin_library(redres::resolve_plugin_library(lib, std::filesystem::current_path()),
                                  {"--plugin " + lib, 0, 0});
    }
    return action ? action() : redres::cli::kExitOk;
  } catch (const redres::ConfigError& e) {
    std::cerr << redres::printable(e.what()) << "\n";  // a name from a file may hold escape sequences
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << redres::printable(e.what()) << "\n";
  } catch (const std::exception& e) {
    std::cerr << "error: " << redres::printable(e.what()) << "\n";
  }
  return redres::cli::kExitBadInput;
}

// redres command-line interface. Only main() catches: configuration errors and API misuse exit with code 2 and a
// message on stderr that starts with "file:line:col:" when a file is at fault.

#include <iostream>

#include "commands.hpp"
#include "redres/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"redres: redundancy resolution of redundant manipulators (QP from plugins, solved as an LVI)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "redres 0.1.0");
  redres::cli::Action action;
  redres::cli::add_robot_command(app, action);
  redres::cli::add_plugins_command(app, action);
  redres::cli::add_run_commands(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : redres::cli::kExitBadInput;
  }
  try {
    return action ? action() : redres::cli::kExitOk;
  } catch (const redres::ConfigError& e) {
    std::cerr << e.what() << "\n";
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
  }
  return redres::cli::kExitBadInput;
}

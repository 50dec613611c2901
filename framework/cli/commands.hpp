#pragma once
// Subcommands of the `redres` CLI. Each registers its options on the CLI11 app and returns the action to run.

#include <functional>

#include <CLI/CLI.hpp>

namespace redres::cli {

/// Exit codes (docs/output_formats.md). kExitBadInput is every error that stops a command doing what it was asked:
/// bad input, and also figures asked for (`run --plots`, `[output] plots = true`, `compare` without `--no-plots`)
/// that cannot be made (no python3 on PATH, no matplotlib, no plot_run.py, or the script failed). It takes
/// precedence over kExitFailedSteps.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailedSteps = 1;
inline constexpr int kExitBadInput = 2;
/// `run` ended by SIGINT or SIGTERM: what it wrote is complete and its summary says "interrupted" (128 + SIGINT).
inline constexpr int kExitInterrupted = 130;

/// An action run after parsing; returns the exit code.
using Action = std::function<int()>;

/// `redres robot FILE [--theta v1,v2,...] [--json]`.
void add_robot_command(CLI::App& app, Action& action);

/// `redres run`, `redres validate`, `redres compare`.
void add_run_commands(CLI::App& app, Action& action);

/// `redres sweep SWEEP.toml --out DIR [--jobs N] [--shard i/N] [--runs]`, `redres sweep --merge DIR... --out DIR`.
void add_sweep_command(CLI::App& app, Action& action);

/// `redres plugins [--json] [--check]`.
void add_plugins_command(CLI::App& app, Action& action);

/// `redres keys [scenario|robot|sweep] [--json]`.
void add_keys_command(CLI::App& app, Action& action);

void add_view_command(CLI::App& app, Action& action);

/// Prints the keys of the input files (all when `file` is empty), text or JSON; returns the exit code.
int print_file_keys(const std::string& file, bool json);

/// Prints every registry (text or JSON).
void print_plugins(bool json);

/// Runs the registry conformance checks on every registered plugin; prints one line per check; returns the number
/// of failures.
int check_plugins(std::ostream& out);

}  // namespace redres::cli

// `redres run`, `redres validate` and `redres compare`: scenarios from the command line.

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <tuple>
#include <vector>

#include "commands.hpp"
#include "progress.hpp"
#include "redres/common/csv.hpp"
#include "redres/run/comparison.hpp"
#include "redres/run/run_output.hpp"
#include "redres/run/scenario.hpp"
#include "stop_signals.hpp"

extern char** environ;  // the environment plot_run.py inherits (POSIX leaves the declaration to the program)

namespace redres::cli {

namespace {

struct RunOptions {
  std::vector<std::string> scenarios;
  std::string out;
  std::vector<std::string> overrides;
  bool quiet = false;
  bool plots = false;
  bool animate = false;
  bool no_plots = false;
  std::string record;  // --record; empty: the scenario's [output] record
};

// plot_run.py: $REDRES_TOOLS_DIR/plot_run.py when set, else <dir of this executable>/REDRES_TOOLS_RELDIR, which is
// where `cmake --install` puts it (<prefix>/bin -> <prefix>/share/redres/tools) and where the build tree keeps a
// copy (build/<preset>/bin -> build/<preset>/share/redres/tools). One relative rule serves both, so an installed
// binary never depends on the source tree it was built from.
std::filesystem::path plot_script() {
  if (const char* env = std::getenv("REDRES_TOOLS_DIR"); env != nullptr && *env != '\0') {
    return std::filesystem::path(env) / "plot_run.py";
  }
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) {
    throw std::runtime_error("cannot locate plot_run.py: /proc/self/exe: " + ec.message() +
                             " (set REDRES_TOOLS_DIR to the directory that holds plot_run.py)");
  }
  return (exe.parent_path() / REDRES_TOOLS_RELDIR / "plot_run.py").lexically_normal();
}

// The first executable `program` in a directory of PATH, as a shell would find it, so that the figures use the
// interpreter the user chose (a virtualenv's, pyenv's or Debian's), never one fixed at build time. Empty if none.
std::filesystem::path find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return {};
  std::string_view rest = path;
  for (;;) {
    const std::size_t colon = rest.find(':');
    std::string dir(rest.substr(0, colon));
    if (dir.empty()) dir = ".";  // POSIX: an empty PATH entry is the working directory
    const std::filesystem::path candidate = std::filesystem::path(dir) / program;
    std::error_code ec;
    if (std::filesystem::is_regular_file(candidate, ec) && access(candidate.c_str(), X_OK) == 0) return candidate;
    if (colon == std::string_view::npos) return {};
    rest.remove_prefix(colon + 1);
  }
}

// What renders the figures. Found before a run, so that a missing python3 or script fails at once instead of
// after a long run.
struct Plotter {
  std::filesystem::path python;
  std::filesystem::path script;
  std::string request;  // what asked for the figures, for the messages: "--plots", "compare", ...
};

// Figures that were asked for but cannot be made are an error (exit code 2), never a warning: a script or CI job
// that asked for them must not pass without them.
Plotter find_plotter(std::string request) {
  Plotter p{find_on_path("python3"), plot_script(), std::move(request)};
  if (p.python.empty()) {
    throw std::runtime_error(p.request + ": python3 not found on PATH; the figures need python3 with matplotlib and " +
                             "numpy (apt-get install python3 python3-matplotlib python3-numpy)");
  }
  if (!std::filesystem::is_regular_file(p.script)) {
    const char* env = std::getenv("REDRES_TOOLS_DIR");
    const std::string hint = env != nullptr && *env != '\0' ? " (REDRES_TOOLS_DIR names a directory without it)"
                                                            : "; redres installs it at " REDRES_TOOLS_RELDIR
                                                              " relative to its executable, or "
                                                              "set REDRES_TOOLS_DIR to the directory that holds it";
    throw std::runtime_error(p.request + ": " + p.script.string() + " not found" + hint);
  }
  return p;
}

// Exit code of plot_run.py when matplotlib or numpy cannot be imported (see there).
constexpr int kPlotMissingLibrary = 3;

// Renders figures with plot_run.py; `args` are the script's arguments, `outputs` where the run's data went (the
// data stays valid when only the figures fail). Throws when the script cannot run or fails.
void render_plots(const Plotter& p, std::vector<std::string> args, bool quiet, const std::string& outputs) {
  if (quiet) args.emplace_back("--quiet");
  args.insert(args.begin(), {p.python.string(), p.script.string()});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::cout.flush();
  // posix_spawn rather than system(): no shell, so paths need no quoting.
  pid_t pid = 0;
  if (const int err = posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ); err != 0) {
    throw std::runtime_error(p.request + ": cannot start " + p.python.string() + ": " + std::strerror(err));
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error(p.request + ": waiting for plot_run.py: " + std::strerror(errno));
  }
  const std::string kept = "; " + outputs + " were written";
  if (WIFEXITED(status) && WEXITSTATUS(status) == kPlotMissingLibrary) {
    throw std::runtime_error(p.request + ": matplotlib is not installed for " + p.python.string() +
                             ", the python3 on PATH: apt-get install python3-matplotlib python3-numpy (Debian's " +
                             "python3) or pip install matplotlib numpy, or put a python3 that has them first on PATH" +
                             kept);
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const std::string how = WIFEXITED(status) ? "exited with code " + std::to_string(WEXITSTATUS(status))
                                              : "was killed by signal " + std::to_string(WTERMSIG(status));
    throw std::runtime_error(p.request + ": plotting failed: " + p.python.string() + " " + p.script.string() + " " +
                             how + kept);
  }
}

// The animation of a run: plot_run.py --animate DIR writes DIR/animation.mp4 (ffmpeg on PATH) or else
// DIR/animation.gif. An animation left by an earlier run into DIR is removed first, so that the file found
// afterwards is this run's; it is an error if there is none.
std::filesystem::path render_animation(const Plotter& p, const std::filesystem::path& dir, bool quiet,
                                       const std::string& outputs) {
  const std::filesystem::path files[] = {dir / "animation.mp4", dir / "animation.gif"};
  for (const auto& f : files) std::filesystem::remove(f);
  render_plots(p, {"--animate", dir.string()}, quiet, outputs);
  for (const auto& f : files) {
    std::error_code ec;
    if (std::filesystem::file_size(f, ec) > 0 && !ec) return f;
  }
  throw std::runtime_error(p.request + ": plot_run.py --animate wrote neither animation.mp4 nor animation.gif in " +
                           dir.string() + "; " + outputs + " were written");
}

struct Outcome {
  Scenario scenario;
  RunResult run;
  RunSummary summary;
};

Outcome run_one(Scenario scenario, const std::filesystem::path& out, bool quiet, const RecordOptions& record = {}) {
  Outcome o{std::move(scenario), {}, {}};
  // From the first step until the files are written, SIGINT and SIGTERM only set the flag: the run ends after its
  // current step, and a signal while the files are written lets the writing finish (no temporaries left behind).
  const StopOnSignals signals;
  {
    ProgressBar bar(o.scenario.name, quiet);
    simulate(
        o.scenario, o.run,
        [&bar](double f, double t) {
          char where[32];
          std::snprintf(where, sizeof where, "t = %.2f s", t);
          bar.update(f, where);
        },
        &g_stop_requested);
  }
  o.summary = summarise(o.scenario, o.run);
  (void)write_run(*o.scenario.robot, o.run, o.summary, out, record);
  if (!quiet) {
    const RunSummary& s = o.summary;
    std::cout << std::setprecision(4) << s.name << ": " << s.steps << " steps of " << s.tau << " s, engine "
              << s.solver.engine << ", max position error " << s.max_position_error << " m, w "
              << s.manipulability.initial << " -> " << s.manipulability.final << ", " << s.solver.failures
              << " failed steps, " << s.wall_time_s << " s -> " << out.string() << "\n";
    if (s.solver.relaxed_steps > 0) {
      std::cout << "  " << s.solver.relaxed_steps << " steps relaxed (rows missed by "
                << s.solver.max_relaxed_task_error << " at most); first: " << s.solver.first_relaxed << "\n";
    }
  }
  // The diagnosis of a failed run goes to stderr, with --quiet too: a script that checks the exit code sees why.
  if (o.summary.solver.failures > 0) {
    const SolverStats& st = o.summary.solver;
    std::cerr << o.scenario.name << ": " << st.failures << " failed step" << (st.failures == 1 ? "" : "s")
              << " (on_infeasible = \"" << st.on_infeasible << "\"";
    if (st.held_steps > 0) std::cerr << ", " << st.held_steps << " held with theta_dot = 0";
    if (st.stopped) std::cerr << ", the run stopped at the first";
    std::cerr << "); first failure: " << st.first_failure << "\n";
  }
  if (o.run.interrupted) {
    std::cerr << o.scenario.name << ": interrupted at t = " << o.run.trajectory.at(o.run.trajectory.size() - 1, "t")
              << " s; " << out.string() << " holds the run up to there (summary.json: \"status\": \"interrupted\")\n";
  }
  return o;
}

// The regular files of a directory with their modification times and sizes, to tell which files a figure step
// wrote.
using Listing = std::vector<std::tuple<std::string, std::filesystem::file_time_type, std::uintmax_t>>;
Listing list_files(const std::filesystem::path& dir) {
  Listing files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    if (!e.is_regular_file(ec)) continue;
    files.emplace_back(e.path().filename().string(), e.last_write_time(ec), e.file_size(ec));
  }
  return files;
}

// Adds the files that are new or changed since `before` to the directory's manifest: the figures just made, which
// the next run into the directory removes if it does not make them again.
void record_new_files(const std::filesystem::path& dir, const Listing& before) {
  std::vector<std::string> added;
  for (const auto& file : list_files(dir)) {
    if (std::find(before.begin(), before.end(), file) == before.end()) added.push_back(std::get<0>(file));
  }
  add_to_output_manifest(dir, added);
}

}  // namespace

void add_run_commands(CLI::App& app, Action& action) {
  auto opts = std::make_shared<RunOptions>();

  CLI::App* run = app.add_subcommand("run", "Run a scenario and write trajectory.csv, frames.csv and summary.json");
  run->add_option("SCENARIO", opts->scenarios, "scenario TOML file")->required()->expected(1);
  run->add_option("--out", opts->out, "output directory")->required();
  run->add_option("--set", opts->overrides, "override a scenario value: key.path=value (repeatable)");
  run->add_flag("--quiet", opts->quiet, "no progress bar and no summary line");
  run->add_flag("--plots", opts->plots,
                "render the figures into the output directory (plot_run.py with the python3 on PATH, which needs "
                "matplotlib; exit code 2 when they cannot be made)");
  run->add_flag("--animate", opts->animate,
                "render an animation of the arm and the obstacles into the output directory: animation.mp4 when "
                "ffmpeg is on PATH, else animation.gif (plot_run.py, as --plots)");
  run->add_option("--record", opts->record,
                  "rows of trajectory.csv: all, every=N (every N-th step and the last), or none (summary.json only); "
                  "the summary always uses every step (default: the scenario's [output] record, else all)");
  run->callback([opts, &action] {
    action = [opts] {
      Scenario scenario = load_scenario(opts->scenarios.front(), opts->overrides);
      RecordOptions record = scenario.record;
      if (!opts->record.empty()) {
        try {
          record = parse_record(opts->record);
        } catch (const std::invalid_argument& e) {
          throw std::runtime_error(std::string("--record: ") + e.what());
        }
      }
      if (record.none && (opts->plots || opts->animate || scenario.plots || scenario.animate)) {
        throw std::runtime_error(
            "the figures and the animation are made from trajectory.csv and frames.csv, which "
            "--record none does not write: use --record every=N");
      }
      std::optional<Plotter> plotter, animator;
      if (opts->plots || scenario.plots) {
        plotter = find_plotter(opts->plots ? "--plots" : opts->scenarios.front() + ": [output] plots = true");
      }
      if (opts->animate || scenario.animate) {
        animator = find_plotter(opts->animate ? "--animate" : opts->scenarios.front() + ": [output] animate = true");
      }
      prepare_output_dir(opts->out);  // before the run, so that a bad --out does not cost the run
      const Outcome o = run_one(std::move(scenario), opts->out, opts->quiet, record);
      if (o.run.interrupted || g_stop_requested.load()) return kExitInterrupted;  // no figures: asked to stop
      const std::string written = "trajectory.csv, frames.csv and summary.json in " + opts->out;
      const Listing before = list_files(opts->out);
      if (plotter) render_plots(*plotter, {opts->out}, opts->quiet, written);
      if (animator) {
        const std::filesystem::path file = render_animation(*animator, opts->out, opts->quiet, written);
        if (!opts->quiet) std::cout << "animation: " << file.string() << "\n";
      }
      if (plotter || animator) record_new_files(opts->out, before);
      return o.run.failures > 0 ? kExitFailedSteps : kExitOk;
    };
  });

  CLI::App* validate =
      app.add_subcommand("validate", "Check a scenario (robot, path, plugins, solver) without running it");
  validate->add_option("SCENARIO", opts->scenarios, "scenario TOML file")->required()->expected(1);
  validate->add_option("--set", opts->overrides, "override a scenario value: key.path=value (repeatable)");
  validate->callback([opts, &action] {
    action = [opts] {
      const Scenario s = load_scenario(opts->scenarios.front(), opts->overrides);
      std::cout << opts->scenarios.front() << ": ok: '" << s.name << "', robot " << s.robot->name() << " ("
                << s.robot->dof() << " joints), " << s.steps() << " steps of " << s.tau << " s, path "
                << s.path->description() << ", " << s.scheme->objectives().size() << " objective(s), "
                << s.scheme->constraints().size() << " constraint(s), engine " << s.engine->name() << "\n";
      return kExitOk;
    };
  });

  CLI::App* compare = app.add_subcommand("compare", "Run several scenarios; write a comparison table and plots");
  compare->add_option("SCENARIOS", opts->scenarios, "scenario TOML files")->required();
  compare->add_option("--out", opts->out, "output directory (one sub-directory per scenario)")->required();
  compare->add_option("--set", opts->overrides, "override applied to every scenario: key.path=value");
  compare->add_flag("--quiet", opts->quiet, "no progress bar and no summary lines");
  compare->add_flag("--no-plots", opts->no_plots, "skip the figures");
  compare->callback([opts, &action] {
    action = [opts] {
      const std::filesystem::path out = opts->out;
      std::optional<Plotter> plotter;
      if (!opts->no_plots) plotter = find_plotter("compare (--no-plots skips the figures)");
      // Every scenario is loaded before the first run, so that a bad later file is reported at once. Scenarios with
      // the same file stem (a/x.toml, b/x.toml) get distinct directories: x, x-2, ...
      std::vector<Scenario> scenarios;
      std::vector<std::string> dirs;
      for (const auto& file : opts->scenarios) {
        scenarios.push_back(load_scenario(file, opts->overrides));
        const std::string stem = std::filesystem::path(file).stem().string();
        std::string name = stem;
        for (int k = 2; std::find(dirs.begin(), dirs.end(), name) != dirs.end(); ++k) {
          name = stem + "-" + std::to_string(k);
        }
        dirs.push_back(name);
      }
      prepare_output_dir(out);
      std::string md = comparison_markdown_heading();
      std::string csv = comparison_csv_heading();
      std::vector<std::string> plot_args = {"--compare"};
      int failures = 0;
      bool interrupted = false;
      for (std::size_t i = 0; i < scenarios.size(); ++i) {
        const std::filesystem::path dir = out / dirs[i];
        const Outcome o = run_one(std::move(scenarios[i]), dir, opts->quiet);
        failures += o.run.failures;
        md += comparison_markdown_row(o.summary);
        csv += comparison_csv_row(o.summary);
        plot_args.push_back(dir.string());
        if (o.run.interrupted || g_stop_requested.load()) {
          interrupted = true;  // the runs after it do not start
          break;
        }
      }
      write_text_file(out / "comparison.md", md);
      write_text_file(out / "comparison.csv", csv);
      if (!opts->quiet) std::cout << "\n" << md << "\nwritten: " << (out / "comparison.md").string() << "\n";
      if (interrupted) {
        std::cerr << "compare: interrupted; comparison.md and comparison.csv hold the runs up to there\n";
        return kExitInterrupted;
      }
      if (plotter) {
        plot_args.insert(plot_args.end(), {"--out", out.string()});
        render_plots(*plotter, std::move(plot_args), opts->quiet, "the runs and comparison.md in " + out.string());
      }
      return failures > 0 ? kExitFailedSteps : kExitOk;
    };
  });
}

}  // namespace redres::cli

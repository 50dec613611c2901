// `redres run`, `redres validate` and `redres compare`: scenarios from the command line.

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "redres/scenario.hpp"

namespace redres::cli {

namespace {

struct RunOptions {
  std::vector<std::string> scenarios;
  std::string out;
  std::vector<std::string> overrides;
  bool quiet = false;
  bool plots = false;
  bool no_plots = false;
};

// A progress bar on stderr, shown only on a terminal, and only once a run looks like it takes over a second.
class ProgressBar {
 public:
  ProgressBar(std::string label, bool quiet)
      : label_(std::move(label)), enabled_(!quiet && isatty(STDERR_FILENO) != 0),
        start_(std::chrono::steady_clock::now()) {}
  ~ProgressBar() {
    if (shown_) std::fprintf(stderr, "\r\033[K");
  }
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void update(double fraction, double t) {
    if (!enabled_) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (!shown_ && (elapsed < 0.2 || fraction <= 0.0 || elapsed / fraction < 1.0)) return;
    shown_ = true;
    const int width = 30;
    const int done = static_cast<int>(fraction * width);
    const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
    std::fprintf(stderr, "\r%s [%.*s%*s] %3.0f%%  t = %.2f s  eta %.1f s", label_.c_str(), done,
                 "##############################", width - done, "", 100.0 * fraction, t, eta);
    std::fflush(stderr);
  }

 private:
  std::string label_;
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_;
};

std::filesystem::path tools_dir() {
  if (const char* env = std::getenv("REDRES_TOOLS_DIR")) return env;
  return REDRES_TOOLS_DIR;
}

// Renders figures with tools/plot_run.py; a missing Python or matplotlib is a warning, not a failure.
void render_plots(const std::string& args, bool quiet) {
  const std::filesystem::path script = tools_dir() / "plot_run.py";
  if (!std::filesystem::exists(script)) {
    std::cerr << "warning: " << script.string() << " not found; no plots (set REDRES_TOOLS_DIR)\n";
    return;
  }
  std::cout.flush();
  // Debian's interpreter has Debian's matplotlib and numpy; another python3 on PATH may not.
  const std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string cmd = python + " \"" + script.string() + "\" " + args + (quiet ? " --quiet" : "");
  if (std::system(cmd.c_str()) != 0) std::cerr << "warning: plotting failed: " << cmd << "\n";
}

struct Outcome {
  Scenario scenario;
  RunResult run;
};

Outcome run_one(const std::string& file, const std::vector<std::string>& overrides, const std::filesystem::path& out,
                bool quiet) {
  Outcome o{load_scenario(file, overrides), {}};
  {
    ProgressBar bar(o.scenario.name, quiet);
    o.run = simulate(o.scenario, [&bar](double f, double t) { bar.update(f, t); });
  }
  write_run(o.scenario, o.run, out);
  if (!quiet) {
    const nlohmann::json s = nlohmann::json::parse(summary_json(o.scenario, o.run));
    std::cout << std::setprecision(4) << o.scenario.name << ": " << s["steps"] << " steps of " << o.scenario.tau
              << " s, engine " << o.run.engine << ", max position error " << s["max_position_error"].get<double>()
              << " m, w " << s["manipulability"]["initial"].get<double>() << " -> "
              << s["manipulability"]["final"].get<double>() << ", " << o.run.failures << " failed steps, "
              << o.run.wall_time_s << " s -> " << out.string() << "\n";
    if (o.run.failures > 0) std::cout << "  first failure: " << o.run.first_failure << "\n";
  }
  return o;
}

std::string table_row(const std::vector<std::string>& cells) {
  std::string s = "|";
  for (const auto& c : cells) s += " " + c + " |";
  return s + "\n";
}

std::string num(double v, int precision = 6) {
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

}  // namespace

void add_run_commands(CLI::App& app, Action& action) {
  auto opts = std::make_shared<RunOptions>();

  CLI::App* run = app.add_subcommand("run", "Run a scenario and write trajectory.csv and summary.json");
  run->add_option("SCENARIO", opts->scenarios, "scenario TOML file")->required()->expected(1);
  run->add_option("--out", opts->out, "output directory")->required();
  run->add_option("--set", opts->overrides, "override a scenario value: key.path=value (repeatable)");
  run->add_flag("--quiet", opts->quiet, "no progress bar and no summary line");
  run->add_flag("--plots", opts->plots, "render the figures (tools/plot_run.py) into the output directory");
  run->callback([opts, &action] {
    action = [opts] {
      const Outcome o = run_one(opts->scenarios.front(), opts->overrides, opts->out, opts->quiet);
      if (opts->plots || o.scenario.plots) render_plots("\"" + opts->out + "\"", opts->quiet);
      return o.run.failures > 0 ? kExitFailedSteps : kExitOk;
    };
  });

  CLI::App* validate = app.add_subcommand("validate", "Check a scenario (robot, path, plugins, solver) without running it");
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
      std::filesystem::create_directories(out);
      std::string md = table_row({"scenario", "engine", "max position error (m)", "w(0)", "w(T)", "min w",
                                  "mean w", "norm theta_dot(0)", "norm theta_dot(T)", "mean iterations", "failures",
                                  "wall time (s)"});
      md += "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
      std::string csv =
          "scenario,engine,max_position_error,w_initial,w_final,w_min,w_mean,initial_joint_velocity_norm,"
          "final_joint_velocity_norm,mean_iterations,failures,wall_time_s\n";
      std::string dirs;
      int failures = 0;
      for (const auto& file : opts->scenarios) {
        const std::string name = std::filesystem::path(file).stem().string();
        const Outcome o = run_one(file, opts->overrides, out / name, opts->quiet);
        failures += o.run.failures;
        const nlohmann::json s = nlohmann::json::parse(summary_json(o.scenario, o.run));
        const std::vector<std::string> cells = {
            o.scenario.name, o.run.engine, num(s["max_position_error"].get<double>(), 4),
            num(s["manipulability"]["initial"].get<double>()), num(s["manipulability"]["final"].get<double>()),
            num(s["manipulability"]["min"].get<double>()), num(s["manipulability"]["mean"].get<double>()),
            num(s["initial_joint_velocity_norm"].get<double>(), 4), num(s["final_joint_velocity_norm"].get<double>(), 4),
            num(s["solver"]["mean_iterations"].get<double>(), 4), std::to_string(o.run.failures),
            num(o.run.wall_time_s, 3)};
        md += table_row(cells);
        for (std::size_t c = 0; c < cells.size(); ++c) csv += (c ? "," : "") + cells[c];
        csv += "\n";
        dirs += " \"" + (out / name).string() + "\"";
      }
      std::ofstream(out / "comparison.md") << md;
      std::ofstream(out / "comparison.csv") << csv;
      if (!opts->quiet) std::cout << "\n" << md << "\nwritten: " << (out / "comparison.md").string() << "\n";
      if (!opts->no_plots) render_plots("--compare" + dirs + " --out \"" + out.string() + "\"", opts->quiet);
      return failures > 0 ? kExitFailedSteps : kExitOk;
    };
  });
}

}  // namespace redres::cli

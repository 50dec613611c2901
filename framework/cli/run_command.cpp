// `redres run`, `redres validate` and `redres compare`: scenarios from the command line.

#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "commands.hpp"
#include "figures.hpp"
#include "progress.hpp"
#include "redres/plant/film.hpp"
#include "redres/plant/mujoco_model.hpp"
#include "redres/run/comparison.hpp"
#include "redres/run/run_output.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/start_check.hpp"
#include "stop_signals.hpp"
#include "view_command.hpp"

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
  bool write_mjcf = false;
  bool film = false;
  bool view = false;
  double film_fps = 25.0;
  std::string record;  // --record; empty: the scenario's [output] record
  std::string format;  // --format; empty: the scenario's [output] format
};

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
    // A run that ended early (stopped at a failed step, or interrupted) says how far it came.
    const std::size_t rows = o.run.trajectory.size();
    const long taken = rows > 0 ? static_cast<long>(rows) - 1 : 0;
    std::cout << std::setprecision(4) << s.name << ": ";
    if (s.status != "complete") std::cout << s.status << " after " << taken << " of ";
    std::cout << s.steps << " steps of " << s.tau << " s, engine " << s.solver.engine << ", max position error "
              << s.max_position_error << " m, w " << s.manipulability.initial << " -> " << s.manipulability.final
              << ", " << s.solver.failures << " failed steps, " << s.wall_time_s << " s -> " << out.string() << "\n";
    if (o.run.plant) {
      const PlantFacts& p = s.plant;
      const bool kinematic_comparison = o.scenario.plant.kinematic_comparison;
      double ratio = 0.0;
      for (std::size_t j = 0; j < p.max_torque.size(); ++j) {
        if (std::isfinite(p.effort_limit[j])) ratio = std::max(ratio, p.max_torque[j] / p.effort_limit[j]);
      }
      std::cout << "  MuJoCo plant (" << p.actuator << ", " << p.substeps << " steps of " << p.timestep
                << " s per control step): max position error " << s.max_position_error << " m";
      if (kinematic_comparison) std::cout << " (kinematic plant " << p.kinematic_max_position_error << " m)";
      std::cout << ", max torque " << 100.0 * ratio << " % of its limit, " << p.max_contacts << " contacts at most";
      if (!p.contact_pairs.empty()) std::cout << ", first at t = " << p.contact_pairs.front().first_time << " s";
      std::cout << "; " << 1e6 * p.controller_seconds / std::max(1L, p.control_steps) << " us per control step, "
                << 1e6 * p.mujoco_seconds / std::max(1L, p.mujoco_steps) << " us per MuJoCo step\n";
    }
    if (s.solver.relaxed_steps > 0) {
      std::cout << "  " << s.solver.relaxed_steps << " steps relaxed (rows missed by "
                << s.solver.max_relaxed_task_error << " at most); first: " << s.solver.first_relaxed << "\n";
    }
  }
  // The diagnosis of a failed run goes to stderr, with --quiet too: a script that checks the exit code sees why.
  if (o.summary.task_error_exceeded) {
    std::cerr << o.scenario.name << ": the task was not tracked: max position error " << o.summary.max_position_error
              << " m > [solver] max_task_error = " << o.summary.max_task_error
              << " m (summary.json: \"task_error_exceeded\": true)\n";
  }
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

// The checked start (run/start_check.hpp): every problem of theta(0) at once, exit code 2, before anything is
// written.
StartReport checked_start(Scenario& s, const std::string& file) {
  StartReport report = check_start(s);
  if (!report.ok()) throw std::runtime_error(file + ": the start is not usable:\n" + report.text());
  return report;
}

// theta0 = { ik = ... }: one line with what the inverse kinematics found (run/ik.hpp), after `prefix` (compare: the
// scenario's file).
void print_ik(const Scenario& s, const std::string& prefix = "") {
  if (!s.ik) return;
  std::ostringstream line;
  line.precision(9);
  line << prefix << "theta0 by inverse kinematics to " << s.ik_target << ": " << s.ik->summary() << "; theta0 = [";
  for (Eigen::Index j = 0; j < s.theta0.size(); ++j) line << (j ? ", " : "") << s.theta0(j);
  std::cout << line.str() << "]\n";
}

// `--film`: the MuJoCo scene of a finished run, rendered offscreen into the output directory (plant/film.hpp), from
// the recorded measured angles at the film's frame times; after the run, never inside its loop.
void film_run(const Outcome& o, const std::filesystem::path& out, double fps, bool quiet) {
  const Trajectory& tr = o.run.trajectory;
  const Scenario& s = o.scenario;
  const int n = s.robot->dof();
  std::vector<std::size_t> theta(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) theta[static_cast<std::size_t>(j)] = tr.column("theta_" + std::to_string(j + 1));
  const std::vector<ShapeSpec> obstacles = scenario_obstacles(s, true);
  const double last = tr.at(tr.size() - 1, "t");
  std::vector<FilmFrame> frames;
  for (const double t : film_times(last, fps)) {
    const auto row = std::min(tr.size() - 1, static_cast<std::size_t>(std::lround(t / s.tau)));
    FilmFrame f;
    f.t = t;
    f.qpos.resize(n);
    for (int j = 0; j < n; ++j) f.qpos(j) = tr(row, theta[static_cast<std::size_t>(j)]);
    f.mocap_pos = mjcf_mocap_positions(obstacles, t);
    frames.push_back(std::move(f));
  }
  FilmOptions options;
  options.fps = fps;
  FilmReport report;
  {
    ProgressBar bar(s.name + " film", quiet);
    report = film(o.run.plant->mjcf, frames, out, options, [&bar](int done, int total) {
      char where[32];
      std::snprintf(where, sizeof where, "%d/%d frames", done, total);
      bar.update(static_cast<double>(done) / total, where);
    });
  }
  if (!quiet) {
    std::cout << "film: " << report.file.string() << " (" << report.frames << " frames at " << fps << " per second, "
              << std::setprecision(3) << report.seconds_per_frame << " s per frame";
    if (!report.frames_dir.empty()) std::cout << "; PNG frames in " << report.frames_dir.string();
    std::cout << ")\n";
  }
}

// `redres run`: one scenario, its files, and the figures or the animation asked for.
int run_scenario(const RunOptions& options) {
  const RunOptions* const opts = &options;
  Scenario scenario = load_scenario(opts->scenarios.front(), opts->overrides);
  (void)checked_start(scenario, opts->scenarios.front());
  if (!opts->quiet) print_ik(scenario);
  RecordOptions record = scenario.record;
  if (!opts->record.empty()) {
    try {
      record = parse_record(opts->record);
      record.format = scenario.record.format;
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(std::string("--record: ") + e.what());
    }
  }
  if (!opts->format.empty()) {
    try {
      record.format = parse_format(opts->format);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(std::string("--format: ") + e.what());
    }
  }
  if (record.none && (opts->plots || opts->animate || opts->view || scenario.plots || scenario.animate)) {
    throw std::runtime_error(
        "the figures, the animation and the view are made from trajectory.csv and frames.csv, which "
        "--record none does not write: use --record every=N");
  }
  if (opts->view && record.format == TrajectoryFormat::kHdf5) {
    throw std::runtime_error("--view reads trajectory.csv and frames.csv, which --format hdf5 does not write");
  }
  std::optional<Plotter> plotter, animator;
  if (opts->plots || scenario.plots) {
    plotter = find_plotter(opts->plots ? "--plots" : opts->scenarios.front() + ": [output] plots = true");
  }
  if (opts->animate || scenario.animate) {
    animator = find_plotter(opts->animate ? "--animate" : opts->scenarios.front() + ": [output] animate = true");
  }
  if (opts->film) {
    if (scenario.plant.kind != "mujoco") {
      throw std::runtime_error("--film renders the MuJoCo scene: scenario '" + scenario.name +
                               "' runs on the kinematic plant; add --set plant.kind=mujoco");
    }
    if (!(opts->film_fps > 0.0 && opts->film_fps <= 1000.0))
      throw std::runtime_error("--film-fps: expected 0 < fps <= 1000 frames per second of simulated time");
  }
  prepare_output_dir(opts->out);  // before the run, so that a bad --out does not cost the run
  if (opts->film) {               // film() replaces nothing: say so before the run, not after it
    for (const char* name : {"film.mp4", "film.gif", "film_frames"}) {
      const std::filesystem::path p = std::filesystem::path(opts->out) / name;
      if (std::filesystem::exists(std::filesystem::symlink_status(p))) {
        throw std::runtime_error("--film: " + p.string() +
                                 " exists (an earlier film?); a film replaces nothing: remove it or use another --out");
      }
    }
  }
  if (opts->write_mjcf) {
    if (scenario.plant.kind != "mujoco") {
      throw std::runtime_error("--write-mjcf: scenario '" + scenario.name +
                               "' runs on the kinematic plant; add --set plant.kind=mujoco");
    }
    const std::filesystem::path model = std::filesystem::path(opts->out) / "mujoco_model.xml";
    // An earlier model redres wrote here (in the manifest, unchanged since) is replaced; any other file of that name
    // is the user's and stays, as --film's do.
    remove_earlier_output(opts->out, "mujoco_model.xml");
    if (std::filesystem::exists(std::filesystem::symlink_status(model))) {
      throw std::runtime_error("--write-mjcf: " + model.string() +
                               " exists, and redres did not write it there (or it changed since): redres replaces "
                               "nothing it did not write; remove it or use another --out");
    }
    write_text_file(model, scenario_mjcf(scenario));  // before the run: MuJoCo's own viewer can open it at once
    if (!opts->quiet) std::cout << "MuJoCo model: " << model.string() << "\n";
  }
  const Outcome o = run_one(std::move(scenario), opts->out, opts->quiet, record);
  // Listed after the run, whose own list of outputs would otherwise take it for an earlier run's and remove it.
  if (opts->write_mjcf) add_to_output_manifest(opts->out, {"mujoco_model.xml"});
  if (o.run.interrupted || g_stop_requested.load()) return kExitInterrupted;  // no figures: asked to stop
  const std::string written =
      std::string(record.format == TrajectoryFormat::kHdf5 ? "trajectory.h5" : "trajectory.csv, frames.csv") +
      " and summary.json in " + opts->out;
  const Listing before = list_files(opts->out);
  if (plotter) render_plots(*plotter, {opts->out}, opts->quiet, written);
  if (animator) {
    const std::filesystem::path file = render_animation(*animator, opts->out, opts->quiet, written);
    if (!opts->quiet) std::cout << "animation: " << file.string() << "\n";
  }
  if (opts->film) film_run(o, opts->out, opts->film_fps, opts->quiet);
  if (plotter || animator || opts->film) record_new_files(opts->out, before);
  if (opts->view) print_view_report(write_run_view({opts->out}, opts->out, ViewOptions{}), opts->quiet);
  return o.run.failures > 0 || o.summary.task_error_exceeded ? kExitFailedSteps : kExitOk;
}

// `redres validate`: loads a scenario (every check of a run's set-up) and says what it holds.
int validate_scenario(const RunOptions& options) {
  const RunOptions* const opts = &options;
  Scenario s = load_scenario(opts->scenarios.front(), opts->overrides);
  const StartReport start = checked_start(s, opts->scenarios.front());
  std::cout << opts->scenarios.front() << ": ok: '" << s.name << "', robot " << s.robot->name() << " ("
            << s.robot->dof() << " joints), " << s.steps() << " steps of " << s.tau << " s, path "
            << s.path->description() << ", " << s.scheme->objectives().size() << " objective(s), "
            << s.scheme->constraints().size() << " constraint(s), engine " << s.engine.type << "\n";
  print_ik(s);
  if (s.plant.kind == "mujoco") {
    const auto substeps = std::lround(s.tau / s.plant.timestep);
    std::cout << "plant: MuJoCo, " << enum_names(PlantActuator{})[static_cast<std::size_t>(s.plant.actuator)].second
              << (s.plant.gravity_compensation ? " with" : " without") << " gravity compensation, " << substeps
              << " MuJoCo step" << (substeps == 1 ? "" : "s") << " of " << s.plant.timestep << " s per control step"
              << (s.plant.delay > 0.0 ? ", measurement delay " + std::to_string(s.plant.delay) + " s" : "") << "\n";
  }
  std::cout << "start: within limits, no collision, task rows' smallest singular value " << start.sigma_min
            << " (w = " << start.w << "), path " << start.path_offset << " m from the end effector (checked in "
            << start.seconds << " s)\n";
  return kExitOk;
}

// `redres compare`: every scenario loaded first, then each run into its own directory, and the comparison table.
int compare_scenarios(const RunOptions& options) {
  const RunOptions* const opts = &options;
  const std::filesystem::path out = opts->out;
  std::optional<Plotter> plotter;
  if (!opts->no_plots) plotter = find_plotter("compare (--no-plots skips the figures)");
  // Every scenario is loaded before the first run, so that a bad later file is reported at once. Scenarios with
  // the same file stem (a/x.toml, b/x.toml) get distinct directories: x, x-2, ...
  std::vector<Scenario> scenarios;
  std::vector<std::string> dirs;
  for (const auto& file : opts->scenarios) {
    scenarios.push_back(load_scenario(file, opts->overrides));
    (void)checked_start(scenarios.back(), file);
    if (!opts->quiet) print_ik(scenarios.back(), file + ": ");
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
    failures += o.run.failures + (o.summary.task_error_exceeded ? 1 : 0);
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
  if (opts->view) {
    std::vector<std::filesystem::path> run_dirs;
    for (const std::string& d : dirs) run_dirs.push_back(out / d);
    print_view_report(write_run_view(run_dirs, out, ViewOptions{}), opts->quiet);
  }
  return failures > 0 ? kExitFailedSteps : kExitOk;
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
  run->add_flag("--write-mjcf", opts->write_mjcf,
                "write the MuJoCo model the run steps ([plant] kind = \"mujoco\") to mujoco_model.xml in the output "
                "directory, for MuJoCo's own viewer");
  run->add_flag("--film", opts->film,
                "render the MuJoCo scene of the run ([plant] kind = \"mujoco\") offscreen after it: film.mp4 when "
                "ffmpeg is on PATH, else PNG frames in film_frames/ and film.gif (docs/plant.md)");
  run->add_flag("--view", opts->view,
                "write view.html into the output directory after the run: the run replayed in 3-D with its plots, "
                "one file for any browser (docs/viewer.md)");
  run->add_option("--film-fps", opts->film_fps, "frames per second of simulated time for --film (default 25)");
  run->add_option("--record", opts->record,
                  "rows of trajectory.csv: all, every=N (every N-th step and the last), or none (summary.json only); "
                  "the summary always uses every step (default: the scenario's [output] record, else all)");
  run->add_option("--format", opts->format,
                  "the recorded tables' file: csv (trajectory.csv, frames.csv) or hdf5 (one trajectory.h5, read with "
                  "h5py; default: the scenario's [output] format, else csv)");
  run->callback([opts, &action] { action = [opts] { return run_scenario(*opts); }; });

  CLI::App* validate =
      app.add_subcommand("validate", "Check a scenario (robot, path, plugins, solver) without running it");
  validate->add_option("SCENARIO", opts->scenarios, "scenario TOML file")->required()->expected(1);
  validate->add_option("--set", opts->overrides, "override a scenario value: key.path=value (repeatable)");
  validate->callback([opts, &action] { action = [opts] { return validate_scenario(*opts); }; });

  CLI::App* compare = app.add_subcommand("compare", "Run several scenarios; write a comparison table and plots");
  compare->add_option("SCENARIOS", opts->scenarios, "scenario TOML files")->required();
  compare->add_option("--out", opts->out, "output directory (one sub-directory per scenario)")->required();
  compare->add_option("--set", opts->overrides, "override applied to every scenario: key.path=value");
  compare->add_flag("--quiet", opts->quiet, "no progress bar and no summary lines");
  compare->add_flag("--no-plots", opts->no_plots, "skip the figures");
  compare->add_flag("--view", opts->view,
                    "write view.html into the output directory: the runs overlaid in 3-D with their plots "
                    "(docs/viewer.md)");
  compare->callback([opts, &action] { action = [opts] { return compare_scenarios(*opts); }; });
}

}  // namespace redres::cli

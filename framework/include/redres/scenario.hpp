#pragma once
/// @file
/// Scenarios: a robot, an initial configuration, a duration and step, a desired path, a scheme (objectives and
/// constraints), solver settings and output options, read from one TOML file; and the simulation that runs them.
///
/// Scenario file (paths resolve relative to the file that names them):
///
///   name = "paper_r_tvcmm"                      # default: the file's stem
///   robot = "../robots/paper_pushrod_6dof.toml"
///   theta0 = ["pi/4", "pi/12", ...]            # numbers or formulas; default: the robot's home
///   duration = 40.0                             # T (s)
///   step = 0.01                                 # tau (s)
///   integrator = "euler"                        # or "heun" (second order)
///   [path]        type = "letter_r", ...       # see path.hpp
///   [[objectives]] ... [[constraints]] ...      # see plugin.hpp
///   [solver]      engine = "projection", ...    # see lvi.hpp
///   [output]      plots = false                 # render the figures with tools/plot_run.py after a run

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "redres/controller.hpp"

namespace redres {

/// Integration of theta_dot.
enum class Integrator { kEuler, kHeun };

/// A loaded scenario. Owns everything a run needs.
struct Scenario {
  std::string name;                       //!< scenario name
  std::string source;                     //!< file it came from
  std::unique_ptr<RobotModel> robot;      //!< the robot
  Eigen::VectorXd theta0;                 //!< theta(0)
  double duration = 0.0;                  //!< T (s)
  double tau = 0.0;                       //!< step (s)
  Integrator integrator = Integrator::kEuler;  //!< integrator
  std::unique_ptr<Path> path;             //!< r_d(t)
  std::unique_ptr<Scheme> scheme;         //!< objectives and constraints
  std::unique_ptr<LviEngine> engine;      //!< solver
  bool plots = false;                     //!< [output] plots
  Eigen::VectorXd safety_margin;          //!< joint_angle_margin's margin per joint (zeros without it)

  /// Number of control steps N = round(T / tau); the run records N + 1 rows, t = 0 .. T.
  [[nodiscard]] int steps() const;
};

/// Loads and checks a scenario. `overrides` are "key.path=value" strings (TOML values; a bare word is a string;
/// array entries by 0-based index, e.g. "objectives.1.p=1"). Every problem is a ConfigError at file:line:col.
[[nodiscard]] Scenario load_scenario(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});

/// The recorded run: one row per step with the columns of DESIGN section 6 (plus the velocity-law limits), and
/// the summary figures.
struct RunResult {
  std::vector<std::string> columns;  //!< CSV header
  std::vector<double> rows;          //!< row-major, rows() x columns.size()
  int failures = 0;                  //!< steps whose solve was not `solved`
  std::string first_failure;         //!< "t = ...: <status>: <diagnosis>" of the first failed step
  double wall_time_s = 0.0;          //!< run time (s)
  std::string engine;                //!< engine(s) that ran, e.g. "projection" or "newton+projection"

  /// Number of rows.
  [[nodiscard]] std::size_t size() const { return columns.empty() ? 0 : rows.size() / columns.size(); }
  /// Value at (row, column name); throws std::out_of_range for an unknown column.
  [[nodiscard]] double at(std::size_t row, const std::string& column) const;
  /// Index of a column; throws std::out_of_range.
  [[nodiscard]] std::size_t column(const std::string& name) const;
};

/// Progress of a run: fraction done in [0, 1] and the simulated time.
using ProgressCallback = std::function<void(double fraction, double t)>;

/// Runs a scenario from theta0 over [0, T] with step tau. Allocation happens before the loop only.
[[nodiscard]] RunResult simulate(Scenario& scenario, const ProgressCallback& progress = {});

/// The summary of DESIGN section 6 (plus robot and scenario facts the plotting tools need), as JSON text.
[[nodiscard]] std::string summary_json(const Scenario& scenario, const RunResult& run);

/// Writes DIR/trajectory.csv and DIR/summary.json (creating DIR).
void write_run(const Scenario& scenario, const RunResult& run, const std::filesystem::path& dir);

}  // namespace redres

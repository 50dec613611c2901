#pragma once
/// @file
/// Scenarios: a robot, an initial configuration, a duration and step, a desired path, a scheme (objectives and
/// constraints), solver settings and output options, read from one TOML file. simulation.hpp runs them,
/// run_summary.hpp summarises a run, run_output.hpp writes it.
///
/// Scenario file (paths resolve relative to the file that names them):
///
///   name = "paper_r_tvcmm"                      # default: the file's stem
///   robot = "../robots/paper_pushrod_6dof.toml"
///   theta0 = ["pi/4", "pi/12", ...]            # numbers or formulas; default: the robot's home
///   theta0 = { ik = { position = [...], rpy = [...] }, seed = "home" }   # or by inverse kinematics (ik.hpp)
///   duration = 40.0                             # T (s)
///   step = 0.01                                 # tau (s)
///   integrator = "euler"                        # or "heun" (second order)
///   [path]        type = "letter_r", ...       # see path.hpp
///   [[objectives]] ... [[constraints]] ...      # see plugin.hpp
///   [solver]      engine = "projection", ...    # see lvi.hpp
///   [output]      record = "all"                # rows of trajectory.csv: "all", "none" or "every=N"
///                 plots = false                 # render the figures with tools/plot_run.py after a run
///                 animate = false               # and/or the animation (animation.mp4 or animation.gif)

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "redres/config/config.hpp"
#include "redres/control/controller.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/model/collision.hpp"
#include "redres/plant/plant.hpp"
#include "redres/run/ik.hpp"
#include "redres/run/record.hpp"

namespace redres {

/// Integration of theta_dot.
enum class Integrator { kEuler, kHeun };

/// A loaded scenario: a value that runs only read. It owns the robot, the path and the scheme, which are immutable;
/// everything a run writes (the controller, its engine and warm start, the plugins' data, the plant) is made by the
/// run, so that runs of one scenario may go on at once in several threads.
struct Scenario {
  std::string name;                   //!< scenario name
  std::string label;                  //!< the run's name in legends and tables (default: name)
  std::string source;                 //!< file it came from
  std::unique_ptr<RobotModel> robot;  //!< the robot
  Eigen::VectorXd theta0;             //!< theta(0)
  /// theta0 = { ik = ... }: what the inverse kinematics found (theta0 is its answer; docs/ik.md); empty otherwise.
  std::optional<IkResult> ik;
  std::string ik_target;                       //!< the IK's target and seed, in words (empty without an IK)
  double duration = 0.0;                       //!< T (s)
  double tau = 0.0;                            //!< step (s)
  Integrator integrator = Integrator::kEuler;  //!< integrator
  std::unique_ptr<Path> path;                  //!< r_d(t)
  std::unique_ptr<Scheme> scheme;              //!< objectives and constraints
  /// [solver]: the engine, as a value; each run and each controller makes its own (EngineSpec::make()).
  EngineSpec engine;
  /// [orientation] turn: the rotation (a world-frame rotation vector, rad; planar: its z) the end effector turns
  /// through over the run, from the orientation it has at t = 0 (Controller::set_orientation_turn); zero: hold it.
  Eigen::Vector3d orientation_turn = Eigen::Vector3d::Zero();
  /// [solver] on_infeasible: what a step whose QP is not solved does (control/failure_policy.hpp); a failed step never
  /// integrates the engine's unconverged iterate, and under kStop the run ends there, with every row up to that step.
  /// The file's default: kBrake for a robot with acceleration limits, else kRelax.
  FailurePolicy on_infeasible = FailurePolicy::kRelax;
  bool on_infeasible_given = false;  //!< the file (or --set) named on_infeasible; the start check reads it
  double relax_weight = 1e4;     //!< [solver] relax_weight: rho of the elastic QP under "relax" and "brake" (1 to 1e8)
  double recover_error = 1e-3;   //!< [solver] recover_error (m): under "brake", the elastic QP goes first above it
  double max_task_error = 0.01;  //!< [solver] max_task_error (m): a larger position error makes the run no success
  RecordOptions record;          //!< [output] record: "all", "none" or "every=N" (rows of trajectory.csv)
  bool plots = false;            //!< [output] plots
  bool animate = false;          //!< [output] animate
  /// [plant]: what the commands drive, the kinematic plant (default) or MuJoCo (docs/plant.md). For MuJoCo, its
  /// timestep is resolved (never 0) and the gains checked against the robot when the scenario is loaded.
  PlantConfig plant;

  /// Number of control steps N = round(T / tau); the run records N + 1 rows, t = 0 .. T. Throws
  /// std::invalid_argument when T / tau is not in [1, kMaxSteps].
  [[nodiscard]] int steps() const;
};

/// The obstacles of the scenario's collision constraints (world-frame shapes at t = 0, each with its velocity if it
/// moves; PluginOutput::scene_obstacles()), inactive constraints' too when `inactive` (a physics plant's world has
/// them whether the controller avoids them or not).
[[nodiscard]] std::vector<ShapeSpec> scenario_obstacles(const Scenario& s, bool inactive);

/// The MuJoCo model a run of `s` on the MuJoCo plant steps (mjcf_from_robot() with the scenario's [plant] and every
/// obstacle of its collision constraints); std::invalid_argument when the scenario's plant is not "mujoco".
[[nodiscard]] std::string scenario_mjcf(const Scenario& s);

/// The most control steps a run may have (duration / step).
inline constexpr double kMaxSteps = 10'000'000;
/// The most memory a run's recorded table may take (2 GiB): rows x columns x 8 bytes, made before the loop.
inline constexpr double kMaxTableBytes = 2.0 * 1024 * 1024 * 1024;

/// The [solver] table's keys that the run reads besides the engine's (on_infeasible, relax_weight), for listings.
[[nodiscard]] const std::vector<KeyInfo>& solver_policy_keys();

/// Every table of a scenario file with its keys (from the schemas the reader reads them with), for `redres keys` and
/// docs/scenario_format.md. The plugins' tables ([path], [[objectives]], [[constraints]], the engine's [solver]
/// keys) are listed by `redres plugins`.
[[nodiscard]] const std::vector<KeyTable>& scenario_key_tables();

/// Loads and checks a scenario. `overrides` are "key.path=value" strings (TOML values; a bare word is a string;
/// array entries by 0-based index, e.g. "objectives.1.p=1"). Every problem is a ConfigError at file:line:col.
[[nodiscard]] Scenario load_scenario(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});

}  // namespace redres

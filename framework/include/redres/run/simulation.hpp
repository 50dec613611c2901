#pragma once
/// @file
/// The simulation of a scenario: from theta(0), one Controller step per control step, applied to the scenario's plant
/// (run/plants.hpp: the kinematic plant integrates with Euler's or Heun's method; the MuJoCo plant simulates the arm),
/// each step recorded into a Trajectory (columns in docs/output_formats.md).

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "redres/plant/mujoco_plant.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/trajectory.hpp"

namespace redres {

/// What a run on the MuJoCo plant ([plant] kind = "mujoco") recorded besides its trajectory (docs/plant.md).
struct PlantFacts {
  std::string actuator;   //!< "velocity_servo", "impedance" or "ideal_velocity"
  double timestep = 0.0;  //!< MuJoCo's time step (s)
  int substeps = 0;       //!< MuJoCo steps per control step
  double delay = 0.0;     //!< the measurement's delay (s)
  /// Per joint over every MuJoCo step: the largest |torque| (N m or N), the joint's effort limit (NaN when it has
  /// none), and the largest |torque rate| (N m/s or N/s).
  std::vector<double> max_torque, effort_limit, max_torque_rate;
  int max_contacts = 0;                         //!< the most contacts (involving the robot) at any MuJoCo step
  double deepest_penetration = 0.0;             //!< m
  std::vector<PlantContactPair> contact_pairs;  //!< every pair that touched, by first time
  /// With `[plant] kinematic_comparison = true`: the same scenario on the kinematic plant, its largest position
  /// error (m), beside this run's (the summary's); 0 otherwise.
  double kinematic_max_position_error = 0.0;
  double controller_seconds = 0.0;  //!< wall time in Controller::step over the run
  double mujoco_seconds = 0.0;      //!< wall time in MuJoCo's steps over the run
  long control_steps = 0, mujoco_steps = 0;
  std::string mjcf;  //!< the model MuJoCo ran (`--write-mjcf`, the film)
};

/// A finished run: the recorded trajectory and what the loop saw.
struct RunResult {
  Trajectory trajectory;  //!< one row per step, t = 0 .. T
  int failures = 0;  //!< steps whose solve failed (not `solved` or `relaxed`; both Heun stages count) or whose state a
                     //!< constraint found violated (Constraint::violated(), e.g. bodies in collision)
  std::string first_failure;              //!< "t = ...: <status>: <diagnosis>" of the first failed solve
  double wall_time_s = 0.0;               //!< time spent in the loop (s)
  std::vector<std::string_view> engines;  //!< engines that ran, in order of first use (a fallback adds one)
  bool stopped = false;                   //!< ended at the first failed step ([solver] on_infeasible = "stop")
  int held_steps = 0;                     //!< steps whose solve failed, held with theta_dot = 0
  int relaxed_steps = 0;                  //!< steps solved with the rows relaxed (on_infeasible = "relax")
  int braked_steps = 0;                   //!< failed steps that braked (on_infeasible = "brake"; counted in failures)
  double max_relaxed_task_error = 0.0;    //!< the largest task_row_error of a relaxed step
  /// The motion the arm was asked for, per joint, over every applied command (Heun's average; a held step's zero):
  /// the largest |acceleration| (rad/s^2) and |jerk| (rad/s^3), the largest excursion beyond the robot's acceleration
  /// and jerk limits at the step's theta (0 when never; empty where the robot gives no such limits), and the steps
  /// over them (by more than 1e-9 (1 + |limit|)).
  std::vector<double> max_joint_acceleration, max_joint_jerk;
  std::vector<double> max_joint_acceleration_violation, max_joint_jerk_violation;
  int steps_over_acceleration_limit = 0, steps_over_jerk_limit = 0;
  std::string first_relaxed;        //!< "t = ...: <diagnosis>" of the first relaxed step
  double controller_seconds = 0.0;  //!< wall time in Controller::step over the run (s), for plants that time it
  long control_steps = 0;           //!< the controller's steps
  bool interrupted = false;         //!< ended early because `stop` was set (SIGINT or SIGTERM in the CLI)
  /// The plugins' data as the run's last step left it (what their summaries read, e.g. FCL's failures).
  std::shared_ptr<const SchemeData> plugin_data;
  /// What the plant recorded besides the table (the MuJoCo plant's figures); empty on the kinematic plant.
  std::optional<PlantFacts> plant;

  /// "projection", or "newton+projection" when a fallback ran.
  [[nodiscard]] std::string engine() const;
};

/// Progress of a run: fraction done in [0, 1] and the simulated time.
using ProgressCallback = std::function<void(double fraction, double t)>;

/// The number of columns a run of `scenario` records (the standard ones and the plugins' own).
[[nodiscard]] std::size_t trajectory_width(const Scenario& scenario);

/// Runs a scenario from theta0 over [0, T] with step tau. Everything is allocated before the loop. The scenario is
/// only read (the run makes its controller, engine and plant), so runs of one scenario may go on in several threads.
[[nodiscard]] RunResult simulate(const Scenario& scenario, const ProgressCallback& progress = {});

/// The same into `run`, which is overwritten; its trajectory's storage is reused when it has room for this run, so
/// that repeated runs (a sweep's worker, a benchmark) skip the allocation and the first touch of the table's pages.
/// `stop`, when given, is read after each recorded step: once it is true the run ends there, with every row up to
/// that step and `interrupted` set (a signal handler may set it).
void simulate(const Scenario& scenario, RunResult& run, const ProgressCallback& progress = {},
              const std::atomic<bool>* stop = nullptr);

}  // namespace redres

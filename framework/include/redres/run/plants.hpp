#pragma once
/// @file
/// The plant interface (docs/plant.md): what a run's commands drive. simulate() runs one loop for every plant: at each
/// control step it reads the plant's state, steps the controller, records the row, and lets the plant apply the step's
/// command over the control period. A plant is made by name (the scenario's `[plant] kind`) from the plant registry;
/// two are built in: `kinematic` (redres's own integration, the default; run/kinematic_plant.cpp) and `mujoco` (a
/// MuJoCo physics plant; run/mujoco_run_plant.cpp). A new plant is one source file: a class derived from Plant and
/// one `plant_registry().add(...)`.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace redres {

struct Scenario;
struct StepOutput;
struct RunResult;
class TableReader;

/// What a plant may ask of the run within one control step.
class PlantStep {
 public:
  /// Solves the step again at another state (Heun's second stage: Controller::reevaluate) and notes its outcome as
  /// the run notes every step's. Null when the run must end there (a failed stage under on_infeasible = "stop").
  virtual const StepOutput* solve_again(const Eigen::VectorXd& theta, double t) = 0;
  /// The command the plant applied over the step, when it is not the step's own (Heun's average of its two stages):
  /// the next step's theta_dot_prev.
  virtual void set_applied(const Eigen::VectorXd& theta_dot) = 0;

 protected:
  ~PlantStep() = default;
};

/// A plant for one run, made by its registration's `make` before the loop (where it may allocate); nothing it does
/// per step allocates.
class Plant {
 public:
  virtual ~Plant() = default;
  /// The joint angles the controller reads at this control step (n).
  [[nodiscard]] virtual const Eigen::VectorXd& theta() const = 0;
  /// The joint velocities it measures (n), or null when it measures none (the controller then reads its own previous
  /// command as the velocity).
  [[nodiscard]] virtual const Eigen::VectorXd* theta_dot() const = 0;
  /// Its own values of this step's row (as many as its registration's `columns`), at the state theta() gave.
  virtual void record(double* values) { (void)values; }
  /// Applies the step's outcome `out` (theta_dot; zero for a held step) over one control period from time t, and
  /// writes into `applied` the command the arm followed over it (the run's motion figures read it). Returns false
  /// when the run ends at this step (its row stays): a second stage under on_infeasible = "stop" failed, or the plant
  /// itself failed, and then `failure` says why.
  virtual bool advance(const StepOutput& out, double t, PlantStep& step, Eigen::VectorXd& applied,
                       std::string& failure) = 0;
  /// After the loop: the plant's own figures into the run's result (RunResult::plant).
  virtual void finish(const Scenario& scenario, RunResult& run) {
    (void)scenario;
    (void)run;
  }
};

/// A kind of plant: its name (`[plant] kind`), what it is, the columns it adds to a run's table, the check of a
/// scenario's `[plant]` table against it, and its factory.
struct PlantType {
  std::string name;
  std::string description;
  /// Its columns at the end of a run's row, for `scenario` (none by default).
  std::function<std::vector<std::string>(const Scenario&)> columns;
  /// Checks the scenario's `[plant]` table `table` (the other keys of PlantConfig, read already) for this plant, and
  /// completes it (e.g. a time step made explicit); reports through table.fail(key, ...).
  std::function<void(const TableReader& table, Scenario& scenario)> check;
  /// The plant of a run of `scenario`, at its theta0.
  std::function<std::unique_ptr<Plant>(const Scenario& scenario)> make;
  /// Whether the loop times each controller step for it (RunResult::controller_seconds; two clock reads per step).
  bool times_controller = false;
};

/// The plants by name.
class PlantRegistry {
 public:
  /// Registers a plant (its name unique; `make` set); returns true, for a static initialiser.
  bool add(PlantType type);
  /// The plant named `name`, or null.
  [[nodiscard]] const PlantType* find(const std::string& name) const;
  /// The plant named `name`; throws std::invalid_argument naming the plants there are.
  [[nodiscard]] const PlantType& at(const std::string& name) const;
  /// Every plant, in the order of registration.
  [[nodiscard]] const std::vector<PlantType>& types() const noexcept { return types_; }

 private:
  std::vector<PlantType> types_;
};

/// The process-wide plant registry.
PlantRegistry& plant_registry();

}  // namespace redres

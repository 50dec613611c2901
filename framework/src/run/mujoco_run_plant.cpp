// The MuJoCo plant of a run (docs/plant.md, "The plant"): each control step the controller reads the measured joint
// angles and velocities, and the command is held over the plant's MuJoCo steps (plant/mujoco_plant.hpp). Its columns:
// measured_theta_dot_1..n, torque_1..n, contacts, penetration; its figures: RunResult::plant.

#include <algorithm>
#include <chrono>
#include <limits>
#include <stdexcept>
#include <utility>

#include "redres/control/controller.hpp"
#include "redres/plant/mujoco_model.hpp"
#include "redres/plant/mujoco_plant.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"
#include "run/builtin_plants.hpp"

namespace redres {

namespace {

class MujocoRunPlant final : public Plant {
 public:
  explicit MujocoRunPlant(const Scenario& s)
      : plant_(*s.robot, s.plant, s.tau, scenario_obstacles(s, true), s.theta0),
        n_(s.robot->dof()),
        command_(Eigen::VectorXd::Zero(s.robot->dof())) {}

  [[nodiscard]] const Eigen::VectorXd& theta() const override { return plant_.theta(); }
  [[nodiscard]] const Eigen::VectorXd* theta_dot() const override { return &plant_.theta_dot(); }

  void record(double* values) override {
    std::copy_n(plant_.theta_dot().data(), n_, values);
    std::copy_n(plant_.torque().data(), n_, values + n_);
    values[2 * n_] = plant_.contacts();
    values[2 * n_ + 1] = plant_.penetration();
    max_contacts_ = std::max(max_contacts_, values[2 * n_]);
    deepest_ = std::max(deepest_, values[2 * n_ + 1]);
  }

  bool advance(const StepOutput& out, double t, PlantStep& /*step*/, Eigen::VectorXd& applied,
               std::string& failure) override {
    if (moves(out.info.status)) {
      command_ = out.theta_dot;
    } else {
      command_.setZero();  // held: the servo is asked for theta_dot = 0
    }
    try {
      plant_.advance(command_, t);
    } catch (const std::runtime_error& e) {
      // MuJoCo failed (diverged, or an error inside it): the run ends here, with every row up to this step.
      failure = std::string("MuJoCo plant: ") + e.what();
      return false;
    }
    applied = command_;
    return true;
  }

  void finish(const Scenario& s, RunResult& run) override {
    PlantFacts facts;
    facts.actuator = std::string(enum_names(PlantActuator{})[static_cast<std::size_t>(s.plant.actuator)].second);
    facts.timestep = plant_.timestep();
    facts.substeps = plant_.substeps();
    facts.delay = s.plant.delay;
    facts.max_torque.assign(plant_.max_torque().data(), plant_.max_torque().data() + n_);
    facts.max_torque_rate.assign(plant_.max_torque_rate().data(), plant_.max_torque_rate().data() + n_);
    for (int j = 0; j < n_; ++j) {
      facts.effort_limit.push_back(s.robot->joint(j).effort_limit.value_or(std::numeric_limits<double>::quiet_NaN()));
    }
    facts.max_contacts = static_cast<int>(max_contacts_);
    facts.deepest_penetration = deepest_;
    facts.contact_pairs = plant_.contact_pairs();
    facts.controller_seconds = run.controller_seconds;
    facts.control_steps = run.control_steps;
    facts.mujoco_seconds = plant_.mujoco_seconds();
    facts.mujoco_steps = plant_.mujoco_steps();
    facts.mjcf = plant_.mjcf();
    run.plant = std::move(facts);
  }

 private:
  MujocoPlant plant_;
  int n_;
  Eigen::VectorXd command_;
  double max_contacts_ = 0.0, deepest_ = 0.0;  // over the rows recorded
};

// The [plant] table of a MuJoCo run against the rest of the scenario: MuJoCo built in, the robot's mass properties,
// the gains' sizes, the control period and the delay whole numbers of MuJoCo time steps (which becomes explicit),
// obstacles MuJoCo can hold.
void check_mujoco(const TableReader& r, Scenario& s) {
  PlantConfig& p = s.plant;
  if (!mujoco_available()) r.fail("kind", "\"mujoco\": " + mujoco_missing());
  const int n = s.robot->dof();
  for (const auto& [key, gains] : {std::pair{"kv", &p.kv}, std::pair{"kp", &p.kp}, std::pair{"kd", &p.kd}}) {
    try {
      (void)gains->resolve(n, key);
    } catch (const FieldError& e) {
      r.fail(key, e.message());
    }
  }
  try {
    p.timestep = plant_timing(p, s.tau).timestep;
  } catch (const FieldError& e) {
    // A default time step that does not divide the period is the table's `kind` choice: reported there.
    r.fail(e.key() == "timestep" && !r.has("timestep") ? "kind" : e.key(), e.message());
  }
  try {
    (void)scenario_mjcf(s);
  } catch (const std::invalid_argument& e) {
    r.fail("kind", std::string("\"mujoco\": ") + e.what());
  }
}

}  // namespace

PlantType mujoco_plant_type() {
  PlantType t;
  t.name = "mujoco";
  t.description = "a MuJoCo physics plant: mass, actuators, gravity and contacts; the controller reads measured states";
  t.columns = [](const Scenario& s) {
    const int n = s.robot->dof();
    std::vector<std::string> columns;
    for (int j = 1; j <= n; ++j) columns.push_back("measured_theta_dot_" + std::to_string(j));
    for (int j = 1; j <= n; ++j) columns.push_back("torque_" + std::to_string(j));
    columns.push_back("contacts");
    columns.push_back("penetration");
    return columns;
  };
  t.check = check_mujoco;
  t.make = [](const Scenario& s) -> std::unique_ptr<Plant> { return std::make_unique<MujocoRunPlant>(s); };
  t.times_controller = true;  // its summary compares the controller's time with MuJoCo's
  return t;
}

}  // namespace redres

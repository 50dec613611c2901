#pragma once
// What the scenario reader's files share (private to run/). load_scenario (scenario.cpp) reads a file's top level
// through ScenarioReading, whose schema (scenario_schema.cpp) names every key; its keys' readers call on the start
// configuration's (scenario_start.cpp: theta0, and the inverse kinematics that may find it) and on the checks of the
// scenario's parts against each other (scenario_checks.cpp: the [solver] policy, the scheme, the [plant]).

#include <optional>
#include <string>

#include "redres/run/scenario.hpp"

namespace redres::scenario_detail {

// theta0 = { ik = { position = [...], rpy = [...] } }: the target of the inverse kinematics that finds theta(0).
struct IkTable {
  bool planar = false;     // set by the reader before the table is read
  bool from_path = false;  // position = "path": the path's start
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> rpy;
  std::optional<double> phi;
  static const Schema<IkTable>& schema();
};

// theta0 = { ik = ..., seed = ... }.
struct Theta0Ik {
  const RobotModel* robot = nullptr;  // set by the reader before the table is read
  IkTable ik;
  std::string seed_name = "home";
  Eigen::VectorXd seed;
  static const Schema<Theta0Ik>& schema();
};

// [output]: what a run writes besides trajectory.csv and summary.json.
struct OutputTable {
  RecordOptions record;
  bool plots = false;
  bool animate = false;
  static const Schema<OutputTable>& schema();
};

// A scenario file's top level, read key by key in this order: each key's reader may use what the keys before it
// gave (the robot bounds theta0, the duration bounds the step, the path starts where the arm does).
struct ScenarioReading {
  Scenario s;
  OutputTable output;
  std::optional<Theta0Ik> ik;  // theta0 = { ik = ... }: solved once the scheme is read
  SourceLocation ik_where;     // theta0's location, for the IK's failure
  static const Schema<ScenarioReading>& schema();
};

// theta0 as an array of joint positions (numbers or formulas, within the limits), or the robot's home without it;
// theta0 = { ik = ... } is read through Theta0Ik instead.
Eigen::VectorXd read_theta0(const TableReader& r, const RobotModel& robot);

// theta0 = { ik = ... }: the IK from the seed, kept within the scheme's joint margins and clear of the bodies of its
// collision constraints; theta0 is its answer. A target it does not reach is a ConfigError at theta0.
void solve_start(Scenario& s, const Theta0Ik& req, const SourceLocation& where);

// [solver]: the run's policy for a step that is not solved, checked against the robot's acceleration limits, and the
// engine with its settings.
void read_solver(const TableReader& r, Scenario& s);

// The scheme just read against the rest of the scenario: the integrator an acceleration-level scheme allows, and the
// size of the table a run records.
void check_scheme(const TableReader& r, const Scenario& s);

// A [plant] table against the rest of the scenario: its kind one of the registered plants (run/plants.hpp), and
// the rest of its keys as that plant checks them.
void check_plant(const TableReader& r, Scenario& s);

}  // namespace redres::scenario_detail

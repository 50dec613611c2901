// A scenario file's schema: its top level's keys in the order they are read (ScenarioReading), its [output] and
// [orientation] tables, and the listing of every table's keys (redres/run/scenario.hpp).

#include "redres/run/scenario.hpp"

#include "run/scenario_reading.hpp"

#include <cmath>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "redres/config/plugin_loader.hpp"
#include "redres/parsers/robot_toml.hpp"

namespace redres {

namespace {

// [orientation]: the end effector's orientation reference (a pose task).
struct OrientationTable {
  bool planar = false;  // set by the reader before the table is read
  Eigen::Vector3d turn = Eigen::Vector3d::Zero();
  static const Schema<OrientationTable>& schema() {
    using C = OrientationTable;
    static const Schema<C> s{{entry<C>(
        "turn", "number (planar) or array of 3 numbers (spatial)", "rad", "0 (hold the orientation at t = 0)",
        "the rotation the end effector turns through over the run (a world-frame rotation vector; planar: about z)",
        [](const TableReader& o, C& c) {
          if (!o.has("turn")) return;
          if (c.planar) {
            c.turn = Eigen::Vector3d(0.0, 0.0, o.number("turn"));
          } else {
            const std::vector<double> w = o.numbers("turn", 3);
            c.turn = Eigen::Vector3d(w[0], w[1], w[2]);
          }
          const double bound = *physical_bound("rad");
          if (!(c.turn.cwiseAbs().maxCoeff() <= bound)) {
            std::ostringstream m;
            m << "expected |x| <= " << bound << " rad (a physical range), got " << c.turn.cwiseAbs().maxCoeff();
            o.fail("turn", m.str());
          }
        },
        "|x| <= 1e+06 rad")}};
    return s;
  }
};

}  // namespace

namespace scenario_detail {

const Schema<OutputTable>& OutputTable::schema() {
  using C = OutputTable;
  static const Schema<C> s{
      {entry<C>("record", "\"all\", \"none\" or \"every=N\"", "", "\"all\"",
                "which steps trajectory.csv has a row for (every=N: every N-th step and the last)",
                [](const TableReader& r, C& c) { c.record = read_record(r, "record", "all"); }),
       entry<C>("format", "\"csv\" or \"hdf5\"", "", "\"csv\"",
                "the recorded tables' file: trajectory.csv and frames.csv, or one trajectory.h5 (HDF5)",
                [](const TableReader& r, C& c) {
                  if (!r.has("format")) return;
                  try {
                    c.record.format = parse_format(r.string("format"));
                  } catch (const std::invalid_argument& e) {
                    r.fail("format", e.what());
                  }
                }),
       field("plots", &C::plots, "", "render the figures with tools/plot_run.py after the run"),
       field("animate", &C::animate, "", "render the animation (animation.mp4, or animation.gif without ffmpeg)")}};
  return s;
}

const Schema<ScenarioReading>& ScenarioReading::schema() {
  using C = ScenarioReading;
  static const Schema<C> keys{{
      plugins_entry<C>("plugin libraries to load first (their plugins may be named below and in the robot file)"),
      entry<C>("name", "string", "", "the file's stem", "the scenario's name (in summary.json and comparisons)",
               [](const TableReader& r, C& c) {
                 if (!r.has("name")) return;
                 c.s.name = r.string("name");
                 if (c.s.name.empty())
                   r.fail("name", "expected a non-empty name (or leave `name` out: the file's stem)");
               }),
      entry<C>("label", "string", "", "the scenario's name",
               "the run's name in legends and tables (summary.json's `label`, the comparison figure and table)",
               [](const TableReader& r, C& c) {
                 if (!r.has("label")) return;
                 c.s.label = r.string("label");
                 if (c.s.label.empty())
                   r.fail("label", "expected a non-empty label (or leave `label` out: the scenario's name)");
               }),
      entry<C>("robot", "path", "", "", "the robot file (TOML; docs/robot_format.md), relative to this file",
               [](const TableReader& r, C& c) {
                 try {
                   c.s.robot = std::make_unique<RobotModel>(load_robot(r.path("robot")));
                 } catch (const ConfigError& e) {
                   // A robot file that is missing, a directory or empty is reported at the key that names it; an
                   // error inside the file keeps its own file:line:col.
                   if (e.where().line == 0) r.fail("robot", e.what());
                   throw;
                 }
               })
          .required(),
      entry<C>("task", "\"position\", \"pose\" or an array of rows", "", "the robot file's task",
               "the task rows (\"pose\": position and orientation; or some rows, e.g. [\"x\", \"y\", \"phi\"])",
               [](const TableReader& r, C& c) {
                 // The scenario chooses the task rows (the robot file's `task` is only the default), so that one
                 // robot file serves position and pose scenarios alike.
                 if (!r.has("task")) return;
                 RobotSpec spec = c.s.robot->spec();
                 read_task(r, spec);
                 c.s.robot = std::make_unique<RobotModel>(std::move(spec));
               }),
      entry<C>("theta0", "array of numbers or formulas, one per joint; or a table {ik, seed}", "rad or m",
               "the robot's home",
               "theta(0), within the joint limits; or found by inverse kinematics (theta0 = { ik = ... }, below)",
               [](const TableReader& r, C& c) {
                 if (r.has("theta0") && r.raw().get("theta0")->is_table()) {
                   const TableReader t = r.table("theta0");
                   const TableReader sub(t.file_ptr(), t.raw(), "theta0");
                   Theta0Ik theta_ik;
                   theta_ik.robot = c.s.robot.get();
                   read_config(sub, Theta0Ik::schema(), theta_ik);
                   sub.finish();
                   c.s.theta0 = theta_ik.seed;  // until the IK has run (the path reads where a relative path starts)
                   c.ik = std::move(theta_ik);
                   c.ik_where = r.location("theta0");
                   return;
                 }
                 c.s.theta0 = read_theta0(r, *c.s.robot);
               }),
      entry<C>(
          "duration", "number", "s", "", "T, the run's duration",
          [](const TableReader& r, C& c) {
            c.s.duration = r.number("duration");
            if (!(c.s.duration > 0.0)) r.fail("duration", "expected a duration T > 0 s");
          },
          "> 0")
          .required(),
      entry<C>(
          "step", "number", "s", "", "tau, the control step",
          [](const TableReader& r, C& c) {
            Scenario& scenario = c.s;
            scenario.tau = r.number("step");
            if (!(scenario.tau > 0.0 && scenario.tau <= scenario.duration))
              r.fail("step", "expected a step 0 < tau <= duration");
            if (!(scenario.duration / scenario.tau <= kMaxSteps)) {
              std::ostringstream m;
              m << "expected at most " << static_cast<long long>(kMaxSteps)
                << " steps, got duration / step = " << scenario.duration << " / " << scenario.tau << " = "
                << scenario.duration / scenario.tau << " (use a longer step or a shorter duration)";
              r.fail("step", m.str());
            }
            if (std::abs(scenario.steps() * scenario.tau - scenario.duration) > 1e-9 * scenario.duration) {
              r.fail("step", "expected a step that divides the duration (T / tau = " +
                                 std::to_string(scenario.duration / scenario.tau) + ")");
            }
          },
          "0 < step <= duration, dividing it; duration / step <= 1e7")
          .required(),
      entry<C>("integrator", "one of 'euler', 'heun'", "", "\"euler\"",
               "how theta_dot is integrated: euler (the paper's), heun (second order)",
               [](const TableReader& r, C& c) {
                 c.s.integrator = r.choice("integrator", {"euler", "heun"}, "euler") == "euler" ? Integrator::kEuler
                                                                                                : Integrator::kHeun;
               }),
      entry<C>("path", "table", "", "", "the desired path r_d(t); its keys are its type's (redres plugins)",
               [](const TableReader& r, C& c) {
                 Scenario& scenario = c.s;
                 KinematicsData k(*scenario.robot);
                 compute_kinematics(*scenario.robot, scenario.theta0, k, KinematicsLevel::kPosition);
                 PathContext pc;
                 pc.dim = scenario.robot->kind() == ChainKind::kPlanar ? 2 : 3;
                 pc.start.head(pc.dim) = k.f.head(pc.dim);
                 if (c.ik && c.ik->ik.from_path) {
                   // The target is where the path starts, which a relative path puts wherever the arm is.
                   const toml::node* placement = r.raw().at_path("path.placement").node();
                   if (placement == nullptr || placement->value_or(std::string()) != "absolute") {
                     r.fail("theta0",
                            "ik = \"path\" aims at where the path starts, and a relative path starts wherever the arm "
                            "does: set `placement = \"absolute\"` and `origin` in [path], or give the target (ik = { "
                            "position = [...] })");
                   }
                 } else if (c.ik) {
                   pc.start.head(pc.dim) = c.ik->ik.position.head(pc.dim);  // where the IK puts the end effector
                 }
                 pc.duration = scenario.duration;
                 const TableReader path_table = r.table("path");
                 scenario.path = make_path(TableReader(path_table.file_ptr(), path_table.raw(), "path"), pc);
               })
          .required(),
      entry<C>("objectives", "array of tables [[objectives]]", "", "",
               "the weighted objectives, at least one; their keys are their type's (redres plugins)",
               [](const TableReader& r, C& c) {
                 Scenario& scenario = c.s;
                 // Reads `constraints` too: one scheme holds both.
                 scenario.scheme =
                     std::make_unique<Scheme>(Scheme::from_toml(r, *scenario.robot, scenario.duration, scenario.tau));
                 check_scheme(r, scenario);
               })
          .required(),
      entry<C>("constraints", "array of tables [[constraints]]", "", "none",
               "the hard constraints; their keys are their type's (redres plugins)",
               [](const TableReader&, C&) {}),  // read with `objectives`, into the same scheme
      entry<C>("tasks", "array of tables [[tasks]]", "", "none",
               "tasks on frames and joints, each hard, soft or an inequality, at a priority (docs/tasks.md)",
               [](const TableReader&, C&) {}),  // read with `objectives`, into the same scheme
      entry<C>("scheme", "table [scheme]", "", "level = \"velocity\"",
               "`level`: \"velocity\" (x = theta_dot, the paper's) or \"acceleration\" (x = theta_ddot; "
               "docs/motion.md); `regularization`: the eps |x|^2 / 2 of every priority level (docs/tasks.md)",
               [](const TableReader&, C&) {}),  // read with `objectives`, into the same scheme
      entry<C>("solver", "table", "", "engine = \"projection\"",
               "the LVI engine and its settings (redres plugins), and what a step that is not solved does",
               [](const TableReader& r, C& c) { read_solver(r, c.s); }),
      entry<C>("orientation", "table [orientation]", "", "none",
               "the end effector's orientation reference, for a pose task (below)",
               [](const TableReader& r, C& c) {
                 if (!r.has("orientation")) return;
                 (void)r.table("orientation");
                 if (!c.s.robot->has_orientation_rows()) {
                   r.fail("orientation",
                          "the task has no orientation rows: set task = \"pose\" (in the scenario or the robot file)");
                 }
                 OrientationTable o;
                 o.planar = c.s.robot->kind() == ChainKind::kPlanar;
                 config_io::read(r, "orientation", o);
                 c.s.orientation_turn = o.turn;
               }),
      field("output", &C::output, "", "what a run writes besides trajectory.csv and summary.json (below)")
          .listed_default("record = \"all\", no figures"),
      entry<C>("plant", "table [plant]", "", "kind = \"kinematic\"",
               "what the commands drive: the kinematic plant or a MuJoCo physics plant (below; docs/plant.md)",
               [](const TableReader& r, C& c) {
                 if (!r.has("plant")) return;
                 config_io::read(r, "plant", c.s.plant);
                 const TableReader t = r.table("plant");
                 const TableReader plant(t.file_ptr(), t.raw(), "plant");
                 check_plant(plant, c.s);
               }),
  }};
  return keys;
}

}  // namespace scenario_detail

using scenario_detail::IkTable;
using scenario_detail::OutputTable;
using scenario_detail::ScenarioReading;
using scenario_detail::Theta0Ik;

const std::vector<KeyTable>& scenario_key_tables() {
  static const std::vector<KeyTable> tables = {
      {"scenario", "", "a scenario file's top level", describe_keys(ScenarioReading::schema())},
      {"scenario", "[output]", "what a run writes besides trajectory.csv and summary.json",
       describe_keys(OutputTable::schema())},
      {"scenario", "[orientation]", "the orientation reference of a pose task",
       describe_keys(OrientationTable::schema())},
      {"scenario", "theta0 = { ik, seed }", "theta(0) found by inverse kinematics (docs/ik.md)",
       describe_keys(Theta0Ik::schema())},
      {"scenario", "theta0.ik = { position, rpy, phi }", "the inverse kinematics' target, in the world frame",
       describe_keys(IkTable::schema())},
      {"scenario", "[scheme]", "what x is, and the priority levels' regularization",
       describe_keys(SchemeTable::schema())},
      {"scenario", "[plant]", "what the commands drive: the kinematic plant or MuJoCo (docs/plant.md)",
       describe_keys(PlantConfig::schema())},
      {"scenario", "[solver]", "the run's policy for a step that is not solved (the engine's keys: redres plugins)",
       solver_policy_keys()},
  };
  return tables;
}

}  // namespace redres

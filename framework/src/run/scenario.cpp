#include "redres/run/scenario.hpp"

#include <array>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "config/overrides.hpp"
#include "redres/config/plugin_loader.hpp"
#include "redres/control/collision_rows.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/plant/mujoco_model.hpp"
#include "redres/run/plants.hpp"
#include "redres/run/plugin_output.hpp"
#include "redres/run/simulation.hpp"

namespace redres {

namespace {

// The [solver] table's keys that are the run's, not the engine's: what a failed step does. Read through a schema,
// like the engine's keys, so that `redres plugins` lists them with their defaults and rules.
struct SolverPolicy {
  FailurePolicy on_infeasible = FailurePolicy::kHold;
  double relax_weight = 1e4;
  double recover_error = 1e-3;
  double max_task_error = 0.01;
  static const Schema<SolverPolicy>& schema() {
    using C = SolverPolicy;
    static const Schema<C> s{
        {field("on_infeasible", &C::on_infeasible, "",
               "what a step whose QP is not solved does: hold (theta_dot = 0; `continue` is the same), stop (the run "
               "ends there), relax (solves the elastic QP, rows relaxed, every bound kept), brake (decelerates within "
               "the acceleration limits, then catches up; docs/motion.md). Default: brake for a robot with "
               "acceleration limits (which refuses hold), else hold"),
         field("relax_weight", &C::relax_weight, "",
               "rho of the elastic QP; only with on_infeasible = \"relax\" or \"brake\"",
               rule<double>("a weight in [1, 1e8]", [](double w) { return w >= 1.0 && w <= 1e8; })),
         field("recover_error", &C::recover_error, "m",
               "under brake, a failed step tries the elastic QP first while the position error exceeds this",
               greater(0.0)),
         field("max_task_error", &C::max_task_error, "m",
               "a run whose largest position error exceeds this is not a success (exit code 1, summary.json's "
               "task_error_exceeded), however many of its steps were solved",
               greater(0.0))},
        {},
        {}};
    return s;
  }
};

// An array of joint positions at `key` (numbers or formulas, one per joint, within the limits).
// `label` starts the entries' messages ("" at the top level, "theta0: " in theta0's table).
Eigen::VectorXd read_joint_array(const TableReader& r, std::string_view key, const RobotModel& robot,
                                 const std::string& expected, const std::string& label = "") {
  const toml::node& node = *r.raw().get(key);
  const toml::array* arr = node.as_array();
  if (arr == nullptr || static_cast<int>(arr->size()) != robot.dof()) r.fail(key, expected);
  const std::string what = label + "key '" + std::string(key) + "'";
  Eigen::VectorXd theta(robot.dof());
  for (int j = 0; j < robot.dof(); ++j) {
    const toml::node& el = (*arr)[static_cast<std::size_t>(j)];
    double v = 0.0;
    bool number = false;
    try {
      number = read_number_or_formula(el, v);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(location_of(r.file(), el), what + ": entry " + std::to_string(j + 1) + ": " + e.what());
    }
    if (!number) {
      throw ConfigError(location_of(r.file(), el), what + ": entry " + std::to_string(j + 1) +
                                                       ": expected a number or a formula string, got " +
                                                       describe_type(el));
    }
    if (!std::isfinite(v)) {
      std::ostringstream s;
      s << what << ": entry " << j + 1 << ": expected a finite number, got " << v;
      throw ConfigError(location_of(r.file(), el), s.str());
    }
    const JointSpec& jt = robot.joint(j);
    if (v < jt.lower || v > jt.upper) {
      std::ostringstream s;
      s.precision(10);
      s << what << ": joint '" << jt.name << "' = " << v << " is outside its limits [" << jt.lower << ", " << jt.upper
        << "]";
      throw ConfigError(location_of(r.file(), el), s.str());
    }
    theta(j) = v;
  }
  return theta;
}

Eigen::VectorXd read_theta0(const TableReader& r, const RobotModel& robot) {
  if (!r.has("theta0")) return robot.home();
  return read_joint_array(r, "theta0", robot,
                          "expected an array of " + std::to_string(robot.dof()) +
                              " joint positions (numbers or formulas such as \"pi/4\"), or a table { ik = ..., seed = "
                              "... } (inverse kinematics, docs/ik.md)");
}

// theta0 = { ik = { position = [...], rpy = [...] } }: the target of the inverse kinematics that finds theta(0).
struct IkTable {
  bool planar = false;     // set by the reader before the table is read
  bool from_path = false;  // position = "path": the path's start
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> rpy;
  std::optional<double> phi;
  static const Schema<IkTable>& schema() {
    using C = IkTable;
    static const Schema<C> s{
        {entry<C>(
             "position", "array of 3 numbers (planar: 2), or \"path\"", "m", "",
             "where the end effector goes, in the world frame; \"path\": where the path starts (r_d(0))",
             [](const TableReader& r, C& c) {
               if (!r.has("position")) r.fail("missing required key 'position' (where the end effector goes)");
               if (const auto* text = r.raw().get("position")->as_string()) {
                 if (text->get() != "path") {
                   r.fail("position", "expected an array of " + std::string(c.planar ? "2" : "3") +
                                          " numbers or \"path\" (the path's start), got \"" + text->get() + "\"");
                 }
                 c.from_path = true;
                 return;
               }
               const std::vector<double> p = r.numbers("position", c.planar ? 2 : 3);
               for (std::size_t i = 0; i < p.size(); ++i) c.position(static_cast<Eigen::Index>(i)) = p[i];
               const double bound = *physical_bound("m");
               if (!(c.position.cwiseAbs().maxCoeff() <= bound)) {
                 std::ostringstream m;
                 m << "expected |x| <= " << bound << " m (a physical range), got " << c.position.cwiseAbs().maxCoeff();
                 r.fail("position", m.str());
               }
             },
             "|x| <= 1000 m")
             .required(),
         entry<C>(
             "rpy", "array of 3 numbers", "rad", "none (position only, or the seed's orientation for a pose task)",
             "spatial robots: the end effector's roll, pitch, yaw, R = Rz(yaw) Ry(pitch) Rx(roll)",
             [](const TableReader& r, C& c) {
               if (!r.has("rpy")) return;
               if (c.planar) {
                 r.fail("rpy", "a planar robot's end-effector orientation is `phi` (one angle about z)");
               }
               const std::vector<double> a = r.numbers("rpy", 3);
               c.rpy = Eigen::Vector3d(a[0], a[1], a[2]);
               if (!(c.rpy->cwiseAbs().maxCoeff() <= *physical_bound("rad"))) {
                 r.fail("rpy", "expected |x| <= 1e6 rad (a physical range)");
               }
             },
             "|x| <= 1e+06 rad"),
         entry<C>(
             "phi", "number", "rad", "none (as rpy)", "planar robots: the end effector's angle about z",
             [](const TableReader& r, C& c) {
               if (!r.has("phi")) return;
               if (!c.planar) {
                 r.fail("phi", "is for a planar robot; a spatial robot's orientation is `rpy = [roll, pitch, yaw]`");
               }
               c.phi = r.number("phi");
               if (!(std::abs(*c.phi) <= *physical_bound("rad"))) {
                 r.fail("phi", "expected |x| <= 1e6 rad (a physical range)");
               }
             },
             "|x| <= 1e+06 rad")}};
    return s;
  }
};

// theta0 = { ik = ..., seed = ... }.
struct Theta0Ik {
  const RobotModel* robot = nullptr;  // set by the reader before the table is read
  IkTable ik;
  std::string seed_name = "home";
  Eigen::VectorXd seed;
  static const Schema<Theta0Ik>& schema() {
    using C = Theta0Ik;
    static const Schema<C> s{
        {entry<C>("ik", "\"path\" or a table {position, rpy, phi}", "", "",
                  "the end effector's target: \"path\" (where the path starts; the path's placement must be "
                  "\"absolute\"), or a pose (below)",
                  [](const TableReader& r, C& c) {
                    if (!r.has("ik")) {
                      r.fail("missing required key 'ik' (the target: \"path\", or { position = [...], rpy = [...] })");
                    }
                    const toml::node& n = *r.raw().get("ik");
                    if (const auto* text = n.as_string()) {
                      if (text->get() != "path") {
                        r.fail("ik",
                               "expected \"path\" (the path's start) or a table { position = [...], rpy = "
                               "[...] }, got \"" +
                                   text->get() + "\"");
                      }
                      c.ik.from_path = true;
                      return;
                    }
                    if (!n.is_table()) {
                      r.fail("ik",
                             "expected \"path\" or a table { position = [...], rpy = [...] }, got " + describe_type(n));
                    }
                    c.ik.planar = c.robot->kind() == ChainKind::kPlanar;
                    config_io::read(r, "ik", c.ik);
                  })
             .required(),
         entry<C>(
             "seed", "\"home\", \"zeros\" or an array of numbers, one per joint", "rad or m", "\"home\"",
             "where the iteration starts: the robot's home, zeros (clamped into the limits), or these joint "
             "positions (within the limits)",
             [](const TableReader& r, C& c) {
               const RobotModel& robot = *c.robot;
               c.seed = robot.home();
               if (!r.has("seed")) return;
               const toml::node& n = *r.raw().get("seed");
               const std::string expected =
                   "expected \"home\", \"zeros\" or an array of " + std::to_string(robot.dof()) + " joint positions";
               if (const auto* text = n.as_string()) {
                 c.seed_name = text->get();
                 if (c.seed_name == "zeros") {
                   c.seed =
                       Eigen::VectorXd::Zero(robot.dof()).cwiseMax(robot.lower_limits()).cwiseMin(robot.upper_limits());
                 } else if (c.seed_name != "home") {
                   r.fail("seed", expected + ", got \"" + c.seed_name + "\"");
                 }
                 return;
               }
               c.seed_name = "given";
               c.seed = read_joint_array(
                   r, "seed", robot,
                   expected + ", got " + describe_type(n) +
                       (n.is_array() ? " of " + std::to_string(n.as_array()->size()) + " element(s)" : ""),
                   "theta0: ");
             })}};
    return s;
  }
};

// [output]: what a run writes besides trajectory.csv and summary.json.
struct OutputTable {
  RecordOptions record;
  bool plots = false;
  bool animate = false;
  static const Schema<OutputTable>& schema() {
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
};

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

void check_plant(const TableReader& r, Scenario& s);

// A scenario file's top level, read key by key in this order: each key's reader may use what the keys before it
// gave (the robot bounds theta0, the duration bounds the step, the path starts where the arm does).
struct ScenarioReading {
  Scenario s;
  OutputTable output;
  std::optional<Theta0Ik> ik;  // theta0 = { ik = ... }: solved once the scheme is read
  SourceLocation ik_where;     // theta0's location, for the IK's failure
  static const Schema<ScenarioReading>& schema();
};

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
                   Theta0Ik ik;
                   ik.robot = c.s.robot.get();
                   read_config(sub, Theta0Ik::schema(), ik);
                   sub.finish();
                   c.s.theta0 = ik.seed;  // until the IK has run (the path reads where a relative path starts)
                   c.ik = std::move(ik);
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
            Scenario& s = c.s;
            s.tau = r.number("step");
            if (!(s.tau > 0.0 && s.tau <= s.duration)) r.fail("step", "expected a step 0 < tau <= duration");
            if (!(s.duration / s.tau <= kMaxSteps)) {
              std::ostringstream m;
              m << "expected at most " << static_cast<long long>(kMaxSteps)
                << " steps, got duration / step = " << s.duration << " / " << s.tau << " = " << s.duration / s.tau
                << " (use a longer step or a shorter duration)";
              r.fail("step", m.str());
            }
            if (std::abs(s.steps() * s.tau - s.duration) > 1e-9 * s.duration) {
              r.fail("step", "expected a step that divides the duration (T / tau = " +
                                 std::to_string(s.duration / s.tau) + ")");
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
                 Scenario& s = c.s;
                 KinematicsData k(*s.robot);
                 compute_kinematics(*s.robot, s.theta0, k, KinematicsLevel::kPosition);
                 PathContext pc;
                 pc.dim = s.robot->kind() == ChainKind::kPlanar ? 2 : 3;
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
                 pc.duration = s.duration;
                 const TableReader path_table = r.table("path");
                 s.path = make_path(TableReader(path_table.file_ptr(), path_table.raw(), "path"), pc);
               })
          .required(),
      entry<C>("objectives", "array of tables [[objectives]]", "", "",
               "the weighted objectives, at least one; their keys are their type's (redres plugins)",
               [](const TableReader& r, C& c) {
                 Scenario& s = c.s;
                 // Reads `constraints` too: one scheme holds both.
                 s.scheme = std::make_unique<Scheme>(Scheme::from_toml(r, *s.robot, s.duration, s.tau));
                 if (s.scheme->order() == ControlOrder::kAcceleration && s.integrator == Integrator::kHeun) {
                   r.fail("integrator",
                          "an acceleration-level scheme ([scheme] level = \"acceleration\") integrates "
                          "its own way (constant acceleration over each step, exact); leave "
                          "`integrator` out or set it to \"euler\"");
                 }
                 const std::size_t width = trajectory_width(s);
                 if (const double bytes = (s.steps() + 1.0) * static_cast<double>(width) * 8.0;
                     bytes > kMaxTableBytes) {
                   std::ostringstream m;
                   m << "expected a run whose recorded table fits in " << kMaxTableBytes / (1024.0 * 1024 * 1024)
                     << " GiB, got " << s.steps() + 1 << " rows of " << width << " columns ("
                     << bytes / (1024.0 * 1024 * 1024) << " GiB; use a longer step or a shorter duration)";
                   r.fail("step", m.str());
                 }
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
               [](const TableReader& r, C& c) {
                 Scenario& s = c.s;
                 const bool limits = s.robot->has_acceleration_limits();
                 s.on_infeasible = limits ? FailurePolicy::kBrake : FailurePolicy::kHold;
                 if (!r.has("solver")) {
                   s.engine = EngineSpec{};  // projection, with the default settings
                   return;
                 }
                 const TableReader t = r.table("solver");
                 const TableReader solver(t.file_ptr(), t.raw(), "solver");
                 SolverPolicy policy;
                 read_config(solver, SolverPolicy::schema(), policy);
                 if (solver.has("on_infeasible")) s.on_infeasible = policy.on_infeasible;
                 s.relax_weight = policy.relax_weight;
                 s.recover_error = policy.recover_error;
                 s.max_task_error = policy.max_task_error;
                 const std::string chosen = solver.has("on_infeasible")
                                                ? std::string(solver.string("on_infeasible"))
                                                : std::string(limits ? "brake" : "hold") + "\", the default";
                 if (s.on_infeasible == FailurePolicy::kHold && limits) {
                   solver.fail("on_infeasible", "\"" + chosen +
                                                    "\" stops every joint at once, a velocity jump that robot '" +
                                                    s.robot->name() +
                                                    "''s acceleration limits forbid; use \"brake\" (the default for "
                                                    "it), \"relax\" or \"stop\"");
                 }
                 if (s.on_infeasible == FailurePolicy::kBrake && !limits) {
                   solver.fail("on_infeasible",
                               "\"brake\" decelerates within the joints' acceleration limits, and "
                               "robot '" +
                                   s.robot->name() +
                                   "' gives none on some joint (`acceleration_limit` in the robot "
                                   "file's [[joints]])");
                 }
                 if (solver.has("relax_weight") && s.on_infeasible != FailurePolicy::kRelax &&
                     s.on_infeasible != FailurePolicy::kBrake) {
                   solver.fail("relax_weight",
                               "is used only with on_infeasible = \"relax\" or \"brake\" "
                               "(on_infeasible is \"" +
                                   chosen + "\")");
                 }
                 if (solver.has("recover_error") && s.on_infeasible != FailurePolicy::kBrake) {
                   solver.fail("recover_error",
                               "is used only with on_infeasible = \"brake\" (on_infeasible is \"" + chosen + "\")");
                 }
                 s.engine = read_engine_spec(solver);
               }),
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

// A [plant] table against the rest of the scenario: its kind one of the registered plants (run/plants.hpp), and
// the rest of its keys as that plant checks them.
void check_plant(const TableReader& r, Scenario& s) {
  const PlantType* type = plant_registry().find(s.plant.kind);
  if (type == nullptr) {
    std::string names;
    for (const PlantType& t : plant_registry().types()) names += (names.empty() ? "\"" : ", \"") + t.name + "\"";
    r.fail("kind", "unknown plant \"" + s.plant.kind + "\"; expected one of " + names);
  }
  if (type->check) type->check(r, s);
}

// The largest `margin` of the scheme's active joint_angle_margin constraints, per joint (zeros without one).
Eigen::VectorXd scheme_margin(const Scheme& scheme, int n) {
  Eigen::VectorXd margin = Eigen::VectorXd::Zero(n);
  for (const auto& c : scheme.constraints()) {
    if (!c->active() || c->type() != "joint_angle_margin") continue;
    const toml::table config = c->config();
    const toml::node* m = config.get("margin");
    if (m == nullptr) continue;
    if (const auto v = m->value<double>()) {
      margin = margin.cwiseMax(Eigen::VectorXd::Constant(n, *v));
    } else if (const toml::array* a = m->as_array(); a != nullptr && static_cast<int>(a->size()) == n) {
      for (int j = 0; j < n; ++j) margin(j) = std::max(margin(j), (*a)[static_cast<std::size_t>(j)].value_or(0.0));
    }
  }
  return margin;
}

std::string vector_text(const Eigen::Ref<const Eigen::VectorXd>& v) {
  std::ostringstream s;
  s.precision(6);
  s << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s << (i > 0 ? ", " : "") << v(i);
  s << "]";
  return s.str();
}

// theta0 = { ik = ... }: the IK from the seed, kept within the scheme's joint margins and clear of the bodies of its
// collision constraints; theta0 is its answer. A target it does not reach is a ConfigError at theta0.
void solve_start(Scenario& s, const Theta0Ik& req, const SourceLocation& where) {
  const RobotModel& robot = *s.robot;
  const bool planar = robot.kind() == ChainKind::kPlanar;
  const int p = robot.position_rows();
  KinematicsData k(robot);
  compute_kinematics(robot, req.seed, k, KinematicsLevel::kPosition);
  IkTarget target;
  std::ostringstream text;
  text.precision(6);
  if (req.ik.from_path) {
    Eigen::VectorXd r(p), r_dot(p);
    s.path->evaluate(0.0, r, r_dot);
    target.position.head(p) = r;
    text << "the path's start ";
  } else {
    target.position.head(p) = req.ik.position.head(p);
  }
  text << "xyz " << vector_text(target.position.head(p));
  bool held = false;  // a pose task without a given orientation keeps the seed's
  if (req.ik.rpy) {
    target.rotation = rpy_matrix({(*req.ik.rpy)(0), (*req.ik.rpy)(1), (*req.ik.rpy)(2)});
    text << " rpy " << vector_text(*req.ik.rpy);
  } else if (req.ik.phi) {
    target.rotation = Eigen::AngleAxisd(*req.ik.phi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    text << " phi " << *req.ik.phi;
  } else if (robot.has_orientation_rows()) {
    held = true;
    target.rotation = planar ? Eigen::AngleAxisd(k.f(2), Eigen::Vector3d::UnitZ()).toRotationMatrix()
                             : Eigen::Matrix3d(k.ee_pose.linear());
    text << " with the seed's orientation";
  }
  // From the path: the task's rows (and a given orientation in full); a given pose: every row.
  if (req.ik.from_path) {
    for (int r = 0; r < p; ++r) {
      if (robot.tracks(r)) target.rows.push_back(robot.reference_names()[static_cast<std::size_t>(r)]);
    }
    if (target.rotation) {
      const std::vector<std::string> names =
          planar ? std::vector<std::string>{"phi"} : std::vector<std::string>{"wx", "wy", "wz"};
      for (std::size_t i = 0; i < names.size(); ++i) {
        if (!held || robot.tracks(p + static_cast<int>(i))) target.rows.push_back(names[i]);
      }
    }
  }
  std::vector<const Constraint*> collision;
  for (const auto& c : s.scheme->constraints()) {
    if (!c->active()) continue;
    const std::unique_ptr<PluginData> data = c->make_data();
    if (dynamic_cast<const PairData*>(data.get()) != nullptr) collision.push_back(c.get());
  }
  IkOptions options;
  options.margin = scheme_margin(*s.scheme, robot.dof());
  IkResult result;
  try {
    result = solve_ik(robot, target, req.seed, collision, options);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(where, std::string("key 'theta0': the inverse kinematics cannot start: ") + e.what());
  }
  if (!result.converged) {
    throw ConfigError(where, "key 'theta0': the inverse kinematics to " + text.str() + " from the seed '" +
                                 req.seed_name + "' " + result.summary() +
                                 " (move the target, give another `seed`, or widen the limits)");
  }
  s.theta0 = result.theta;
  s.ik = result;
  s.ik_target = text.str() + " from the seed '" + req.seed_name + "'";
}

}  // namespace

std::vector<ShapeSpec> scenario_obstacles(const Scenario& s, bool inactive) {
  std::vector<ShapeSpec> out;
  for (const auto& c : s.scheme->constraints()) {
    const PluginOutput* output = output_of(*c);
    if (output != nullptr && (inactive || c->active())) output->scene_obstacles(out);
  }
  return out;
}

std::string scenario_mjcf(const Scenario& s) {
  if (s.plant.kind != "mujoco")
    throw std::invalid_argument("scenario '" + s.name + "' runs on the kinematic plant: set [plant] kind = \"mujoco\"");
  MjcfOptions options;
  options.plant = s.plant;
  options.obstacles = scenario_obstacles(s, true);
  return mjcf_from_robot(*s.robot, options);
}

int Scenario::steps() const {
  const double ratio = duration / tau;
  REDRES_REQUIRE(ratio >= 0.5 && ratio <= kMaxSteps, "Scenario::steps",
                 "duration / step is in [1, " + std::to_string(static_cast<long long>(kMaxSteps)) + "] (got " +
                     std::to_string(ratio) + ")");
  return static_cast<int>(std::lround(ratio));
}

const std::vector<KeyInfo>& solver_policy_keys() {
  static const std::vector<KeyInfo> keys = describe_keys(SolverPolicy::schema());
  return keys;
}

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

Scenario load_scenario(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  const std::shared_ptr<TomlFile> parsed = parse_toml_file(file);
  apply_overrides(parsed->root, overrides);
  const std::shared_ptr<const TomlFile> doc = parsed;
  const TableReader r = TableReader::root(doc, "scenario");

  ScenarioReading reading;
  reading.s.source = file.string();
  reading.s.name = file.stem().string();
  read_config(r, ScenarioReading::schema(), reading);
  r.finish();
  if (reading.s.label.empty()) reading.s.label = reading.s.name;
  if (reading.ik) solve_start(reading.s, *reading.ik, reading.ik_where);
  Scenario s = std::move(reading.s);
  s.record = reading.output.record;
  s.plots = reading.output.plots;
  s.animate = reading.output.animate;
  return s;
}

}  // namespace redres

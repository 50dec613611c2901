// redres._redres: the C++ side of the Python module. The pure-Python package (redres/__init__.py) builds on it:
// typed plugin configurations, compare(), and the base classes of Python-defined plugins.

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "frame_access.hpp"
#include "python_plugins.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/control/path.hpp"
#include "redres/control/task.hpp"
#include "redres/extend/plugin_kinds.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/model/velocity_limit.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"
#include "redres/plant/mujoco_model.hpp"
#include "redres/qp/lvi.hpp"
#include "redres/run/comparison.hpp"
#include "redres/run/run_output.hpp"
#include "redres/run/run_summary.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"
#include "redres/run/sweep.hpp"
#include "redres/run/trajectory_columns.hpp"
#include "types.hpp"

#ifndef REDRES_VERSION
#error "REDRES_VERSION (the project's version) is set by framework/python/CMakeLists.txt"
#endif

namespace redres::python {
namespace {

// --- robots -----------------------------------------------------------------------------------------------------

// The kinematics at one configuration, copied out of KinematicsData.
struct KinematicsResult {
  Eigen::VectorXd theta, f, grad_w, grad_mu;
  Eigen::MatrixXd J;
  double w = 0.0, mu = 0.0;
  Eigen::Matrix4d ee_pose = Eigen::Matrix4d::Identity();
  std::vector<Eigen::Matrix4d> link_frames;
  // For the named frames: the robot (shared with its redres.Robot) and the kinematics it was computed into.
  std::shared_ptr<const RobotModel> robot;
  std::shared_ptr<const KinematicsData> data;
};

Eigen::VectorXd checked_theta(const RobotModel& robot, const Eigen::VectorXd& theta, const char* who) {
  if (theta.size() != robot.dof()) {
    throw std::invalid_argument(std::string(who) + ": theta has " + std::to_string(theta.size()) +
                                " entries, expected dof = " + std::to_string(robot.dof()));
  }
  for (Eigen::Index j = 0; j < theta.size(); ++j) {
    if (!std::isfinite(theta(j))) {
      throw std::invalid_argument(std::string(who) + ": theta is finite (theta[" + std::to_string(j) +
                                  "] = " + std::to_string(theta(j)) + ")");
    }
  }
  return theta;
}

KinematicsResult kinematics_of(const std::shared_ptr<const RobotModel>& model, const Eigen::VectorXd& theta) {
  const RobotModel& robot = *model;
  auto data = std::make_shared<KinematicsData>(robot);
  KinematicsData& k = *data;
  compute_kinematics(robot, checked_theta(robot, theta, "Robot.kinematics"), k, KinematicsLevel::kAll);
  KinematicsResult out;
  // A robot borrowed from a step's context (ctx.robot, no owner) may be gone before the result: it keeps a copy.
  out.robot = model.use_count() > 0 ? model : std::make_shared<const RobotModel>(robot);
  out.data = data;
  out.theta = k.theta;
  out.f = k.f;
  out.J = k.J;
  out.w = k.w;
  out.grad_w = k.grad_w;
  out.mu = k.mu;
  out.grad_mu = k.grad_mu;
  out.ee_pose = k.ee_pose.matrix();
  out.link_frames = link_frames_of(k);
  return out;
}

// --- scenarios and runs ------------------------------------------------------------------------------------------

// One user at a time of what a scenario or a controller holds (its plugins' state, the engine's warm start, the
// step's buffers). Another thread waits its turn; the thread that holds it already (a plugin that runs its own
// scenario or steps its own controller from inside the step) is refused, where waiting would never end.
struct Exclusive {
  std::mutex mutex;
  std::atomic<std::thread::id> owner{};
};

class Hold {
 public:
  // Call without the GIL: the thread waited for may need it to finish.
  Hold(Exclusive& e, const char* what) : e_(e) {
    if (e_.owner.load() == std::this_thread::get_id()) {
      throw std::runtime_error(std::string(what) +
                               ": called again from inside its own step (a plugin of it called it); a scenario or "
                               "controller takes one step at a time: use another one inside a plugin");
    }
    e_.mutex.lock();
    e_.owner.store(std::this_thread::get_id());
  }
  ~Hold() {
    e_.owner.store(std::thread::id());
    e_.mutex.unlock();
  }
  Hold(const Hold&) = delete;
  Hold& operator=(const Hold&) = delete;

 private:
  Exclusive& e_;
};

// redres.Scenario: a loaded scenario, only read by its runs (simulate() makes each run's controller, engine and
// plant): any number of runs at once, on any number of Python threads.
struct PyScenario {
  std::shared_ptr<Scenario> scenario;
};

// redres.Result: a finished run, its summary, and the scenario it came from (for write()).
struct PyResult {
  std::shared_ptr<const RunResult> run;
  std::shared_ptr<const RunSummary> summary;
  std::shared_ptr<Scenario> scenario;
};

// One column of the row-major trajectory as a strided numpy view (no copy), kept alive by `owner`.
py::array column_view(const Trajectory& tr, std::size_t col, py::handle owner) {
  const double* base = tr.values().empty() ? nullptr : tr.values().data() + col;
  py::array a(py::dtype::of<double>(), {static_cast<py::ssize_t>(tr.size())},
              {static_cast<py::ssize_t>(sizeof(double) * tr.width())}, base, owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

// The scenarios this thread is running: a run takes no turn (several threads may run one scenario at once), but a
// plugin that runs its own scenario from inside a step would recurse without end, so that is refused.
class RunningHere {
 public:
  explicit RunningHere(const Scenario* s) {
    for (const Scenario* r : running()) {
      if (r == s) {
        throw std::runtime_error(
            "Scenario.run: called again from inside its own step (a plugin of it called it); a run of a scenario "
            "cannot contain another run of it: use another scenario inside a plugin");
      }
    }
    running().push_back(s);
  }
  ~RunningHere() { running().pop_back(); }
  RunningHere(const RunningHere&) = delete;
  RunningHere& operator=(const RunningHere&) = delete;

 private:
  static std::vector<const Scenario*>& running() {
    thread_local std::vector<const Scenario*> list;
    return list;
  }
};

PyResult run_scenario(PyScenario& s, const py::object& progress) {
  // Calls the progress function (if any) and lets Ctrl-C stop a long run: both need the GIL, taken about 200
  // times per run.
  const ProgressCallback callback = [&progress](double fraction, double t) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!progress.is_none()) progress(fraction, t);
  };
  PyResult out;
  {
    const RunningHere here(s.scenario.get());
    py::gil_scoped_release release;
    auto run = std::make_shared<RunResult>(simulate(*s.scenario, callback));
    out.summary = std::make_shared<RunSummary>(summarise(*s.scenario, *run));
    out.run = std::move(run);
  }
  out.scenario = s.scenario;
  return out;
}

// "key=value" overrides from a dict whose values were already rendered as TOML text (by the Python package).
std::vector<std::string> override_strings(const std::optional<std::vector<std::pair<std::string, std::string>>>& o) {
  std::vector<std::string> out;
  if (o) {
    for (const auto& [k, v] : *o) out.push_back(k + "=" + v);
  }
  return out;
}

// --- sweeps --------------------------------------------------------------------------------------------------------

// The sweep table's cells as Python values, by what each column holds: the summary's fields keep their types (a
// vector field's columns <key>_<k> are numbers), plugin metrics and theta0 entries are numbers, an axis value is a
// number when it reads as one, status and diagnosis are text; an empty cell (a failed run's figures) is None.
py::list typed_rows(const SweepTable& table, const SweepSpec& spec) {
  enum class Kind { kText, kNumber, kInteger, kBool, kAxis };
  std::vector<Kind> kinds;
  for (const std::string& column : table.columns) {
    Kind kind = Kind::kText;
    if (column == "index") {
      kind = Kind::kInteger;
    } else if (column.rfind("theta0_", 0) == 0 || column.rfind("metrics.", 0) == 0) {
      kind = Kind::kNumber;
    } else {
      for (const SweepAxis& a : spec.axes) kind = a.key == column ? Kind::kAxis : kind;
      for (const SummaryField& f : summary_fields()) {
        const bool whole = column == f.key;
        const bool entry =
            column.size() > f.key.size() && column.compare(0, f.key.size(), f.key) == 0 && column[f.key.size()] == '_';
        if ((!whole && !entry) || f.get == nullptr) continue;
        const SummaryValue sample = f.get(RunSummary{});
        if (std::holds_alternative<double>(sample) || std::holds_alternative<std::vector<double>>(sample)) {
          kind = Kind::kNumber;
        } else if (std::holds_alternative<long>(sample)) {
          kind = Kind::kInteger;
        } else if (std::holds_alternative<bool>(sample)) {
          kind = Kind::kBool;
        }
      }
    }
    kinds.push_back(kind);
  }
  py::list rows;
  for (const auto& row : table.rows) {
    py::list out;
    for (std::size_t c = 0; c < row.size(); ++c) {
      const std::string& cell = row[c];
      if (cell.empty() && kinds[c] != Kind::kText) {
        out.append(py::none());
        continue;
      }
      char* end = nullptr;
      switch (kinds[c]) {
        case Kind::kText: out.append(cell); break;
        case Kind::kInteger: out.append(std::stol(cell)); break;
        case Kind::kNumber: out.append(std::stod(cell)); break;
        case Kind::kBool: out.append(cell == "true"); break;
        case Kind::kAxis: {
          const double v = std::strtod(cell.c_str(), &end);
          if (end == cell.c_str() + cell.size()) {
            out.append(v);
          } else {
            out.append(cell);
          }
          break;
        }
      }
    }
    rows.append(out);
  }
  return rows;
}

// --- QPs ---------------------------------------------------------------------------------------------------------

py::dict qp_dict(const QpProblem& qp) {
  py::dict d;
  d["W"] = Eigen::MatrixXd(qp.W);
  d["zeta"] = Eigen::VectorXd(qp.zeta);
  d["J"] = Eigen::MatrixXd(qp.J);
  d["d"] = Eigen::VectorXd(qp.d);
  d["A"] = Eigen::MatrixXd(qp.A);
  d["b"] = Eigen::VectorXd(qp.b);
  d["lo"] = Eigen::VectorXd(qp.lo);
  d["hi"] = Eigen::VectorXd(qp.hi);
  return d;
}

// redres.solve_qp: one QP given as qp_dict's keys, solved by a named engine from a cold start.
py::dict solve_qp(const py::dict& given, const std::string& engine, double tolerance, int max_iterations) {
  const auto matrix = [&](const char* key) { return given[key].cast<Eigen::MatrixXd>(); };
  const auto vector = [&](const char* key) { return given[key].cast<Eigen::VectorXd>(); };
  for (const char* key : {"W", "zeta", "J", "d", "lo", "hi"}) {
    if (!given.contains(key)) throw std::invalid_argument(std::string("solve_qp: the QP has no '") + key + "'");
  }
  const Eigen::MatrixXd W = matrix("W"), J = matrix("J");
  const Eigen::Index n = W.rows();
  const Eigen::MatrixXd A = given.contains("A") ? matrix("A") : Eigen::MatrixXd(0, n);
  QpProblem qp;
  qp.resize(static_cast<int>(n), static_cast<int>(J.rows()), static_cast<int>(A.rows()));
  const auto fill = [](auto& into, const auto& from, const char* key) {
    if (into.rows() != from.rows() || into.cols() != from.cols()) {
      throw std::invalid_argument(std::string("solve_qp: '") + key + "' is " + std::to_string(from.rows()) + " x " +
                                  std::to_string(from.cols()) + ", expected " + std::to_string(into.rows()) + " x " +
                                  std::to_string(into.cols()));
    }
    into = from;
  };
  fill(qp.W, W, "W");
  fill(qp.zeta, vector("zeta"), "zeta");
  fill(qp.J, J, "J");
  fill(qp.d, vector("d"), "d");
  fill(qp.A, A, "A");
  fill(qp.b, given.contains("b") ? vector("b") : Eigen::VectorXd(0), "b");
  fill(qp.lo, vector("lo"), "lo");
  fill(qp.hi, vector("hi"), "hi");
  qp.validate();
  SolverSettings settings;
  settings.tolerance = tolerance;
  settings.max_iterations = max_iterations;
  std::unique_ptr<LviEngine> solver = make_engine(engine, settings);
  SolverResult r;
  solver->setup(qp.n(), qp.m_eq(), qp.m_in(), r);
  {
    py::gil_scoped_release release;
    solver->solve(qp, r);  // checks W's structure itself: a dense W is solved as dense
  }
  py::dict out;
  out["x"] = Eigen::VectorXd(r.x);
  out["y"] = Eigen::VectorXd(r.y);
  out["z"] = Eigen::VectorXd(r.z);
  out["status"] = to_string(r.info.status);
  out["engine"] = std::string(r.info.engine);
  out["iterations"] = r.info.iterations;
  out["residual"] = r.info.residual;
  out["primal_residual"] = r.info.primal_residual;
  out["dual_residual"] = r.info.dual_residual;
  out["complementarity"] = r.info.complementarity;
  out["diagnosis"] = r.info.diagnosis;
  return out;
}

// --- controllers -------------------------------------------------------------------------------------------------

// One step's SolverInfo, with the engine's name owned.
struct LevelStepInfo {
  int priority = 0;
  std::string status, diagnosis;
  int iterations = 0;
  double residual = 0.0, task_error = 0.0;
};

struct StepInfo {
  std::string status, engine, diagnosis;
  int iterations = 0;
  double residual = 0.0;
  std::vector<LevelStepInfo> levels;  // a scheme with several priority levels: each level's outcome
  double primal_residual = 0.0, dual_residual = 0.0, complementarity = 0.0;  // the certificate's figures
  [[nodiscard]] bool ok() const { return status == "solved"; }
};

StepInfo info_of(const StepOutput& out) {
  const SolverInfo& i = out.info;
  StepInfo info{to_string(i.status), std::string(i.engine), i.diagnosis,      i.iterations, i.residual, {},
                i.primal_residual,   i.dual_residual,       i.complementarity};
  for (const LevelInfo& l : out.levels) {
    info.levels.push_back({l.priority, to_string(l.status), l.diagnosis, l.iterations, l.residual, l.task_error});
  }
  return info;
}

// redres.Controller: the per-step API for a caller's own loop, owning (or sharing) what the C++ Controller needs.
struct PyController {
  std::shared_ptr<const RobotModel> robot;
  std::shared_ptr<Scenario> scenario;  // when built from a scenario (it owns the scheme, engine and path)
  std::unique_ptr<Scheme> scheme;
  std::unique_ptr<LviEngine> engine;
  std::unique_ptr<Path> path;
  std::unique_ptr<Controller> controller;
  StepOutput out;
  std::shared_ptr<Exclusive> use = std::make_shared<Exclusive>();  // one step at a time
};

bool is_spec(py::handle item) { return py::hasattr(item, "_spec_table"); }

toml::table spec_table(py::handle item, std::string& where) {
  where = py::str(item.attr("_spec_where")).cast<std::string>();
  return to_table(item.attr("_spec_table").cast<py::dict>(), where);
}

// A plugin configuration of `kind` ("objective", "constraint", "task") in a Controller's list `list`, or a clear
// TypeError for one of another kind (e.g. an objective among the tasks, whose type the task registry would not know).
void check_kind(py::handle item, const char* kind, const char* list, std::size_t index) {
  const std::string got = py::str(item.attr("kind")).cast<std::string>();
  if (got != kind) {
    throw py::type_error("Controller: " + std::string(list) + "[" + std::to_string(index) + "] is " +
                         py::repr(item).cast<std::string>() + " (kind '" + got + "'); expected a redres." + kind +
                         "s.* configuration");
  }
}

// The orientation turn of a Controller (as a scenario's [orientation] turn): a number about z for a planar robot, a
// world-frame rotation vector (3,) for a spatial one.
Eigen::Vector3d turn_of(const RobotModel& model, const py::handle& value) {
  Eigen::Vector3d turn = Eigen::Vector3d::Zero();
  if (model.kind() == ChainKind::kPlanar) {
    if (!py::isinstance<py::float_>(value) && !py::isinstance<py::int_>(value)) {
      throw py::type_error("Controller: orientation_turn of a planar robot is a number (rad, about z)");
    }
    turn.z() = value.cast<double>();
  } else {
    const auto v = value.cast<Eigen::VectorXd>();
    if (v.size() != 3) {
      throw std::invalid_argument("Controller: orientation_turn of a spatial robot has 3 entries, got " +
                                  std::to_string(v.size()));
    }
    turn = v;
  }
  if (!turn.allFinite()) throw std::invalid_argument("Controller: orientation_turn is finite");
  return turn;
}

std::unique_ptr<PyController> make_controller(const PyRobot& robot, const py::list& objectives,
                                              const py::list& constraints, py::object engine, py::object path, double T,
                                              double tau, std::optional<Eigen::VectorXd> theta0,
                                              const std::string& level, const py::list& tasks,
                                              std::optional<double> regularization, py::object orientation_turn) {
  auto c = std::make_unique<PyController>();
  c->robot = robot.model;
  const RobotModel& model = *c->robot;
  std::vector<std::unique_ptr<Objective>> objs;
  std::vector<std::unique_ptr<Constraint>> cons;
  std::vector<std::unique_ptr<Task>> tasks_made;
  std::size_t index = 0;
  for (py::handle item : objectives) {
    std::string where;
    if (is_spec(item)) check_kind(item, "objective", "objectives", index);
    objs.push_back(is_spec(item) ? make_objective_from(spec_table(item, where), where, model)
                                 : wrap_objective(py::reinterpret_borrow<py::object>(item), model));
    ++index;
  }
  index = 0;
  for (py::handle item : constraints) {
    std::string where;
    if (is_spec(item)) check_kind(item, "constraint", "constraints", index);
    cons.push_back(is_spec(item) ? make_constraint_from(spec_table(item, where), where, model)
                                 : wrap_constraint(py::reinterpret_borrow<py::object>(item), model));
    ++index;
  }
  index = 0;
  for (py::handle item : tasks) {
    if (!is_spec(item)) {
      throw py::type_error("Controller: tasks[" + std::to_string(index) + "] is " + py::repr(item).cast<std::string>() +
                           "; expected a redres.tasks.* configuration");
    }
    check_kind(item, "task", "tasks", index);
    std::string where;
    tasks_made.push_back(make_task_from(spec_table(item, where), where, model));
    ++index;
  }
  if (level != "velocity" && level != "acceleration") {
    throw std::invalid_argument("Controller: expected level 'velocity' or 'acceleration', got '" + level + "'");
  }
  if (regularization && !(*regularization > 0.0 && *regularization <= 1.0)) {
    throw std::invalid_argument("Controller: regularization: expected a number in (0, 1], got " +
                                std::to_string(*regularization));
  }
  c->scheme = std::make_unique<Scheme>(model, std::move(objs), std::move(cons), std::move(tasks_made),
                                       level == "velocity" ? ControlOrder::kVelocity : ControlOrder::kAcceleration);
  if (regularization) c->scheme->set_regularization(*regularization);
  if (py::isinstance<py::str>(engine)) {
    c->engine = make_engine(engine.cast<std::string>());
  } else {
    std::string where;
    const toml::table t = spec_table(engine, where);
    c->engine = make_engine(reader_of(t, where));
  }
  if (!path.is_none()) {
    const Eigen::VectorXd start_theta = theta0 ? checked_theta(model, *theta0, "Controller") : model.home();
    KinematicsData k(model);
    compute_kinematics(model, start_theta, k, KinematicsLevel::kPosition);
    PathContext pc;
    pc.dim = model.kind() == ChainKind::kPlanar ? 2 : 3;
    pc.start.head(pc.dim) = k.f.head(pc.dim);
    pc.duration = T;
    std::string where;
    const toml::table t = spec_table(path, where);
    c->path = make_path(reader_of(t, where), pc);
  }
  c->controller = std::make_unique<Controller>(model, *c->scheme, *c->engine, c->path.get(), T, tau);
  if (!orientation_turn.is_none()) c->controller->set_orientation_turn(turn_of(model, orientation_turn));
  c->out = c->controller->make_output();
  return c;
}

std::unique_ptr<PyController> controller_of(const PyScenario& s) {
  auto c = std::make_unique<PyController>();
  c->scenario = s.scenario;  // kept alive; only read
  Scenario& sc = *s.scenario;
  c->robot = std::shared_ptr<const RobotModel>(s.scenario, sc.robot.get());
  c->controller = Controller::from_scenario(sc);  // what simulate() runs, the relax policy included
  c->out = c->controller->make_output();
  return c;
}

// The controller behind a method's `self`, or nullptr when it was never made (its __init__ raised, or was not
// called: the half-made object a traceback keeps), which pybind11 would hand over as garbage.
PyController* made(py::handle self) {
  auto* inst = reinterpret_cast<py::detail::instance*>(self.ptr());
  const py::detail::value_and_holder vh =
      inst->get_value_and_holder(py::detail::get_type_info(typeid(PyController)), false);
  return vh.inst != nullptr && vh && vh.holder_constructed() ? vh.value_ptr<PyController>() : nullptr;
}

PyController& live(py::handle self) {
  PyController* c = made(self);
  if (c == nullptr) throw std::runtime_error("redres.Controller: this controller was never made (its __init__ raised)");
  return *c;
}

// f(c.controller) in c's turn, without the GIL (f touches no Python object); its result is a copy.
template <class F>
auto in_turn(PyController& c, const char* what, F&& f) {
  py::gil_scoped_release release;
  const Hold hold(*c.use, what);
  return f(*c.controller);
}

// One step's (theta_dot, StepInfo), copied in the step's turn.
template <class Step>
py::tuple step_in_turn(PyController& c, Step&& step) {
  auto [theta_dot, info] = in_turn(c, "Controller.step", [&](Controller& k) {
    step(k);
    return std::make_pair(Eigen::VectorXd(c.out.theta_dot), info_of(c.out));
  });
  return py::make_tuple(std::move(theta_dot), std::move(info));
}

// --- the registries' listing ---------------------------------------------------------------------------------------

py::dict key_dict(const KeyInfo& k) {
  py::dict d;
  d["name"] = k.name;
  d["default"] = k.default_text;
  d["unit"] = k.unit;
  d["help"] = k.help;
  d["rule"] = k.rule;
  d["type"] = k.type;
  d["presence"] = k.presence == Presence::kOptional   ? "optional"
                  : k.presence == Presence::kRequired ? "required"
                                                      : "group";
  d["group"] = k.group;
  return d;
}

// Every registered plugin of every kind of the one table of kinds (extend/plugin_kinds.hpp).
py::list registry_listing() {
  py::list out;
  for (const PluginKind& kind : plugin_kinds()) {
    py::list common_keys;
    for (const auto& k : kind.common_keys()) common_keys.append(key_dict(k));
    for (const PluginEntryInfo& e : kind.entries()) {
      py::dict d;
      d["kind"] = kind.id;
      d["type"] = e.type;
      d["summary"] = e.summary;
      d["origin"] = e.origin;
      py::list keys;
      for (const auto& k : e.keys) keys.append(key_dict(k));
      d["keys"] = keys;
      d["common_keys"] = common_keys;
      py::list groups;
      for (const auto& [g, what] : e.groups) groups.append(py::make_tuple(g, what));
      d["groups"] = groups;
      out.append(d);
    }
  }
  return out;
}

// The table of kinds itself: each kind's id, its namespace (plural) and where files name it.
py::list kinds_listing() {
  py::list out;
  for (const PluginKind& kind : plugin_kinds()) {
    py::dict d;
    d["kind"] = kind.id;
    d["plural"] = kind.plural;
    d["name"] = kind.name;
    d["heading"] = kind.heading;
    out.append(d);
  }
  return out;
}

}  // namespace
}  // namespace redres::python

PYBIND11_MODULE(_redres, m) {
  using namespace redres;
  using namespace redres::python;
  m.doc() = "redres: redundancy resolution of redundant manipulators (the C++ core; use the `redres` package)";
  // The version is written once, in the top-level CMakeLists.txt's project(); CMake passes it here.
  m.attr("__version__") = REDRES_VERSION;

  auto& config_error = py::register_exception<ConfigError>(m, "ConfigError", PyExc_ValueError);
  config_error.doc() =
      "A bad robot or scenario file, or a bad plugin configuration: the message starts with file:line:col.";

  py::class_<KinematicsResult>(m, "Kinematics", "Kinematics at one configuration (copies).")
      .def_readonly("theta", &KinematicsResult::theta, "the configuration (n,)")
      .def_readonly("f", &KinematicsResult::f, "task coordinates f(theta): position, then orientation for a pose")
      .def_readonly("J", &KinematicsResult::J, "task Jacobian (m, n)")
      .def_readonly("w", &KinematicsResult::w, "manipulability w = det(J J')")
      .def_readonly("grad_w", &KinematicsResult::grad_w, "d w / d theta (n,)")
      .def_readonly("mu", &KinematicsResult::mu, "Yoshikawa's sqrt(det(J J'))")
      .def_readonly("grad_mu", &KinematicsResult::grad_mu, "d mu / d theta (n,)")
      .def_readonly("ee_pose", &KinematicsResult::ee_pose, "end-effector pose in the world frame (4, 4)")
      .def_readonly("link_frames", &KinematicsResult::link_frames, "each joint's frame after its motion (4, 4)")
      .def_property_readonly(
          "frame_names", [](const KinematicsResult& k) { return frame_names(*k.robot); },
          "the robot's named frames (each joint's link, a URDF's other links, 'end_effector'), in order")
      .def(
          "frame_pose",
          [](const KinematicsResult& k, const std::string& name) {
            return frame_pose_of(*k.robot, *k.data, name, "Kinematics.frame_pose");
          },
          py::arg("name"), "world pose (4, 4) of the named frame; an unknown name raises ValueError")
      .def(
          "frame_jacobian",
          [](const KinematicsResult& k, const std::string& name, const std::optional<Eigen::VectorXd>& point) {
            return frame_jacobian_of(*k.robot, *k.data, name, point, "Kinematics.frame_jacobian");
          },
          py::arg("name"), py::arg("point") = py::none(),
          "Jacobian (6, n) [v; omega] of the named frame, its origin moved by `point` (3,) in the frame's own axes "
          "(default: the origin)")
      .def("__repr__", [](const KinematicsResult& k) { return "<redres.Kinematics w=" + std::to_string(k.w) + ">"; });

  py::class_<PyRobot>(m, "Robot", "A robot model (redres.Robot.load(path) reads a robot TOML file, DH or URDF).")
      .def_static(
          "load",
          [](const std::filesystem::path& path) {
            return PyRobot{std::make_shared<const RobotModel>(load_robot(path))};
          },
          py::arg("path"), "Loads a robot TOML file; a bad file raises redres.ConfigError with file:line:col.")
      .def_property_readonly(
          "name", [](const PyRobot& r) { return r.model->name(); }, "the robot's name (its file's `name`)")
      .def_property_readonly(
          "kind", [](const PyRobot& r) { return std::string(to_string(r.model->kind())); }, "'planar' or 'spatial'")
      .def_property_readonly(
          "dof", [](const PyRobot& r) { return r.model->dof(); }, "number of joints n")
      .def_property_readonly(
          "task_dim", [](const PyRobot& r) { return r.model->task_dim(); }, "task rows m")
      .def_property_readonly(
          "task_names", [](const PyRobot& r) { return r.model->task_names(); },
          "the task rows' names, e.g. ['x', 'y', 'z'] (the rows of f and J)")
      .def_property_readonly(
          "reference_names", [](const PyRobot& r) { return r.model->reference_names(); },
          "the reference rows' names (the entries of r_d and r_d_dot, and of StepContext.f)")
      .def_property_readonly(
          "joint_names",
          [](const PyRobot& r) {
            std::vector<std::string> names;
            for (const auto& j : r.model->joints()) names.push_back(j.name);
            return names;
          },
          "the joints' names, in order")
      .def_property_readonly(
          "lower_limits", [](const PyRobot& r) { return Eigen::VectorXd(r.model->lower_limits()); }, "theta^- (n,)")
      .def_property_readonly(
          "upper_limits", [](const PyRobot& r) { return Eigen::VectorXd(r.model->upper_limits()); }, "theta^+ (n,)")
      .def_property_readonly(
          "home", [](const PyRobot& r) { return Eigen::VectorXd(r.model->home()); }, "the home configuration (n,)")
      .def_property_readonly(
          "source", [](const PyRobot& r) { return r.model->source(); }, "the file the robot was read from")
      .def(
          "kinematics", [](const PyRobot& r, const Eigen::VectorXd& theta) { return kinematics_of(r.model, theta); },
          py::arg("theta"),
          "f, J, w, grad w, mu, grad mu, the end-effector pose and the link frames at theta (numpy arrays); the named "
          "frames' poses and Jacobians through frame_pose(name) and frame_jacobian(name, point).")
      .def(
          "velocity_limits",
          [](const PyRobot& r, const Eigen::VectorXd& theta) {
            const RobotModel& model = *r.model;
            Eigen::VectorXd lo(model.dof()), hi(model.dof());
            model.velocity_limits(checked_theta(model, theta, "Robot.velocity_limits"), lo, hi);
            return py::make_tuple(lo, hi);
          },
          py::arg("theta"), "(lower, upper): each joint's velocity-limit law at theta (e.g. the push-rod law)")
      .def("__repr__", [](const PyRobot& r) {
        return "<redres.Robot '" + r.model->name() + "' " + to_string(r.model->kind()) + ", " +
               std::to_string(r.model->dof()) + " joints>";
      });

  py::class_<PyResult>(m, "Result",
                       "A finished run: the trajectory's columns as numpy arrays (views, no copy) and its summary.\n\n"
                       "result['theta_1'] is one column; result.columns lists them; result.summary is summary.json "
                       "as a dict; result.failures counts failed steps (a failed step is a status, not an exception).")
      .def_property_readonly(
          "columns", [](const PyResult& r) { return r.run->trajectory.columns(); },
          "the trajectory's column names, in order (trajectory.csv's heading)")
      .def(
          "__getitem__",
          [](py::object self, const std::string& name) {
            const PyResult& r = self.cast<const PyResult&>();
            const auto& cols = r.run->trajectory.columns();
            const auto it = std::find(cols.begin(), cols.end(), name);
            if (it == cols.end()) throw py::key_error("no column '" + name + "' in the trajectory");
            return column_view(r.run->trajectory, static_cast<std::size_t>(it - cols.begin()), self);
          },
          py::arg("name"), "one column as a read-only numpy view (no copy); KeyError for an unknown name")
      .def(
          "__contains__",
          [](const PyResult& r, const std::string& name) {
            const auto& cols = r.run->trajectory.columns();
            return std::find(cols.begin(), cols.end(), name) != cols.end();
          },
          py::arg("name"), "whether the trajectory has the column `name`")
      .def_property_readonly(
          "values",
          [](py::object self) {
            const Trajectory& tr = self.cast<const PyResult&>().run->trajectory;
            py::array a(
                py::dtype::of<double>(), {static_cast<py::ssize_t>(tr.size()), static_cast<py::ssize_t>(tr.width())},
                {static_cast<py::ssize_t>(sizeof(double) * tr.width()), static_cast<py::ssize_t>(sizeof(double))},
                tr.values().data(), self);
            py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
            return a;
          },
          "every column, (rows, columns), row-major, a view")
      .def_property_readonly(
          "summary_json", [](const PyResult& r) { return to_json(*r.summary); },
          "summary.json of the run, as text (Result.summary parses it)")
      .def_property_readonly(
          "failures", [](const PyResult& r) { return r.run->failures; }, "the number of failed steps")
      .def_property_readonly(
          "first_failure", [](const PyResult& r) { return r.run->first_failure; },
          "when and why the first step failed (empty when none did)")
      .def_property_readonly(
          "status", [](const PyResult& r) { return r.run->failures == 0 ? "ok" : "failed_steps"; },
          "'ok', or 'failed_steps' when a step failed")
      .def_property_readonly(
          "engine", [](const PyResult& r) { return r.run->engine(); }, "the LVI engine the run used")
      .def_property_readonly(
          "name", [](const PyResult& r) { return r.summary->name; }, "the scenario's name")
      .def_property_readonly(
          "final_theta",
          [](const PyResult& r) {
            return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(
                r.summary->final_theta.data(), static_cast<Eigen::Index>(r.summary->final_theta.size())));
          },
          "theta at the end of the run (n,)")
      .def_property_readonly(
          "wall_time_s", [](const PyResult& r) { return r.run->wall_time_s; }, "how long the run took (s, wall clock)")
      .def(
          "write",
          [](const PyResult& r, const std::filesystem::path& dir, const std::string& record) {
            write_run(*r.scenario->robot, *r.run, *r.summary, dir, parse_record(record));
          },
          py::arg("out_dir"), py::arg("record") = "all",
          "Writes trajectory.csv, frames.csv and summary.json, as `redres run --out` does; record is 'all', "
          "'every=N' or 'none', as --record.")
      .def("__repr__", [](const PyResult& r) {
        return "<redres.Result '" + r.summary->name + "' " + std::to_string(r.run->trajectory.size()) + " rows, " +
               (r.run->failures == 0 ? std::string("ok") : std::to_string(r.run->failures) + " failed steps") + ">";
      });

  py::class_<PyScenario>(m, "Scenario", "A loaded scenario (redres.Scenario.load(path, overrides)).")
      .def_static(
          "_load",
          [](const std::filesystem::path& path,
             const std::optional<std::vector<std::pair<std::string, std::string>>>& o) {
            return PyScenario{std::make_shared<Scenario>(load_scenario(path, override_strings(o)))};
          },
          py::arg("path"), py::arg("overrides") = py::none())
      .def_property_readonly(
          "name", [](const PyScenario& s) { return s.scenario->name; }, "the scenario's name")
      .def_property_readonly(
          "source", [](const PyScenario& s) { return s.scenario->source; }, "the file the scenario was read from")
      .def_property_readonly(
          "robot",
          [](const PyScenario& s) {
            return PyRobot{std::shared_ptr<const RobotModel>(s.scenario, s.scenario->robot.get())};
          },
          "its robot, with the task rows the scenario chose")
      .def_property_readonly(
          "theta0", [](const PyScenario& s) { return Eigen::VectorXd(s.scenario->theta0); },
          "the start configuration (n,)")
      .def_property_readonly(
          "duration", [](const PyScenario& s) { return s.scenario->duration; }, "T (s)")
      .def_property_readonly(
          "step", [](const PyScenario& s) { return s.scenario->tau; }, "tau (s)")
      .def_property_readonly(
          "steps", [](const PyScenario& s) { return s.scenario->steps(); }, "N = T / tau")
      .def_property_readonly(
          "engine", [](const PyScenario& s) { return s.scenario->engine.type; }, "the LVI engine's name")
      .def("run", &run_scenario, py::arg("progress") = py::none(),
           "Runs the scenario from theta0 over [0, T] and returns a redres.Result. The GIL is released while it "
           "runs (Python threads can run other scenarios meanwhile); progress(fraction, t), if given, is called "
           "about 200 times. Failed steps are counted in the result, not raised.")
      .def("controller", &controller_of,
           "A redres.Controller for this scenario's robot, scheme, engine and path (sharing them: its steps and "
           "the scenario's runs take turns).")
      .def("__repr__", [](const PyScenario& s) {
        return "<redres.Scenario '" + s.scenario->name + "' " + std::to_string(s.scenario->steps()) + " steps>";
      });

  py::class_<LevelStepInfo>(m, "LevelInfo", "one priority level's outcome at a step (docs/tasks.md)")
      .def_readonly("priority", &LevelStepInfo::priority, "the level's priority (0 the highest)")
      .def_readonly("status", &LevelStepInfo::status,
                    "'solved', 'relaxed' (its tasks in least squares), 'not_run' (skipped) or why it failed")
      .def_readonly("iterations", &LevelStepInfo::iterations, "the engine's iterations at this level")
      .def_readonly("residual", &LevelStepInfo::residual, "||e(u)||_2 of the level's LVI at its answer")
      .def_readonly("task_error", &LevelStepInfo::task_error, "the largest miss of its tasks' rows at the answer")
      .def_readonly("diagnosis", &LevelStepInfo::diagnosis, "why it was relaxed, skipped or failed")
      .def("__repr__", [](const LevelStepInfo& l) {
        return "LevelInfo(priority=" + std::to_string(l.priority) + ", status='" + l.status + "')";
      });
  py::class_<StepInfo>(m, "StepInfo", "One step's solver outcome.")
      .def_readonly("status", &StepInfo::status,
                    "'solved' (the engine stopped and its answer passed the certificate), 'max_iterations', "
                    "'infeasible', 'numerical_error', 'inaccurate_primal', 'inaccurate_dual', "
                    "'inaccurate_complementarity', 'invalid_problem', 'relaxed' or 'braked'")
      .def_readonly("primal_residual", &StepInfo::primal_residual,
                    "the certificate's largest miss of a row or bound (docs/engines.md)")
      .def_readonly("dual_residual", &StepInfo::dual_residual, "the certificate's largest stationarity residual")
      .def_readonly("complementarity", &StepInfo::complementarity,
                    "the certificate's largest force of an inequality row that is not active")
      .def_property_readonly("ok", &StepInfo::ok, "status == 'solved'")
      .def_readonly("iterations", &StepInfo::iterations, "the engine's iterations (all levels together)")
      .def_readonly("residual", &StepInfo::residual, "||e(u)||_2 of the LVI at the answer")
      .def_readonly("engine", &StepInfo::engine, "the engine that ran (a fallback names itself)")
      .def_readonly("diagnosis", &StepInfo::diagnosis, "empty when solved; else which joint, bound, row and plugin")
      .def_readonly("levels", &StepInfo::levels,
                    "with tasks or objectives at several priorities (docs/tasks.md): each level's LevelInfo, highest "
                    "first; empty otherwise")
      .def("__repr__", [](const StepInfo& i) {
        return "<redres.StepInfo " + i.status + ", " + std::to_string(i.iterations) + " iterations>";
      });

  py::class_<PyController>(m, "Controller",
                           "The per-step API for a caller's own loop (use redres.Controller, which documents it).")
      .def(py::init(&make_controller), py::arg("robot"), py::arg("objectives"), py::arg("constraints"),
           py::arg("engine") = "newton", py::arg("path") = py::none(), py::arg("T") = 1.0, py::arg("tau") = 0.01,
           py::arg("theta0") = py::none(), py::arg("level") = "velocity", py::arg("tasks") = py::list(),
           py::arg("regularization") = py::none(), py::arg("orientation_turn") = py::none(),
           "Builds the scheme from the objectives, constraints and tasks (their priorities make the levels) for the "
           "robot, at `level` ('velocity' or 'acceleration'), the engine (a name or an engine configuration) and the "
           "optional path (placed at f(theta0)); T and tau in s; regularization is the eps of every priority level "
           "(default 1e-9); orientation_turn the rotation the end effector turns through over T (rad). Sized here: "
           "step() allocates nothing.")
      .def("__repr__",
           [](py::handle p) {
             if (made(p) == nullptr) return std::string("<redres.Controller, never made>");
             PyController& c = live(p);
             const Controller& k = *c.controller;
             return "<redres.Controller robot '" + k.robot().name() + "', " + std::to_string(k.robot().dof()) +
                    " joints, " + std::to_string(k.scheme().objectives().size()) + " objectives, " +
                    std::to_string(k.scheme().constraints().size()) + " constraints, " +
                    std::to_string(k.scheme().tasks().size()) + " tasks, engine '" + std::string(k.engine_name()) +
                    "'>";
           })
      .def(
          "step",
          [](py::handle p, const Eigen::VectorXd& theta, double t) {
            PyController& c = live(p);
            return step_in_turn(c, [&](Controller& k) { k.step(theta, t, c.out); });
          },
          py::arg("theta"), py::arg("t"),
          "One control step at (theta, t) with r_d and r_d_dot from the path: returns (theta_dot, StepInfo).")
      .def(
          "step",
          [](py::handle p, const Eigen::VectorXd& theta, const Eigen::VectorXd& theta_dot_measured, double t) {
            PyController& c = live(p);
            return step_in_turn(c, [&](Controller& k) { k.step(theta, theta_dot_measured, t, c.out); });
          },
          py::arg("theta"), py::arg("theta_dot_measured"), py::arg("t"),
          "One control step with the joint velocity the caller measured (plugins read it as "
          "Context.theta_dot_measured; the acceleration level starts from it): returns (theta_dot, StepInfo).")
      .def(
          "step",
          [](py::handle p, const Eigen::VectorXd& theta, double t, const Eigen::VectorXd& r_d,
             const Eigen::VectorXd& r_d_dot) {
            PyController& c = live(p);
            return step_in_turn(c, [&](Controller& k) { k.step(theta, t, r_d, r_d_dot, c.out); });
          },
          py::arg("theta"), py::arg("t"), py::arg("r_d"), py::arg("r_d_dot"),
          "One control step with the caller's r_d and r_d_dot (reference_dim entries): returns (theta_dot, StepInfo).")
      .def(
          "step",
          [](py::handle p, const Eigen::VectorXd& theta, double t, const Eigen::VectorXd& r_d,
             const Eigen::VectorXd& r_d_dot, const Eigen::VectorXd& r_d_ddot) {
            PyController& c = live(p);
            return step_in_turn(c, [&](Controller& k) { k.step(theta, t, r_d, r_d_dot, r_d_ddot, c.out); });
          },
          py::arg("theta"), py::arg("t"), py::arg("r_d"), py::arg("r_d_dot"), py::arg("r_d_ddot"),
          "The same with the caller's r_d_ddot too (an acceleration-level scheme): returns (theta_dot, StepInfo).")
      .def(
          "set_applied",
          [](py::handle p, const Eigen::VectorXd& theta_dot) {
            PyController& c = live(p);
            in_turn(c, "Controller.set_applied", [&](Controller& k) { k.set_applied(theta_dot); });
          },
          py::arg("theta_dot"),
          "The command actually applied this step (the next step's theta_dot_prev), when it is not the step's own.")
      .def(
          "set_period",
          [](py::handle p, double tau) {
            PyController& c = live(p);
            in_turn(c, "Controller.set_period", [&](Controller& k) { k.set_period(tau); });
          },
          py::arg("tau"), "The period of the steps from now on (s), when the loop runs at another than tau.")
      .def(
          "set_failure_policy",
          [](py::handle p, const std::string& policy, double relax_weight, double recover_error) {
            PyController& c = live(p);
            FailurePolicy f{};
            try {
              f = failure_policy_from_name(policy);
            } catch (const std::invalid_argument& e) {
              throw std::invalid_argument(std::string("Controller.set_failure_policy: ") + e.what());
            }
            in_turn(c, "Controller.set_failure_policy",
                    [&](Controller& k) { k.set_failure_policy(f, relax_weight, recover_error); });
          },
          py::arg("policy"), py::arg("relax_weight") = 1e4, py::arg("recover_error") = 1e-3,
          "What a failed step does: 'hold', 'stop' (gives up as 'hold' does; the caller's loop ends), 'relax' or "
          "'brake', the names of a scenario's [solver] on_infeasible (docs/motion.md).")
      .def_property_readonly(
          "failure_policy",
          [](py::handle p) {
            PyController& c = live(p);
            return in_turn(c, "Controller.failure_policy",
                           [](Controller& k) { return std::string(failure_policy_name(k.failure_policy())); });
          },
          "the failure policy's name: 'hold', 'stop', 'relax' or 'brake'")
      .def_property_readonly(
          "theta_ddot",
          [](py::handle p) {
            PyController& c = live(p);
            return in_turn(c, "Controller.theta_ddot", [&c](Controller&) { return Eigen::VectorXd(c.out.theta_ddot); });
          },
          "the last step's commanded acceleration (rad/s^2)")
      .def_property_readonly(
          "theta_dot_prev",
          [](py::handle p) {
            PyController& c = live(p);
            return in_turn(c, "Controller.theta_dot_prev",
                           [](Controller& k) { return Eigen::VectorXd(k.theta_dot_prev()); });
          },
          "the previous step's command as the last step's plugins saw it")
      .def(
          "reset",
          [](py::handle p) {
            PyController& c = live(p);
            in_turn(c, "Controller.reset", [](Controller& k) { k.reset(); });
          },
          "Forgets the engine's warm start.")
      .def_property_readonly(
          "robot",
          [](py::handle p) {
            PyController& c = live(p);
            return PyRobot{c.robot};
          },
          "the robot the controller steps")
      .def_property_readonly(
          "r_d",
          [](py::handle p) {
            PyController& c = live(p);
            return in_turn(c, "Controller.r_d", [](Controller& k) { return Eigen::VectorXd(k.r_d()); });
          },
          "the last step's desired task coordinates")
      .def_property_readonly(
          "r_d_dot",
          [](py::handle p) {
            PyController& c = live(p);
            return in_turn(c, "Controller.r_d_dot", [](Controller& k) { return Eigen::VectorXd(k.r_d_dot()); });
          },
          "the last step's desired task velocity")
      .def_property_readonly(
          "f",
          [](py::handle p) {
            PyController& c = live(p);
            return in_turn(c, "Controller.f", [](Controller& k) { return Eigen::VectorXd(k.kinematics().f); });
          },
          "the last step's task coordinates f(theta)")
      .def_property_readonly(
          "w",
          [](py::handle p) {
            PyController& c = live(p);
            return in_turn(c, "Controller.w", [](Controller& k) { return k.kinematics().w; });
          },
          "the last step's manipulability w = det(J J')")
      .def_property_readonly(
          "qp",
          [](py::handle p) {
            PyController& c = live(p);
            return qp_dict(in_turn(c, "Controller.qp", [](Controller& k) { return QpProblem(k.qp()); }));
          },
          "the last step's QP (copies): W, zeta, J, d, A, b, lo, hi (the first priority level's)")
      .def(
          "level_qp",
          [](py::handle p, int level) {
            PyController& c = live(p);
            return qp_dict(in_turn(c, "Controller.level_qp", [level](Controller& k) {
              const int levels = static_cast<int>(k.levels().levels().size());
              if (level < 0 || level >= std::max(levels, 1)) {
                throw std::invalid_argument("Controller.level_qp: level " + std::to_string(level) +
                                            " is not one of the scheme's " + std::to_string(std::max(levels, 1)) +
                                            " priority levels");
              }
              return QpProblem(k.levels().problem(level));
            }));
          },
          py::arg("level"),
          "the last step's QP of priority level `level` (0 is the first; a lower level's rows hold the levels above "
          "it at their optima), as `qp` gives it");

  m.def(
      "_sweep",
      [](const std::filesystem::path& file, unsigned jobs, const std::string& shard, const std::string& out_dir) {
        const SweepSpec spec = load_sweep(file);
        // Without out_dir, a sweep that writes its runs gets a new private directory (never a fixed name in the
        // shared temporary directory), named in a warning so that the runs are not lost.
        std::filesystem::path dir = out_dir;
        if (dir.empty() && spec.write_runs) {
          dir = make_private_directory("redres-sweep-");
          const std::string where = "redres.sweep: no out_dir; the runs are written into " + dir.string();
          if (PyErr_WarnEx(PyExc_UserWarning, where.c_str(), 1) < 0) throw py::error_already_set();
        }
        SweepTable table;
        {
          py::gil_scoped_release release;
          table = run_sweep(spec, shard.empty() ? SweepShard{} : parse_shard(shard), jobs, dir);
        }
        return py::make_tuple(table.columns, typed_rows(table, spec));
      },
      py::arg("file"), py::arg("jobs") = 0, py::arg("shard") = "", py::arg("out_dir") = "");
  m.def(
      "_comparison",
      [](const std::vector<const PyResult*>& results) {
        py::list columns, rows;
        for (const ComparisonColumn& c : comparison_columns()) {
          columns.append(py::make_tuple(std::string(c.key), std::string(c.heading)));
        }
        std::vector<const RunSummary*> summaries;
        for (const PyResult* r : results) {
          summaries.push_back(r->summary.get());
          py::list row;
          for (const ComparisonColumn& c : comparison_columns()) {
            row.append(std::visit([](const auto& v) { return py::cast(v); }, summary_value(*r->summary, c.field)));
          }
          rows.append(row);
        }
        return py::make_tuple(columns, rows, comparison_markdown(summaries));
      },
      py::arg("results"));
  m.def(
      "trajectory_column_groups",
      []() {
        py::list out;
        for (const TrajectoryColumnGroup& g : trajectory_column_groups()) {
          const char* count = g.count == ColumnCount::kPerJoint       ? "n"
                              : g.count == ColumnCount::kPerReference ? "m_ref"
                              : g.count == ColumnCount::kOne          ? "1"
                                                                      : "1 (orientation rows)";
          py::dict d;
          d["name"] = std::string(g.name);
          d["count"] = count;
          d["unit"] = std::string(g.unit);
          d["meaning"] = std::string(g.meaning);
          out.append(d);
        }
        return out;
      },
      "The standard columns of trajectory.csv (and of a Result), group by group: name (or prefix), count ('1', "
      "'n' per joint, 'm_ref' per reference row), unit and meaning; the same list the C++ run fills its rows from.");
  m.def("solve_qp", &solve_qp, py::arg("qp"), py::arg("engine") = "newton", py::arg("tolerance") = 1e-9,
        py::arg("max_iterations") = 100000,
        "Solves one QP (a dict with Controller.qp's keys; A and b may be left out) with the named engine from a cold "
        "start. Returns x, y, z, status ('solved' only when the certificate holds), engine, iterations, residual, "
        "primal_residual, dual_residual, complementarity and diagnosis.");
  m.def("_registry", &registry_listing);
  m.def("_plugin_kinds", &kinds_listing);
  m.def(
      "mujoco_available", [] { return mujoco_available(); },
      "Whether this build of redres has the MuJoCo plant ([plant] kind = \"mujoco\"; docs/plant.md).");
  bind_python_plugins(m);
}

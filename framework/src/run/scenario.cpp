#include "redres/run/scenario.hpp"

#include <array>
#include <cmath>
#include <optional>
#include <sstream>
#include <string_view>
#include <utility>

#include "config/overrides.hpp"
#include "redres/config/plugin_loader.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/run/simulation.hpp"

namespace redres {

namespace {

// The [solver] table's keys that are the run's, not the engine's: what a failed step does. Read through a schema,
// like the engine's keys, so that `redres plugins` lists them with their defaults and rules.
enum class Policy { kHold, kStop, kRelax, kContinue };
auto enum_names(Policy) {
  return std::array{
      std::pair{Policy::kHold, std::string_view("hold")}, std::pair{Policy::kStop, std::string_view("stop")},
      std::pair{Policy::kRelax, std::string_view("relax")}, std::pair{Policy::kContinue, std::string_view("continue")}};
}
struct SolverPolicy {
  Policy on_infeasible = Policy::kHold;
  double relax_weight = 1e4;
  static const Schema<SolverPolicy>& schema() {
    using C = SolverPolicy;
    static const Schema<C> s{
        {field("on_infeasible", &C::on_infeasible, "",
               "what a step whose QP is not solved does: hold (theta_dot = 0; `continue` is the same), stop (the run "
               "ends there), relax (solves the elastic QP, rows relaxed, every bound kept)"),
         field("relax_weight", &C::relax_weight, "", "rho of the elastic QP; only with on_infeasible = \"relax\"",
               rule<double>("a weight in [1, 1e8]", [](double w) { return w >= 1.0 && w <= 1e8; }))},
        {},
        {}};
    return s;
  }
};

Eigen::VectorXd read_theta0(const TableReader& r, const RobotModel& robot) {
  if (!r.has("theta0")) return robot.home();
  const toml::node& node = *r.raw().get("theta0");
  const toml::array* arr = node.as_array();
  if (arr == nullptr || static_cast<int>(arr->size()) != robot.dof()) {
    r.fail("theta0", "expected an array of " + std::to_string(robot.dof()) + " joint positions (numbers or " +
                         "formulas such as \"pi/4\")");
  }
  Eigen::VectorXd theta(robot.dof());
  for (int j = 0; j < robot.dof(); ++j) {
    const toml::node& el = (*arr)[static_cast<std::size_t>(j)];
    double v = 0.0;
    bool number = false;
    try {
      number = read_number_or_formula(el, v);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(location_of(r.file(), el), "key 'theta0': entry " + std::to_string(j + 1) + ": " + e.what());
    }
    if (!number) {
      throw ConfigError(location_of(r.file(), el), "key 'theta0': entry " + std::to_string(j + 1) +
                                                       ": expected a number or a formula string, got " +
                                                       describe_type(el));
    }
    if (!std::isfinite(v)) {
      std::ostringstream s;
      s << "key 'theta0': entry " << j + 1 << ": expected a finite number, got " << v;
      throw ConfigError(location_of(r.file(), el), s.str());
    }
    const JointSpec& jt = robot.joint(j);
    if (v < jt.lower || v > jt.upper) {
      std::ostringstream s;
      s.precision(10);
      s << "key 'theta0': joint '" << jt.name << "' = " << v << " is outside its limits [" << jt.lower << ", "
        << jt.upper << "]";
      throw ConfigError(location_of(r.file(), el), s.str());
    }
    theta(j) = v;
  }
  return theta;
}

}  // namespace

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

Scenario load_scenario(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  const std::shared_ptr<TomlFile> parsed = parse_toml_file(file);
  apply_overrides(parsed->root, overrides);
  const std::shared_ptr<const TomlFile> doc = parsed;
  const TableReader r = TableReader::root(doc, "scenario");

  load_plugins_from(r);  // plugin libraries first: their plugins may be named below (and in the robot file)
  Scenario s;
  s.source = file.string();
  s.name = r.string("name", file.stem().string());
  if (s.name.empty()) r.fail("name", "expected a non-empty name (or leave `name` out: the file's stem)");
  try {
    s.robot = std::make_unique<RobotModel>(load_robot(r.path("robot")));
  } catch (const ConfigError& e) {
    // A robot file that is missing, a directory or empty is reported at the key that names it; an error inside the
    // file keeps its own file:line:col.
    if (e.where().line == 0) r.fail("robot", e.what());
    throw;
  }
  if (r.has("task")) {
    // The scenario chooses the task rows (the robot file's `task` is only the default), so that one robot file
    // serves position and pose scenarios alike.
    RobotSpec spec = s.robot->spec();
    read_task(r, spec);
    s.robot = std::make_unique<RobotModel>(std::move(spec));
  }
  s.theta0 = read_theta0(r, *s.robot);
  s.duration = r.number("duration");
  s.tau = r.number("step");
  if (!(s.duration > 0.0)) r.fail("duration", "expected a duration T > 0 s");
  if (!(s.tau > 0.0 && s.tau <= s.duration)) r.fail("step", "expected a step 0 < tau <= duration");
  if (!(s.duration / s.tau <= kMaxSteps)) {
    std::ostringstream m;
    m << "expected at most " << static_cast<long long>(kMaxSteps) << " steps, got duration / step = " << s.duration
      << " / " << s.tau << " = " << s.duration / s.tau << " (use a longer step or a shorter duration)";
    r.fail("step", m.str());
  }
  if (std::abs(s.steps() * s.tau - s.duration) > 1e-9 * s.duration) {
    r.fail("step", "expected a step that divides the duration (T / tau = " + std::to_string(s.duration / s.tau) + ")");
  }
  s.integrator = r.choice("integrator", {"euler", "heun"}, "euler") == "euler" ? Integrator::kEuler : Integrator::kHeun;

  KinematicsData k(*s.robot);
  compute_kinematics(*s.robot, s.theta0, k, KinematicsLevel::kPosition);
  PathContext pc;
  pc.dim = s.robot->kind() == ChainKind::kPlanar ? 2 : 3;
  pc.start.head(pc.dim) = k.f.head(pc.dim);
  pc.duration = s.duration;
  const TableReader path_table = r.table("path");
  s.path = make_path(TableReader(path_table.file_ptr(), path_table.raw(), "path"), pc);

  s.scheme = std::make_unique<Scheme>(Scheme::from_toml(r, *s.robot, s.duration, s.tau));
  const std::size_t width = trajectory_width(s);
  if (const double bytes = (s.steps() + 1.0) * static_cast<double>(width) * 8.0; bytes > kMaxTableBytes) {
    std::ostringstream m;
    m << "expected a run whose recorded table fits in " << kMaxTableBytes / (1024.0 * 1024 * 1024) << " GiB, got "
      << s.steps() + 1 << " rows of " << width << " columns (" << bytes / (1024.0 * 1024 * 1024)
      << " GiB; use a longer step or a shorter duration)";
    r.fail("step", m.str());
  }
  if (r.has("solver")) {
    const TableReader t = r.table("solver");
    const TableReader solver(t.file_ptr(), t.raw(), "solver");
    SolverPolicy policy;
    read_config(solver, SolverPolicy::schema(), policy);
    s.on_infeasible = policy.on_infeasible == Policy::kStop    ? OnInfeasible::kStop
                      : policy.on_infeasible == Policy::kRelax ? OnInfeasible::kRelax
                                                               : OnInfeasible::kHold;
    s.relax_weight = policy.relax_weight;
    if (solver.has("relax_weight") && s.on_infeasible != OnInfeasible::kRelax) {
      solver.fail("relax_weight", "is used only with on_infeasible = \"relax\" (on_infeasible is \"" +
                                      std::string(solver.string("on_infeasible", "hold")) + "\")");
    }
    s.engine = make_engine(solver);
  } else {
    s.engine = make_engine("projection");
  }
  if (auto orientation = r.optional_table("orientation")) {
    const TableReader o(orientation->file_ptr(), orientation->raw(), "orientation");
    const bool planar = s.robot->kind() == ChainKind::kPlanar;
    if (!s.robot->has_orientation_rows()) {
      r.fail("orientation",
             "the task has no orientation rows: set task = \"pose\" (in the scenario or the robot file)");
    }
    if (o.has("turn")) {
      if (planar) {
        s.orientation_turn = Eigen::Vector3d(0.0, 0.0, o.number("turn"));
      } else {
        const std::vector<double> w = o.numbers("turn", 3);
        s.orientation_turn = Eigen::Vector3d(w[0], w[1], w[2]);
      }
      const double bound = *physical_bound("rad");
      if (!(s.orientation_turn.cwiseAbs().maxCoeff() <= bound)) {
        std::ostringstream m;
        m << "expected |x| <= " << bound << " rad (a physical range), got " << s.orientation_turn.cwiseAbs().maxCoeff();
        o.fail("turn", m.str());
      }
    }
    o.finish();
  }
  if (auto out = r.optional_table("output")) {
    const TableReader o(out->file_ptr(), out->raw(), "output");
    s.record = read_record(o, "record", "all");
    s.plots = o.boolean("plots", false);
    s.animate = o.boolean("animate", false);
    o.finish();
  }
  r.finish();
  return s;
}

}  // namespace redres

// The checks of a scenario's parts against each other: the [solver] policy for a failed step against the robot's
// acceleration limits, the scheme against the integrator and the size of the recorded table, the [plant] against the
// registered plants; and the [solver] policy's keys (redres/run/scenario.hpp).

#include "redres/run/scenario.hpp"

#include "run/scenario_reading.hpp"

#include <sstream>
#include <string>

#include "redres/control/engine_registry.hpp"
#include "redres/run/plants.hpp"
#include "redres/run/simulation.hpp"

namespace redres {

namespace {

// The [solver] table's keys that are the run's, not the engine's: what a failed step does. Read through a schema,
// like the engine's keys, so that `redres plugins` lists them with their defaults and rules.
struct SolverPolicy {
  FailurePolicy on_infeasible = FailurePolicy::kRelax;
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
               "acceleration limits (which refuses hold), else relax"),
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

}  // namespace

const std::vector<KeyInfo>& solver_policy_keys() {
  static const std::vector<KeyInfo> keys = describe_keys(SolverPolicy::schema());
  return keys;
}

namespace scenario_detail {

void read_solver(const TableReader& r, Scenario& s) {
  const bool limits = s.robot->has_acceleration_limits();
  s.on_infeasible = limits ? FailurePolicy::kBrake : FailurePolicy::kRelax;
  if (!r.has("solver")) {
    s.engine = EngineSpec{};  // projection, with the default settings
    return;
  }
  const TableReader t = r.table("solver");
  const TableReader solver(t.file_ptr(), t.raw(), "solver");
  SolverPolicy policy;
  read_config(solver, SolverPolicy::schema(), policy);
  if (solver.has("on_infeasible")) {
    s.on_infeasible = policy.on_infeasible;
    s.on_infeasible_given = true;
  }
  s.relax_weight = policy.relax_weight;
  s.recover_error = policy.recover_error;
  s.max_task_error = policy.max_task_error;
  const std::string chosen = solver.has("on_infeasible") ? std::string(solver.string("on_infeasible"))
                                                         : std::string(limits ? "brake" : "relax") + "\", the default";
  if (s.on_infeasible == FailurePolicy::kHold && limits) {
    solver.fail("on_infeasible", "\"" + chosen + "\" stops every joint at once, a velocity jump that robot '" +
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
    solver.fail("recover_error", "is used only with on_infeasible = \"brake\" (on_infeasible is \"" + chosen + "\")");
  }
  s.engine = read_engine_spec(solver);
}

void check_scheme(const TableReader& r, const Scenario& s) {
  if (s.scheme->order() == ControlOrder::kAcceleration && s.integrator == Integrator::kHeun) {
    r.fail("integrator",
           "an acceleration-level scheme ([scheme] level = \"acceleration\") integrates "
           "its own way (constant acceleration over each step, exact); leave "
           "`integrator` out or set it to \"euler\"");
  }
  const std::size_t width = trajectory_width(s);
  if (const double bytes = (s.steps() + 1.0) * static_cast<double>(width) * 8.0; bytes > kMaxTableBytes) {
    std::ostringstream m;
    m << "expected a run whose recorded table fits in " << kMaxTableBytes / (1024.0 * 1024 * 1024) << " GiB, got "
      << s.steps() + 1 << " rows of " << width << " columns (" << bytes / (1024.0 * 1024 * 1024)
      << " GiB; use a longer step or a shorter duration)";
    r.fail("step", m.str());
  }
}

void check_plant(const TableReader& r, Scenario& s) {
  const PlantType* type = plant_registry().find(s.plant.kind);
  if (type == nullptr) {
    std::string names;
    for (const PlantType& t : plant_registry().types()) names += (names.empty() ? "\"" : ", \"") + t.name + "\"";
    r.fail("kind", "unknown plant \"" + s.plant.kind + "\"; expected one of " + names);
  }
  if (type->check) type->check(r, s);
}

}  // namespace scenario_detail

}  // namespace redres

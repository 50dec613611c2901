#include "redres/run/run_summary.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>

#include <nlohmann/json.hpp>

#include "redres/model/convex.hpp"

namespace redres {

const Metric* RunSummary::metric(const std::string& plugin, const std::string& metric_name) const {
  for (const auto& pm : metrics) {
    if (pm.plugin != plugin) continue;
    for (const auto& m : pm.metrics) {
      if (m.name == metric_name) return &m;
    }
  }
  return nullptr;
}

namespace {

// Every number in `j` is finite; otherwise a std::runtime_error names its path (e.g. "solver.max_residual").
void require_finite_numbers(const nlohmann::json& j, const std::string& path) {
  if (j.is_number_float() && !std::isfinite(j.get<double>())) {
    throw std::runtime_error("summary.json: '" + path + "' is " + std::to_string(j.get<double>()) +
                             ", not a finite number (JSON has no inf or nan); this is a bug in the figure's source");
  }
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) require_finite_numbers(value, path.empty() ? key : path + "." + key);
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) require_finite_numbers(j[i], path + "[" + std::to_string(i) + "]");
  }
}

// The spells in which the task was not met as asked (solver_status not 0), the longest of them, and when the run
// came back from it.
void task_losses(const Trajectory& tr, double tau, SolverStats& out) {
  const std::size_t c_t = tr.column("t"), c_status = tr.column("solver_status"), rows = tr.size();
  std::size_t lost = 0, best_start = 0, best_length = 0;
  for (std::size_t r = 0; r < rows;) {
    if (tr(r, c_status) == 0.0) {
      ++r;
      continue;
    }
    const std::size_t start = r;
    while (r < rows && tr(r, c_status) != 0.0) ++r;
    ++out.task_lost_spells;
    lost += r - start;
    if (r - start > best_length) {
      best_start = start;
      best_length = r - start;
    }
  }
  out.task_lost_time = static_cast<double>(lost) * tau;
  if (best_length == 0) return;
  std::ostringstream msg;
  msg.precision(6);
  const std::size_t end = best_start + best_length;  // the first row after the spell, if any
  msg << "t = " << tr(best_start, c_t) << " s to " << tr(end - 1, c_t) << " s (" << best_length << " steps); ";
  if (end < rows) {
    msg << "back at " << tr(end, c_t) << " s";
  } else {
    msg << "not back by the end";
  }
  out.longest_task_loss = msg.str();
}

}  // namespace

RunSummary summarise(const Scenario& s, const RunResult& run) {
  const RobotModel& robot = *s.robot;
  const Trajectory& tr = run.trajectory;
  const int n = robot.dof();
  const std::size_t rows = tr.size();
  REDRES_REQUIRE(rows > 0, "summarise", "the run recorded at least one step");

  // Column indices, looked up once.
  const std::size_t c_err = tr.column("position_error"), c_w = tr.column("manipulability"),
                    c_res = tr.column("solver_residual"), c_it = tr.column("solver_iterations");
  std::vector<std::size_t> c_th, c_thd, c_vlo, c_vhi, c_lo, c_hi;
  for (int j = 1; j <= n; ++j) {
    const std::string J = std::to_string(j);
    c_th.push_back(tr.column("theta_" + J));
    c_thd.push_back(tr.column("theta_dot_" + J));
    c_vlo.push_back(tr.column("vel_lo_" + J));
    c_vhi.push_back(tr.column("vel_hi_" + J));
    c_lo.push_back(tr.column("lo_" + J));
    c_hi.push_back(tr.column("hi_" + J));
  }
  double max_err = 0.0, w_min = 1e300, w_max = -1e300, w_sum = 0.0, angle_viol = 0.0, vel_viol = 0.0;
  double max_res = 0.0, it_sum = 0.0, it_max = 0.0;
  long active_steps = 0;
  for (std::size_t r = 0; r < rows; ++r) {
    max_err = std::max(max_err, tr(r, c_err));
    const double wv = tr(r, c_w);
    w_min = std::min(w_min, wv);
    w_max = std::max(w_max, wv);
    w_sum += wv;
    max_res = std::max(max_res, tr(r, c_res));
    it_sum += tr(r, c_it);
    it_max = std::max(it_max, tr(r, c_it));
    bool active = false;
    for (int j = 0; j < n; ++j) {
      const auto k = static_cast<std::size_t>(j);
      const double th = tr(r, c_th[k]), thd = tr(r, c_thd[k]);
      angle_viol = std::max({angle_viol, th - robot.upper_limits()(j), robot.lower_limits()(j) - th});
      vel_viol = std::max({vel_viol, thd - tr(r, c_vhi[k]), tr(r, c_vlo[k]) - thd});
      const double blo = tr(r, c_lo[k]), bhi = tr(r, c_hi[k]);
      active = active || std::abs(thd - blo) <= 1e-9 * (1.0 + std::abs(blo)) ||
               std::abs(thd - bhi) <= 1e-9 * (1.0 + std::abs(bhi));
    }
    active_steps += active ? 1 : 0;
  }
  const auto joint_velocity_norm = [&](std::size_t r) {
    double sq = 0.0;
    for (std::size_t k = 0; k < c_thd.size(); ++k) sq += std::pow(tr(r, c_thd[k]), 2);
    return std::sqrt(sq);
  };

  RunSummary out;
  out.name = s.name;
  out.label = s.label.empty() ? s.name : s.label;
  out.source = s.source;
  out.status = run.interrupted ? "interrupted" : run.stopped ? "stopped" : "complete";
  out.steps = s.steps();
  out.tau = s.tau;
  out.duration = s.duration;
  out.integrator = s.integrator == Integrator::kEuler ? "euler" : "heun";
  out.path = s.path->description();
  out.max_position_error = max_err;
  out.final_position_error = tr(rows - 1, c_err);
  out.max_task_error = s.max_task_error;
  out.task_error_exceeded = !(max_err <= s.max_task_error);
  out.initial_joint_velocity_norm = joint_velocity_norm(0);
  out.final_joint_velocity_norm = joint_velocity_norm(rows - 1);
  out.manipulability = {tr(0, c_w), tr(rows - 1, c_w), w_min, w_sum / static_cast<double>(rows), w_max};
  out.max_joint_angle_violation = std::max(0.0, angle_viol);
  out.max_joint_velocity_violation = std::max(0.0, vel_viol);
  out.steps_with_active_bounds = active_steps;
  out.max_joint_acceleration = run.max_joint_acceleration;
  out.max_joint_jerk = run.max_joint_jerk;
  out.max_joint_acceleration_violation = run.max_joint_acceleration_violation;
  out.max_joint_jerk_violation = run.max_joint_jerk_violation;
  out.steps_over_acceleration_limit = run.steps_over_acceleration_limit;
  out.steps_over_jerk_limit = run.steps_over_jerk_limit;
  for (int j = 0; j < n; ++j) out.final_theta.push_back(tr(rows - 1, c_th[static_cast<std::size_t>(j)]));
  out.solver.engine = run.engine();
  out.solver.mean_iterations = it_sum / static_cast<double>(rows);
  out.solver.max_iterations = it_max;
  out.solver.max_residual = max_res;
  out.solver.failures = run.failures;
  out.solver.first_failure = run.first_failure;
  out.solver.stopped = run.stopped;
  out.solver.on_infeasible = std::string(failure_policy_name(s.on_infeasible));
  out.solver.braked_steps = run.braked_steps;
  out.solver.held_steps = run.held_steps;
  out.solver.relaxed_steps = run.relaxed_steps;
  out.solver.max_relaxed_task_error = run.max_relaxed_task_error;
  out.solver.first_relaxed = run.first_relaxed;
  task_losses(tr, s.tau, out.solver);
  out.wall_time_s = run.wall_time_s;
  out.plant_kind = s.plant.kind;
  if (run.plant) {
    out.plant = *run.plant;
    out.plant.mjcf.clear();
  }
  out.robot.name = robot.name();
  out.robot.kind = to_string(robot.kind());
  out.robot.task_rows = robot.task_names();
  const Eigen::Vector3d base = robot.base().translation();
  out.robot.base_position = {base.x(), base.y(), base.z()};
  for (int j = 0; j < n; ++j) {
    out.robot.joint_names.push_back(robot.joint(j).name);
    out.robot.lower_limits.push_back(robot.lower_limits()(j));
    out.robot.upper_limits.push_back(robot.upper_limits()(j));
    out.robot.link_lengths.push_back(robot.joint(j).length);
  }
  for (const auto& l : robot.link_shapes()) out.robot.link_shapes.push_back({l.link + 1, l.spec});
  out.robot.visuals = robot.visuals();
  out.robot.base = robot.base();
  // Each plugin's figures from the recorded run and its data of the run (none without one: a run made elsewhere).
  const SchemeData* data = run.plugin_data.get();
  const auto collect = [&](const Plugin& p, const std::vector<std::unique_ptr<PluginData>>* datas, std::size_t k) {
    const PluginOutput* output = output_of(p);
    if (!p.active() || output == nullptr) return;
    const PluginData* own = datas != nullptr && k < datas->size() ? (*datas)[k].get() : nullptr;
    PluginMetrics pm{p.name(), {}};
    output->summarise(robot, tr, own, pm.metrics);
    if (!pm.metrics.empty()) out.metrics.push_back(std::move(pm));
    std::vector<ShapeSpec> shapes;
    output->scene_obstacles(shapes);
    for (auto& shape : shapes) out.obstacles.push_back({p.name(), std::move(shape)});
  };
  const auto& objectives = s.scheme->objectives();
  const auto& constraints = s.scheme->constraints();
  for (std::size_t k = 0; k < objectives.size(); ++k) collect(*objectives[k], data ? &data->objectives : nullptr, k);
  for (std::size_t k = 0; k < constraints.size(); ++k) collect(*constraints[k], data ? &data->constraints : nullptr, k);
  const auto& tasks = s.scheme->tasks();
  for (std::size_t k = 0; k < tasks.size(); ++k) collect(*tasks[k], data ? &data->tasks : nullptr, k);
  return out;
}

namespace {

nlohmann::json vector_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// A shape: its kind, sizes and pose in its owner's frame (docs/output_formats.md).
nlohmann::json shape_json(const ShapeSpec& shape) {
  const Eigen::Isometry3d T = shape.pose();
  const Eigen::Matrix3d R = T.linear();
  nlohmann::json j = {{"shape", std::string(config_io::enum_name(shape.shape))}};
  switch (shape.shape) {
    case ShapeSpec::Kind::kSphere: j["radius"] = shape.radius.value_or(0.0); break;
    case ShapeSpec::Kind::kCapsule:
    case ShapeSpec::Kind::kCylinder:
      j["radius"] = shape.radius.value_or(0.0);
      j["length"] = shape.axis_length();
      break;
    case ShapeSpec::Kind::kBox: j["size"] = shape.size.value_or(std::array<double, 3>{0.0, 0.0, 0.0}); break;
    case ShapeSpec::Kind::kConvex:
      // The mesh it was made from, its counts, and its vertices' bounding box (centred on its pose) as `size`.
      j["file"] = shape.file.value_or("").string();
      if (shape.hull) {
        j["vertices"] = shape.hull->vertices.size();
        j["faces"] = shape.hull->faces.size();
        j["size"] = vector_json(2.0 * shape.hull->half_extent);
      }
      break;
    case ShapeSpec::Kind::kOctree:
    case ShapeSpec::Kind::kPoints: {
      // The file, and its occupied cells (centre, edge; cloud frame): every k-th of them past 3,000, for plots.
      j["file"] = shape.file.value_or("").string();
      j["radius"] = shape.radius.value_or(0.0);
      if (shape.cloud) {
        const auto cells = occupied_cells(*shape.cloud);
        const std::size_t step = cells.size() / 3000 + 1;
        nlohmann::json list = nlohmann::json::array();
        for (std::size_t i = 0; i < cells.size(); i += step) list.push_back(cells[i]);
        j["cells"] = std::move(list);
        j["cells_total"] = cells.size();
      }
      break;
    }
  }
  j["position"] = vector_json(T.translation());
  j["rotation"] = {vector_json(R.row(0).transpose()), vector_json(R.row(1).transpose()),
                   vector_json(R.row(2).transpose())};
  return j;
}

// An obstacle: its plugin, its shape at t = 0 in the world frame, and its velocity.
nlohmann::json obstacle_json(const ObstacleFacts& o) {
  nlohmann::json j = {{"plugin", o.plugin}};
  j.update(shape_json(o.shape));
  j["velocity"] = o.shape.velocity.value_or(std::array<double, 3>{0.0, 0.0, 0.0});
  return j;
}

}  // namespace

namespace {

using S = RunSummary;
SummaryValue text(const std::string& v) { return v; }
SummaryValue count(long v) { return v; }

}  // namespace

const std::vector<SummaryField>& summary_fields() {
  static const std::vector<SummaryField> fields{
      {"name", "string", "scenario name", [](const S& s) { return text(s.name); }},
      {"label", "string", "the run's name in legends and tables (the scenario's `label`; default: its `name`)",
       [](const S& s) { return text(s.label); }},
      {"source", "string", "the scenario file as given on the command line", [](const S& s) { return text(s.source); }},
      {"status", "string",
       "`\"complete\"`; `\"stopped\"` (at its first failed step, `on_infeasible = \"stop\"`); or `\"interrupted\"` (by "
       "SIGINT or SIGTERM: the rows up to the step it was at)",
       [](const S& s) { return text(s.status); }},
      {"steps", "integer", "round(T / tau)", [](const S& s) { return count(s.steps); }},
      {"tau", "number", "step (s)", [](const S& s) { return SummaryValue(s.tau); }},
      {"duration", "number", "T (s)", [](const S& s) { return SummaryValue(s.duration); }},
      {"integrator", "string", "`euler` or `heun`", [](const S& s) { return text(s.integrator); }},
      {"path", "string", "the path's description, e.g. `letter_r (3 strokes, 0.4154 m, cycloidal per stroke)`",
       [](const S& s) { return text(s.path); }},
      {"max_position_error", "number", "largest `position_error` (m)",
       [](const S& s) { return SummaryValue(s.max_position_error); }},
      {"final_position_error", "number", "`position_error` at t = T (m)",
       [](const S& s) { return SummaryValue(s.final_position_error); }},
      {"max_task_error", "number", "the bound on `max_position_error` ([solver] max_task_error, m)",
       [](const S& s) { return SummaryValue(s.max_task_error); }},
      {"task_error_exceeded", "boolean",
       "`max_position_error` > `max_task_error`: the run is no success (exit code 1) however many steps were solved",
       [](const S& s) { return SummaryValue(s.task_error_exceeded); }},
      {"initial_joint_velocity_norm", "number", "norm of theta_dot at t = 0 (rad/s)",
       [](const S& s) { return SummaryValue(s.initial_joint_velocity_norm); }},
      {"final_joint_velocity_norm", "number", "norm of theta_dot at t = T (rad/s)",
       [](const S& s) { return SummaryValue(s.final_joint_velocity_norm); }},
      {"manipulability.initial", "number", "w = det(J J') at t = 0",
       [](const S& s) { return SummaryValue(s.manipulability.initial); }},
      {"manipulability.final", "number", "w at t = T", [](const S& s) { return SummaryValue(s.manipulability.final); }},
      {"manipulability.min", "number", "the smallest w of the run",
       [](const S& s) { return SummaryValue(s.manipulability.min); }},
      {"manipulability.mean", "number", "the mean of w over the rows",
       [](const S& s) { return SummaryValue(s.manipulability.mean); }},
      {"manipulability.max", "number", "the largest w of the run",
       [](const S& s) { return SummaryValue(s.manipulability.max); }},
      {"max_joint_angle_violation", "number >= 0",
       "largest excursion of any theta_i beyond theta_i^- or theta_i^+ (rad)",
       [](const S& s) { return SummaryValue(s.max_joint_angle_violation); }},
      {"max_joint_velocity_violation", "number >= 0",
       "largest excursion of any theta_dot_i beyond its velocity law `vel_lo_i` or `vel_hi_i` (rad/s)",
       [](const S& s) { return SummaryValue(s.max_joint_velocity_violation); }},
      {"max_joint_acceleration", "array of n numbers",
       "per joint, the largest \\|acceleration\\| of the commands the arm was given, (applied_k - applied_{k-1}) / tau "
       "(Heun's average counts; a held step's zero too) (rad/s^2)",
       [](const S& s) { return SummaryValue(s.max_joint_acceleration); }},
      {"max_joint_jerk", "array of n numbers", "per joint, the largest \\|jerk\\| of those commands (rad/s^3)",
       [](const S& s) { return SummaryValue(s.max_joint_jerk); }},
      {"max_joint_acceleration_violation", "array of n numbers >= 0, or empty",
       "per joint, the largest excursion of that acceleration beyond the robot's `acceleration_limit` at the step's "
       "theta (0 when never; empty when the robot gives none)",
       [](const S& s) { return SummaryValue(s.max_joint_acceleration_violation); }},
      {"max_joint_jerk_violation", "array of n numbers >= 0, or empty", "the same against the robot's `jerk_limit`",
       [](const S& s) { return SummaryValue(s.max_joint_jerk_violation); }},
      {"steps_over_acceleration_limit", "integer",
       "steps whose command leaves some joint's acceleration limit by more than 1e-9 (1 + \\|limit\\|)",
       [](const S& s) { return count(s.steps_over_acceleration_limit); }},
      {"steps_over_jerk_limit", "integer", "the same for the jerk limits",
       [](const S& s) { return count(s.steps_over_jerk_limit); }},
      {"steps_with_active_bounds", "integer",
       "rows in which some theta_dot_i is at lo_i or hi_i, to within 1e-9 (1 + abs(bound))",
       [](const S& s) { return count(s.steps_with_active_bounds); }},
      {"final_theta", "array of n numbers", "theta at t = T", [](const S& s) { return SummaryValue(s.final_theta); }},
      {"solver.engine", "string",
       "the engines that ran, in the order first used, joined by `+` (e.g. `projection`, `newton+projection`)",
       [](const S& s) { return text(s.solver.engine); }},
      {"solver.mean_iterations", "number", "mean of `solver_iterations`",
       [](const S& s) { return SummaryValue(s.solver.mean_iterations); }},
      {"solver.max_iterations", "number", "largest `solver_iterations` (written as a JSON floating-point number)",
       [](const S& s) { return SummaryValue(s.solver.max_iterations); }},
      {"solver.max_residual", "number", "largest `solver_residual`",
       [](const S& s) { return SummaryValue(s.solver.max_residual); }},
      {"solver.failures", "integer",
       "solves whose status is neither `solved` nor `relaxed`: the rows whose `solver_status` is not 0, plus, with "
       "`heun`, the failed second QPs; plus the solved rows whose state a constraint reports as violated (two bodies "
       "overlapping, [collision.md](collision.md#when-a-step-fails))",
       [](const S& s) { return count(s.solver.failures); }},
      {"solver.first_failure", "string",
       "`t = <t> s: <status>: <diagnosis>` for the first failed solve (for a Heun second QP, t is the time of its "
       "prediction, t + tau), or `t = <t> s: constraint '<name>': <what>` for a violated state; empty if none",
       [](const S& s) { return text(s.solver.first_failure); }},
      {"solver.stopped", "boolean",
       "the run ended at its first failed step (`[solver] on_infeasible = \"stop\"`): its last row is that step's, "
       "before T",
       [](const S& s) { return SummaryValue(s.solver.stopped); }},
      {"solver.on_infeasible", "string", "the policy: `\"hold\"`, `\"stop\"`, `\"relax\"` or `\"brake\"`",
       [](const S& s) { return text(s.solver.on_infeasible); }},
      {"solver.held_steps", "integer",
       "failed steps held with theta_dot = 0 (the rows before T whose `solver_status` is none of 0, 6 and 7)",
       [](const S& s) { return count(s.solver.held_steps); }},
      {"solver.braked_steps", "integer",
       "failed steps that braked: every row whose `solver_status` is 7 (the last row's too); the arm decelerated "
       "within its acceleration limits; counted in `solver.failures`",
       [](const S& s) { return count(s.solver.braked_steps); }},
      {"solver.relaxed_steps", "integer",
       "steps solved with the rows relaxed (`solver_status` 6); they are not failures",
       [](const S& s) { return count(s.solver.relaxed_steps); }},
      {"solver.max_relaxed_task_error", "number",
       "the largest max_r \\|J_r theta_dot - d_r\\| of a relaxed step (the task rows' units per second: m/s, rad/s); 0 "
       "when none",
       [](const S& s) { return SummaryValue(s.solver.max_relaxed_task_error); }},
      {"solver.first_relaxed", "string",
       "`t = <t> s: rows relaxed (weight ...), missed by ... at most, after <status>: <diagnosis>` for the first "
       "relaxed step; empty if none",
       [](const S& s) { return text(s.solver.first_relaxed); }},
      {"solver.task_lost_time", "number",
       "how long the task was not met as asked: the rows whose `solver_status` is not 0 (relaxed, braked, held or "
       "failed) times tau (s)",
       [](const S& s) { return SummaryValue(s.solver.task_lost_time); }},
      {"solver.task_lost_spells", "integer", "the runs of consecutive such rows",
       [](const S& s) { return count(s.solver.task_lost_spells); }},
      {"solver.longest_task_loss", "string",
       "`t = <a> s to <b> s (<k> steps); back at <c> s` for the longest run of such rows, `<c>` the first solved row "
       "after it, or `...; not back by the end`; empty if none",
       [](const S& s) { return text(s.solver.longest_task_loss); }},
      {"plant.kind", "string",
       "`kinematic` or `mujoco` ([plant] kind; docs/plant.md); the `plant.*` figures below "
       "are empty (or 0) on the kinematic plant",
       [](const S& s) { return text(s.plant_kind); }},
      {"plant.actuator", "string", "`velocity_servo`, `impedance` or `ideal_velocity`",
       [](const S& s) { return text(s.plant.actuator); }},
      {"plant.timestep", "number", "MuJoCo's time step (s)", [](const S& s) { return SummaryValue(s.plant.timestep); }},
      {"plant.delay", "number", "the measurement's delay (s)", [](const S& s) { return SummaryValue(s.plant.delay); }},
      {"plant.max_torque", "array of n numbers", "per joint, the largest \\|torque\\| of any MuJoCo step (N m or N)",
       [](const S& s) { return SummaryValue(s.plant.max_torque); }},
      {"plant.effort_limit", "array of n numbers", "per joint, the robot's effort limit (N m or N; 0: none)",
       [](const S& s) {
         std::vector<double> v;
         for (const double e : s.plant.effort_limit) v.push_back(std::isfinite(e) ? e : 0.0);
         return SummaryValue(v);
       }},
      {"plant.max_torque_ratio", "number",
       "the largest `max_torque` / `effort_limit` over the joints with a limit (1: a torque reached its limit)",
       [](const S& s) {
         double r = 0.0;
         for (std::size_t j = 0; j < s.plant.max_torque.size() && j < s.plant.effort_limit.size(); ++j) {
           if (std::isfinite(s.plant.effort_limit[j])) r = std::max(r, s.plant.max_torque[j] / s.plant.effort_limit[j]);
         }
         return SummaryValue(r);
       }},
      {"plant.max_torque_rate", "array of n numbers",
       "per joint, the largest \\|torque rate\\| between MuJoCo steps (N m/s or N/s)",
       [](const S& s) { return SummaryValue(s.plant.max_torque_rate); }},
      {"plant.max_contacts", "integer", "the most contacts involving the robot at any MuJoCo step",
       [](const S& s) { return count(s.plant.max_contacts); }},
      {"plant.deepest_penetration", "number", "the deepest penetration MuJoCo found (m)",
       [](const S& s) { return SummaryValue(s.plant.deepest_penetration); }},
      {"plant.first_contact_time", "number", "when the first contact began (s; -1: never)",
       [](const S& s) {
         return SummaryValue(s.plant.contact_pairs.empty() ? -1.0 : s.plant.contact_pairs.front().first_time);
       }},
      {"plant.contact_pairs", "array of strings",
       "every pair of bodies that touched, by first contact: `\"a vs b from t = ... s (deepest ... m, ... steps)\"`",
       [](const S& s) {
         std::vector<std::string> v;
         for (const PlantContactPair& p : s.plant.contact_pairs) {
           std::ostringstream line;
           line << p.a << " vs " << p.b << " from t = " << p.first_time << " s (deepest " << p.deepest << " m, "
                << p.steps << " steps)";
           v.push_back(line.str());
         }
         return SummaryValue(v);
       }},
      {"plant.kinematic_max_position_error", "number",
       "with `[plant] kinematic_comparison = true`: the same scenario on the kinematic plant, its `max_position_error` "
       "(m), beside this run's (under dynamics); 0 otherwise",
       [](const S& s) { return SummaryValue(s.plant.kinematic_max_position_error); }},
      {"plant.control_step_us", "number", "mean wall time of one controller step (us)",
       [](const S& s) {
         return SummaryValue(s.plant.control_steps > 0
                                 ? 1e6 * s.plant.controller_seconds / static_cast<double>(s.plant.control_steps)
                                 : 0.0);
       }},
      {"plant.mujoco_step_us", "number", "mean wall time of one MuJoCo step, the plant's torques included (us)",
       [](const S& s) {
         return SummaryValue(
             s.plant.mujoco_steps > 0 ? 1e6 * s.plant.mujoco_seconds / static_cast<double>(s.plant.mujoco_steps) : 0.0);
       }},
      {"wall_time_s", "number", "wall-clock time of the integration loop (s)",
       [](const S& s) { return SummaryValue(s.wall_time_s); }},
      {"robot.name", "string", "robot name", [](const S& s) { return text(s.robot.name); }},
      {"robot.kind", "string", "`planar` or `spatial`", [](const S& s) { return text(s.robot.kind); }},
      {"robot.joint_names", "array of n strings", "joint names",
       [](const S& s) { return SummaryValue(s.robot.joint_names); }},
      {"robot.task_rows", "array of m strings",
       "the task's rows, e.g. `[\"x\", \"y\"]` or `[\"x\", \"y\", \"z\", \"wy\", \"wz\"]`",
       [](const S& s) { return SummaryValue(s.robot.task_rows); }},
      {"robot.base_position", "array of 3 numbers",
       "the origin of the robot's `[base]` pose in the world (m); plots draw the base there",
       [](const S& s) { return SummaryValue(s.robot.base_position); }},
      {"robot.lower_limits", "array of n numbers", "theta^-",
       [](const S& s) { return SummaryValue(s.robot.lower_limits); }},
      {"robot.upper_limits", "array of n numbers", "theta^+",
       [](const S& s) { return SummaryValue(s.robot.upper_limits); }},
      {"robot.link_lengths", "array of n numbers", "planar link lengths l_i (the `length` key; 0 where not given)",
       [](const S& s) { return SummaryValue(s.robot.link_lengths); }},
      {"robot.link_shapes", "array of objects",
       "the links' collision shapes (the robot file's `collision`), in joint order: `joint` (1-based, the frame of "
       "`frames.csv` it moves with) and the shape keys below, its pose in that joint's frame (a capsule along the link "
       "resolved to its end points). `[]` for a robot without collision shapes",
       nullptr},
      {"robot.visuals", "array of objects",
       "a URDF robot's visual elements (what `redres view` draws; docs/viewer.md): `joint` (1-based, the frame of "
       "`frames.csv` it rides in; 0: the base's links, posed in the world), `link`, `shape` (`mesh`, `box`, "
       "`cylinder`, `sphere`), `file` (a mesh found; empty with `problem` saying why when not), `scale`, `size`, "
       "`radius`, `length`, `position`, `rotation` (as for the shapes), `rgba` (the material's colour, when given). "
       "`[]` for other robots",
       nullptr},
      {"metrics", "object", "figures reported by plugins, by plugin instance name; see below", nullptr},
      {"obstacles", "array of objects",
       "the obstacles of the active plugins that have some (`obstacle_avoidance`), for drawing; see below. `[]` when "
       "there are none",
       nullptr},
  };
  return fields;
}

std::string summary_fields_markdown() {
  std::string md = "| key | type | meaning |\n|---|---|---|\n";
  for (const SummaryField& f : summary_fields()) {
    md += "| `" + std::string(f.key) + "` | " + std::string(f.type) + " | " + std::string(f.meaning) + " |\n";
  }
  return md;
}

SummaryValue summary_value(const RunSummary& summary, std::string_view key) {
  std::string known;
  for (const SummaryField& f : summary_fields()) {
    if (f.key == key && f.get != nullptr) return f.get(summary);
    if (f.get != nullptr) known += (known.empty() ? "" : ", ") + std::string(f.key);
  }
  throw std::invalid_argument("summary_value: no summary field '" + std::string(key) + "'; known fields: " + known);
}

std::string to_json(const RunSummary& s) {
  nlohmann::json j = nlohmann::json::object();
  for (const SummaryField& f : summary_fields()) {
    if (f.get == nullptr) continue;  // a structured part, written below
    // "a.b" is key b of table a.
    nlohmann::json* at = &j;
    std::string_view key = f.key;
    for (std::size_t dot = key.find('.'); dot != std::string_view::npos; dot = key.find('.')) {
      at = &(*at)[std::string(key.substr(0, dot))];
      key.remove_prefix(dot + 1);
    }
    std::visit([&](const auto& v) { (*at)[std::string(key)] = v; }, f.get(s));
  }
  nlohmann::json metrics = nlohmann::json::object();
  for (const auto& pm : s.metrics) {
    nlohmann::json figures = nlohmann::json::object();
    for (const auto& m : pm.metrics) {
      figures[m.name] =
          m.values.size() == 1 && !m.per_joint ? nlohmann::json(m.values.front()) : nlohmann::json(m.values);
    }
    metrics[pm.plugin] = figures;
  }
  nlohmann::json obstacles = nlohmann::json::array();
  for (const auto& o : s.obstacles) obstacles.push_back(obstacle_json(o));
  nlohmann::json link_shapes = nlohmann::json::array();
  for (const auto& l : s.robot.link_shapes) {
    nlohmann::json shape = {{"joint", l.joint}};
    shape.update(shape_json(l.shape));
    link_shapes.push_back(shape);
  }
  j["robot"]["link_shapes"] = link_shapes;
  nlohmann::json visuals = nlohmann::json::array();
  for (const VisualSpec& v : s.robot.visuals) {
    static const char* const kinds[] = {"mesh", "box", "cylinder", "sphere"};
    const Eigen::Isometry3d pose = v.joint < 0 ? s.robot.base * v.pose : v.pose;
    const Eigen::Matrix3d R = pose.linear();
    nlohmann::json e = {
        {"joint", v.joint + 1},
        {"link", v.link},
        {"shape", kinds[static_cast<int>(v.kind)]},
        {"position", vector_json(pose.translation())},
        {"rotation",
         {vector_json(R.row(0).transpose()), vector_json(R.row(1).transpose()), vector_json(R.row(2).transpose())}}};
    switch (v.kind) {
      case VisualSpec::Kind::kMesh:
        e["file"] = v.file.string();
        e["scale"] = vector_json(v.scale);
        if (!v.problem.empty()) e["problem"] = v.problem;
        break;
      case VisualSpec::Kind::kBox: e["size"] = v.size; break;
      case VisualSpec::Kind::kCylinder:
        e["radius"] = v.radius;
        e["length"] = v.length;
        break;
      case VisualSpec::Kind::kSphere: e["radius"] = v.radius; break;
    }
    if (v.rgba) e["rgba"] = *v.rgba;
    visuals.push_back(std::move(e));
  }
  j["robot"]["visuals"] = visuals;
  j["metrics"] = metrics;
  j["obstacles"] = obstacles;
  require_finite_numbers(j, "");
  return j.dump(2);
}

}  // namespace redres

#include "redres/run/run_summary.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

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
  out.source = s.source;
  out.status = run.interrupted ? "interrupted" : run.stopped ? "stopped" : "complete";
  out.steps = s.steps();
  out.tau = s.tau;
  out.duration = s.duration;
  out.integrator = s.integrator == Integrator::kEuler ? "euler" : "heun";
  out.path = s.path->description();
  out.max_position_error = max_err;
  out.final_position_error = tr(rows - 1, c_err);
  out.initial_joint_velocity_norm = joint_velocity_norm(0);
  out.final_joint_velocity_norm = joint_velocity_norm(rows - 1);
  out.manipulability = {tr(0, c_w), tr(rows - 1, c_w), w_min, w_sum / static_cast<double>(rows), w_max};
  out.max_joint_angle_violation = std::max(0.0, angle_viol);
  out.max_joint_velocity_violation = std::max(0.0, vel_viol);
  out.steps_with_active_bounds = active_steps;
  for (int j = 0; j < n; ++j) out.final_theta.push_back(tr(rows - 1, c_th[static_cast<std::size_t>(j)]));
  out.solver = {run.engine(), it_sum / static_cast<double>(rows), it_max, max_res, run.failures, run.first_failure,
                run.stopped};
  out.solver.on_infeasible = s.on_infeasible == OnInfeasible::kStop    ? "stop"
                             : s.on_infeasible == OnInfeasible::kRelax ? "relax"
                                                                       : "hold";
  out.solver.held_steps = run.held_steps;
  out.solver.relaxed_steps = run.relaxed_steps;
  out.solver.max_relaxed_task_error = run.max_relaxed_task_error;
  out.solver.first_relaxed = run.first_relaxed;
  out.wall_time_s = run.wall_time_s;
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
  const auto collect = [&](const Plugin& p) {
    if (!p.active()) return;
    PluginMetrics pm{p.name(), {}};
    p.summarise(robot, tr, pm.metrics);
    if (!pm.metrics.empty()) out.metrics.push_back(std::move(pm));
    std::vector<ShapeSpec> shapes;
    p.scene_obstacles(shapes);
    for (auto& shape : shapes) out.obstacles.push_back({p.name(), std::move(shape)});
  };
  for (const auto& o : s.scheme->objectives()) collect(*o);
  for (const auto& c : s.scheme->constraints()) collect(*c);
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

std::string to_json(const RunSummary& s) {
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
    nlohmann::json j = {{"joint", l.joint}};
    j.update(shape_json(l.shape));
    link_shapes.push_back(j);
  }
  const ManipulabilityStats& w = s.manipulability;
  const nlohmann::json j = {
      {"name", s.name},
      {"source", s.source},
      {"status", s.status},
      {"steps", s.steps},
      {"tau", s.tau},
      {"duration", s.duration},
      {"integrator", s.integrator},
      {"path", s.path},
      {"max_position_error", s.max_position_error},
      {"final_position_error", s.final_position_error},
      {"initial_joint_velocity_norm", s.initial_joint_velocity_norm},
      {"final_joint_velocity_norm", s.final_joint_velocity_norm},
      {"manipulability",
       {{"initial", w.initial}, {"final", w.final}, {"min", w.min}, {"mean", w.mean}, {"max", w.max}}},
      {"max_joint_angle_violation", s.max_joint_angle_violation},
      {"max_joint_velocity_violation", s.max_joint_velocity_violation},
      {"steps_with_active_bounds", s.steps_with_active_bounds},
      {"final_theta", s.final_theta},
      {"solver",
       {{"engine", s.solver.engine},
        {"mean_iterations", s.solver.mean_iterations},
        {"max_iterations", s.solver.max_iterations},
        {"max_residual", s.solver.max_residual},
        {"failures", s.solver.failures},
        {"first_failure", s.solver.first_failure},
        {"stopped", s.solver.stopped},
        {"on_infeasible", s.solver.on_infeasible},
        {"held_steps", s.solver.held_steps},
        {"relaxed_steps", s.solver.relaxed_steps},
        {"max_relaxed_task_error", s.solver.max_relaxed_task_error},
        {"first_relaxed", s.solver.first_relaxed}}},
      {"wall_time_s", s.wall_time_s},
      {"robot",
       {{"name", s.robot.name},
        {"kind", s.robot.kind},
        {"joint_names", s.robot.joint_names},
        {"task_rows", s.robot.task_rows},
        {"base_position", s.robot.base_position},
        {"lower_limits", s.robot.lower_limits},
        {"upper_limits", s.robot.upper_limits},
        {"link_lengths", s.robot.link_lengths},
        {"link_shapes", link_shapes}}},
      {"metrics", metrics},
      {"obstacles", obstacles},
  };
  require_finite_numbers(j, "");
  return j.dump(2);
}

}  // namespace redres

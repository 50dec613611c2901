#include "redres/scenario.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "redres/formula.hpp"

namespace redres {

namespace {

// --- overrides ---------------------------------------------------------------------------------------------------

[[noreturn]] void bad_override(const std::string& text, const std::string& why) {
  throw ConfigError({"--set " + text, 0, 0}, why);
}

void apply_override(toml::table& root, const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) bad_override(text, "expected key.path=value");
  const std::string key = text.substr(0, eq);
  const std::string value = text.substr(eq + 1);
  // The value as TOML (numbers, booleans, arrays, quoted strings); a bare word is a string.
  toml::table holder;
  try {
    holder = toml::parse("v = " + value, "--set " + key);
  } catch (const toml::parse_error&) {
    std::string quoted = "\"";
    for (char ch : value) {
      if (ch == '"' || ch == '\\') quoted += '\\';
      quoted += ch;
    }
    holder = toml::parse("v = " + quoted + "\"", "--set " + key);
  }
  toml::node& v = *holder.get("v");
  std::vector<std::string> parts;
  std::stringstream in(key);
  for (std::string p; std::getline(in, p, '.');) {
    if (p.empty()) bad_override(text, "empty component in key '" + key + "'");
    parts.push_back(p);
  }
  toml::node* cur = &root;
  for (std::size_t i = 0; i + 1 <= parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool last = i + 1 == parts.size();
    if (auto* t = cur->as_table()) {
      if (last) {
        t->insert_or_assign(part, std::move(v));
        return;
      }
      if (t->get(part) == nullptr) t->insert(part, toml::table{});
      cur = t->get(part);
    } else if (auto* a = cur->as_array()) {
      std::size_t idx = 0;
      try {
        idx = std::stoul(part);
      } catch (const std::exception&) {
        bad_override(text, "'" + part + "' is not an index into the array '" + parts[i - 1] + "'");
      }
      if (idx >= a->size()) {
        bad_override(text, "'" + parts[i - 1] + "' has " + std::to_string(a->size()) + " entries; index " + part +
                               " is out of range (indices start at 0)");
      }
      if (last) {
        a->replace(a->begin() + static_cast<std::ptrdiff_t>(idx), std::move(v));
        return;
      }
      cur = a->get(idx);
    } else {
      bad_override(text, "'" + parts[i - 1] + "' is a value, not a table");
    }
  }
}

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
    if (const auto* i = el.as_integer()) {
      v = static_cast<double>(i->get());
    } else if (const auto* f = el.as_floating_point()) {
      v = f->get();
    } else if (const auto* s = el.as_string()) {
      try {
        v = evaluate_constant(s->get());
      } catch (const std::invalid_argument& e) {
        throw ConfigError(location_of(r.file(), el), "key 'theta0': entry " + std::to_string(j + 1) + ": " + e.what());
      }
    } else {
      throw ConfigError(location_of(r.file(), el), "key 'theta0': entry " + std::to_string(j + 1) +
                                                       ": expected a number or a formula string, got " +
                                                       describe_type(el));
    }
    const JointSpec& jt = robot.joint(j);
    if (!std::isfinite(v) || v < jt.lower || v > jt.upper) {
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

int Scenario::steps() const { return static_cast<int>(std::lround(duration / tau)); }

Scenario load_scenario(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  const std::shared_ptr<TomlFile> parsed = parse_toml_file(file);
  for (const auto& o : overrides) apply_override(parsed->root, o);
  const std::shared_ptr<const TomlFile> doc = parsed;
  const TableReader r = TableReader::root(doc, "scenario");

  Scenario s;
  s.source = file.string();
  s.name = r.string("name", file.stem().string());
  s.robot = std::make_unique<RobotModel>(load_robot(r.path("robot")));
  s.theta0 = read_theta0(r, *s.robot);
  s.duration = r.number("duration");
  s.tau = r.number("step");
  if (!(s.duration > 0.0)) r.fail("duration", "expected a duration T > 0 s");
  if (!(s.tau > 0.0 && s.tau <= s.duration)) r.fail("step", "expected a step 0 < tau <= duration");
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

  s.scheme = std::make_unique<Scheme>(Scheme::from_toml(r, *s.robot));
  if (r.has("solver")) {
    const TableReader t = r.table("solver");
    s.engine = make_engine(TableReader(t.file_ptr(), t.raw(), "solver"));
  } else {
    s.engine = make_engine("projection");
  }
  if (auto out = r.optional_table("output")) {
    const TableReader o(out->file_ptr(), out->raw(), "output");
    s.plots = o.boolean("plots", false);
    o.finish();
  }
  r.finish();

  s.safety_margin = Eigen::VectorXd::Zero(s.robot->dof());
  for (const auto& c : s.scheme->constraints()) {
    if (c->type() != "joint_angle_margin" || !c->active()) continue;
    const toml::table cfg = c->config();
    const auto file_text = [&] {
      std::ostringstream o;
      o << cfg;
      return o.str();
    }();
    const auto f = parse_toml_string(file_text, "<joint_angle_margin>");
    s.safety_margin = s.safety_margin.cwiseMax(read_per_joint(TableReader::root(f), "margin", 0.0, s.robot->dof()));
  }
  return s;
}

double RunResult::at(std::size_t row, const std::string& name) const { return rows[row * columns.size() + column(name)]; }

std::size_t RunResult::column(const std::string& name) const {
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (columns[c] == name) return c;
  }
  throw std::out_of_range("RunResult: no column '" + name + "'");
}

RunResult simulate(Scenario& s, const ProgressCallback& progress) {
  const RobotModel& robot = *s.robot;
  const int n = robot.dof();
  const int m = robot.task_dim();
  const int position_rows = robot.kind() == ChainKind::kPlanar ? 2 : 3;
  RunResult run;
  auto& cols = run.columns;
  cols.emplace_back("t");
  const auto add = [&cols, n](const std::string& prefix) {
    for (int j = 1; j <= n; ++j) cols.push_back(prefix + std::to_string(j));
  };
  add("theta_");
  add("theta_dot_");
  add("lo_");
  add("hi_");
  for (const auto& name : robot.task_names()) cols.push_back("rd_" + name);
  for (const auto& name : robot.task_names()) cols.push_back("r_" + name);
  for (const char* c : {"position_error", "manipulability", "solver_iterations", "solver_residual"}) cols.emplace_back(c);
  add("vel_lo_");
  add("vel_hi_");
  cols.emplace_back("solver_status");
  const std::size_t width = cols.size();
  const int steps = s.steps();
  run.rows.assign(static_cast<std::size_t>(steps + 1) * width, 0.0);

  Controller ctrl(robot, *s.scheme, *s.engine, s.path.get(), s.duration, s.tau);
  ctrl.set_kinematics_level(KinematicsLevel::kManipulability);
  {
    KinematicsData k0(robot);
    compute_kinematics(robot, s.theta0, k0, KinematicsLevel::kPosition);
    if (m > position_rows) {
      ctrl.set_orientation_reference(robot.kind() == ChainKind::kPlanar ? Eigen::Vector3d(0, 0, k0.f(2))
                                                                        : Eigen::Vector3d(k0.f.tail<3>()));
    }
  }
  Eigen::VectorXd theta = s.theta0, x1(n), theta_pred(n), vlo(n), vhi(n);
  const char* engines[4] = {nullptr, nullptr, nullptr, nullptr};
  const auto start = std::chrono::steady_clock::now();
  const int report_every = std::max(1, steps / 200);

  for (int k = 0; k <= steps; ++k) {
    const double t = k == steps ? s.duration : k * s.tau;
    const StepOutput out = ctrl.step(theta, t);
    const KinematicsData& kin = ctrl.kinematics();
    const QpProblem& qp = ctrl.qp();
    robot.velocity_limits(theta, vlo, vhi);
    double* row = run.rows.data() + static_cast<std::size_t>(k) * width;
    std::size_t c = 0;
    row[c++] = t;
    for (int j = 0; j < n; ++j) row[c++] = theta(j);
    for (int j = 0; j < n; ++j) row[c++] = out.theta_dot(j);
    for (int j = 0; j < n; ++j) row[c++] = qp.lo(j);
    for (int j = 0; j < n; ++j) row[c++] = qp.hi(j);
    for (int r = 0; r < m; ++r) row[c++] = ctrl.r_d()(r);
    for (int r = 0; r < m; ++r) row[c++] = kin.f(r);
    row[c++] = (ctrl.r_d().head(position_rows) - kin.f.head(position_rows)).norm();
    row[c++] = kin.w;
    row[c++] = out.info.iterations;
    row[c++] = out.info.residual;
    for (int j = 0; j < n; ++j) row[c++] = vlo(j);
    for (int j = 0; j < n; ++j) row[c++] = vhi(j);
    row[c++] = static_cast<double>(static_cast<int>(out.info.status));
    for (auto& e : engines) {
      if (e == out.info.engine) break;
      if (e == nullptr) {
        e = out.info.engine;
        break;
      }
    }
    if (out.info.status != SolverStatus::kSolved) {
      if (run.failures++ == 0) {
        std::ostringstream msg;
        msg << "t = " << t << " s: " << to_string(out.info.status) << ": " << out.info.diagnosis;
        run.first_failure = msg.str();
      }
    }
    if (progress && (k % report_every == 0 || k == steps)) progress(static_cast<double>(k) / steps, t);
    if (k == steps) break;
    if (s.integrator == Integrator::kEuler) {
      theta += s.tau * out.theta_dot;
    } else {
      // Heun: average the slopes at theta and at the Euler prediction (one more QP per step).
      x1 = out.theta_dot;
      theta_pred = theta + s.tau * x1;
      const StepOutput out2 = ctrl.step(theta_pred, std::min(s.duration, t + s.tau));
      theta += 0.5 * s.tau * (x1 + out2.theta_dot);
    }
  }
  run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const char* e : engines) {
    if (e == nullptr) break;
    run.engine += (run.engine.empty() ? "" : "+") + std::string(e);
  }
  return run;
}

std::string summary_json(const Scenario& s, const RunResult& run) {
  const RobotModel& robot = *s.robot;
  const int n = robot.dof();
  const std::size_t rows = run.size();
  const auto col = [&](const std::string& name) { return run.column(name); };
  const std::size_t w = run.columns.size();
  const auto val = [&](std::size_t r, std::size_t c) { return run.rows[r * w + c]; };

  // Column indices, looked up once.
  const std::size_t c_err = col("position_error"), c_w = col("manipulability"), c_res = col("solver_residual"),
                    c_it = col("solver_iterations");
  std::vector<std::size_t> c_th, c_thd, c_vlo, c_vhi, c_lo, c_hi;
  for (int j = 1; j <= n; ++j) {
    const std::string J = std::to_string(j);
    c_th.push_back(col("theta_" + J));
    c_thd.push_back(col("theta_dot_" + J));
    c_vlo.push_back(col("vel_lo_" + J));
    c_vhi.push_back(col("vel_hi_" + J));
    c_lo.push_back(col("lo_" + J));
    c_hi.push_back(col("hi_" + J));
  }
  double max_err = 0.0, w_min = 1e300, w_max = -1e300, w_sum = 0.0, angle_viol = 0.0, vel_viol = 0.0;
  double safety_entry = 0.0, max_res = 0.0, it_sum = 0.0, it_max = 0.0;
  long active_steps = 0;
  for (std::size_t r = 0; r < rows; ++r) {
    max_err = std::max(max_err, val(r, c_err));
    const double wv = val(r, c_w);
    w_min = std::min(w_min, wv);
    w_max = std::max(w_max, wv);
    w_sum += wv;
    max_res = std::max(max_res, val(r, c_res));
    it_sum += val(r, c_it);
    it_max = std::max(it_max, val(r, c_it));
    bool active = false;
    for (int j = 0; j < n; ++j) {
      const auto k = static_cast<std::size_t>(j);
      const double th = val(r, c_th[k]), thd = val(r, c_thd[k]);
      const double lo = robot.lower_limits()(j), hi = robot.upper_limits()(j);
      angle_viol = std::max({angle_viol, th - hi, lo - th});
      safety_entry = std::max({safety_entry, th - (hi - s.safety_margin(j)), (lo + s.safety_margin(j)) - th});
      vel_viol = std::max({vel_viol, thd - val(r, c_vhi[k]), val(r, c_vlo[k]) - thd});
      const double blo = val(r, c_lo[k]), bhi = val(r, c_hi[k]);
      active = active || std::abs(thd - blo) <= 1e-9 * (1.0 + std::abs(blo)) ||
               std::abs(thd - bhi) <= 1e-9 * (1.0 + std::abs(bhi));
    }
    active_steps += active ? 1 : 0;
  }
  const auto joint_velocity_norm = [&](std::size_t r) {
    double sq = 0.0;
    for (std::size_t k = 0; k < c_thd.size(); ++k) sq += std::pow(val(r, c_thd[k]), 2);
    return std::sqrt(sq);
  };
  std::vector<double> final_theta, lengths, lower, upper, margin;
  std::vector<std::string> names;
  for (int j = 0; j < n; ++j) {
    final_theta.push_back(val(rows - 1, c_th[static_cast<std::size_t>(j)]));
    names.push_back(robot.joint(j).name);
    lower.push_back(robot.lower_limits()(j));
    upper.push_back(robot.upper_limits()(j));
    margin.push_back(s.safety_margin(j));
    lengths.push_back(robot.joint(j).length);
  }
  nlohmann::json j = {
      {"name", s.name},
      {"source", s.source},
      {"steps", s.steps()},
      {"tau", s.tau},
      {"duration", s.duration},
      {"integrator", s.integrator == Integrator::kEuler ? "euler" : "heun"},
      {"path", s.path->description()},
      {"max_position_error", max_err},
      {"final_position_error", val(rows - 1, c_err)},
      {"initial_joint_velocity_norm", joint_velocity_norm(0)},
      {"final_joint_velocity_norm", joint_velocity_norm(rows - 1)},
      {"manipulability",
       {{"initial", val(0, c_w)},
        {"final", val(rows - 1, c_w)},
        {"min", w_min},
        {"mean", w_sum / static_cast<double>(rows)},
        {"max", w_max}}},
      {"max_joint_angle_violation", std::max(0.0, angle_viol)},
      {"max_safety_region_entry", std::max(0.0, safety_entry)},
      {"max_joint_velocity_violation", std::max(0.0, vel_viol)},
      {"steps_with_active_bounds", active_steps},
      {"final_theta", final_theta},
      {"solver",
       {{"engine", run.engine},
        {"mean_iterations", it_sum / static_cast<double>(rows)},
        {"max_iterations", it_max},
        {"max_residual", max_res},
        {"failures", run.failures},
        {"first_failure", run.first_failure}}},
      {"wall_time_s", run.wall_time_s},
      {"robot",
       {{"name", robot.name()},
        {"kind", to_string(robot.kind())},
        {"joint_names", names},
        {"lower_limits", lower},
        {"upper_limits", upper},
        {"link_lengths", lengths},
        {"safety_margin", margin}}},
  };
  return j.dump(2);
}

void write_run(const Scenario& s, const RunResult& run, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const std::filesystem::path csv = dir / "trajectory.csv";
  std::FILE* f = std::fopen(csv.string().c_str(), "w");
  if (f == nullptr) throw std::runtime_error("cannot write " + csv.string());
  for (std::size_t c = 0; c < run.columns.size(); ++c) std::fprintf(f, "%s%s", c ? "," : "", run.columns[c].c_str());
  std::fputc('\n', f);
  const std::size_t w = run.columns.size();
  for (std::size_t r = 0; r < run.size(); ++r) {
    for (std::size_t c = 0; c < w; ++c) std::fprintf(f, "%s%.12g", c ? "," : "", run.rows[r * w + c]);
    std::fputc('\n', f);
  }
  if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + csv.string());
  std::ofstream js(dir / "summary.json");
  js << summary_json(s, run) << "\n";
  if (!js) throw std::runtime_error("cannot write " + (dir / "summary.json").string());
}

}  // namespace redres

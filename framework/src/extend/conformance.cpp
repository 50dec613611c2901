#include "redres/extend/conformance.hpp"

#include <cmath>
#include <set>
#include <sstream>

#include "extend/kind_checks.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/control/path.hpp"
#include "redres/control/plugin.hpp"
#include "redres/control/scheme.hpp"
#include "redres/control/task.hpp"
#include "redres/extend/plugin_kinds.hpp"
#include "redres/model/robot.hpp"
#include "redres/model/velocity_limit.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"
#include "redres/qp/lvi.hpp"

namespace redres {

namespace {

// A velocity law that needs no registry: the checks must not depend on any one plugin being registered.
class FixedLaw final : public VelocityLimitLaw {
 public:
  FixedLaw() : VelocityLimitLaw("conformance_fixed") {}
  VelocityBounds bounds(double /*theta*/) const override { return {-1.5, 1.5}; }
  std::string describe() const override { return "fixed(+-1.5)"; }

 private:
  void write_config(toml::table& /*out*/) const override {}
};

JointSpec joint(const std::string& name, double lower, double upper) {
  JointSpec j;
  j.name = name;
  j.lower = lower;
  j.upper = upper;
  j.velocity_limit = std::make_shared<FixedLaw>();
  ShapeSpec capsule;  // along the link
  capsule.radius = 0.02;
  j.collision.push_back(capsule);
  return j;
}

std::vector<RobotModel> test_robots() {
  std::vector<RobotModel> robots;
  RobotSpec planar;
  planar.name = "conformance_planar6";
  planar.kind = ChainKind::kPlanar;
  for (int j = 0; j < 6; ++j) {
    planar.joints.push_back(joint("j" + std::to_string(j + 1), -2.5, 2.5));
    planar.joints.back().length = 0.3 - 0.03 * j;
  }
  planar.home = Eigen::VectorXd::Constant(6, 0.3);
  robots.emplace_back(planar);
  RobotSpec pose = planar;
  pose.name = "conformance_planar4_pose";
  pose.joints.resize(4);
  pose.task = TaskRows::kPose;
  pose.home = Eigen::VectorXd::Constant(4, 0.4);
  robots.emplace_back(pose);
  RobotSpec spatial;
  spatial.name = "conformance_spatial7_pose";
  spatial.kind = ChainKind::kSpatial;
  spatial.task = TaskRows::kPose;
  const double a[7] = {0, 0, 0, 0.08, -0.08, 0, 0.09};
  const double d[7] = {0.33, 0, 0.32, 0, 0.38, 0, 0.1};
  const double alpha[7] = {-1.5708, 1.5708, 1.5708, -1.5708, 1.5708, 1.5708, 0};
  for (int j = 0; j < 7; ++j) {
    spatial.joints.push_back(joint("s" + std::to_string(j + 1), -2.8, 2.8));
    spatial.joints.back().a = a[j];
    spatial.joints.back().d = d[j];
    spatial.joints.back().alpha = alpha[j];
    spatial.joints.back().acceleration_limit = std::make_shared<FixedLaw>();  // +-1.5 rad/s^2
    spatial.joints.back().jerk_limit = std::make_shared<FixedLaw>();          // +-1.5 rad/s^3
  }
  spatial.home = (Eigen::VectorXd(7) << 0.1, -0.5, 0.2, -1.8, 0.1, 1.5, 0.7).finished();
  robots.emplace_back(spatial);
  return robots;
}

// A reproducible uniform sequence (the checks must give the same verdict every time).
class Lcg {
 public:
  double next(double lo, double hi) {
    state_ = state_ * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * static_cast<double>(state_ >> 11) / 9007199254740992.0;
  }

 private:
  unsigned long long state_ = 20261123ULL;
};

std::string toml_text(const toml::table& t) {
  std::ostringstream s;
  s << t;
  return s.str();
}

struct Recorder {
  std::vector<ConformanceResult>& out;
  std::string kind, type;
  void operator()(const std::string& check, bool ok, const std::string& detail) const {
    out.push_back({kind, type, check, ok, detail});
  }
};

// Keys written by config() that the schema (and the common keys) do not document.
std::string undocumented(const toml::table& config, const std::vector<KeyInfo>& keys,
                         const std::vector<KeyInfo>& common) {
  std::set<std::string> known = {"type"};
  for (const auto& k : keys) known.insert(k.name);
  for (const auto& k : common) known.insert(k.name);
  std::string bad;
  for (const auto& [k, v] : config) {
    if (known.count(std::string(k.str())) == 0) bad += (bad.empty() ? "" : ", ") + std::string(k.str());
  }
  return bad;
}

template <class P, class Entry, class Make>
void check_scheme_plugin(const Entry& e, const std::vector<RobotModel>& robots, const std::vector<KeyInfo>& common,
                         Make make_from_table, const Recorder& rec) {
  int built = 0;
  for (const RobotModel& robot : robots) {
    const std::string on = " on " + robot.name();
    std::unique_ptr<P> p;
    try {
      try {
        p = e.make(e.defaults, robot);
      } catch (const std::exception&) {
        if (!e.example.has_value()) throw;
        p = e.make(e.example, robot);  // a plugin with required keys: its registered example
      }
    } catch (const std::exception& ex) {
      // A plugin may not apply to every robot (e.g. it needs a spatial arm); it must build on at least one.
      rec("defaults", true, "not applicable" + on + ": " + ex.what());
      continue;
    }
    ++built;
    // Round trip.
    const toml::table config = p->config();
    try {
      const auto file = parse_toml_string(toml_text(config), "<" + e.type + " config>");
      const std::unique_ptr<P> again = make_from_table(TableReader::root(file), robot);
      const bool same = toml_text(again->config()) == toml_text(config);
      rec("round trip", same, same ? "config() read back" + on : "config() differs after reading it back" + on);
    } catch (const std::exception& ex) {
      rec("round trip", false, "config() cannot be read back" + on + ": " + ex.what());
    }
    const std::string bad = undocumented(config, e.keys, common);
    rec("documented keys", bad.empty(), bad.empty() ? "every written key is in the schema" : "undocumented: " + bad);
    // Finite contributions, and the gradient of objectives with a potential.
    std::vector<std::unique_ptr<Objective>> objectives;
    std::vector<std::unique_ptr<Constraint>> constraints;
    std::vector<std::unique_ptr<Task>> tasks;
    const P* raw = p.get();
    if constexpr (std::is_same_v<P, Objective>) {
      objectives.push_back(std::move(p));
    } else if constexpr (std::is_same_v<P, Constraint>) {
      constraints.push_back(std::move(p));
    } else {
      tasks.push_back(std::move(p));
    }
    const Scheme scheme(robot, std::move(objectives), std::move(constraints), std::move(tasks));
    QpProblem qp;
    SchemeData scheme_data = scheme.make_data();
    scheme.setup(qp, scheme_data);
    KinematicsData kin(robot);
    Eigen::VectorXd r_d = Eigen::VectorXd::Zero(robot.reference_dim()), r_d_dot = r_d;
    Context ctx{0.0, 10.0, 0.01, &robot, &kin, &r_d, &r_d_dot};
    Lcg lcg;
    std::string finite_error, gradient_error;
    double worst = 0.0;
    for (int trial = 0; trial < 8; ++trial) {
      Eigen::VectorXd theta(robot.dof());
      for (int j = 0; j < robot.dof(); ++j) {
        const double lo = robot.lower_limits()(j), hi = robot.upper_limits()(j);
        theta(j) = lcg.next(lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo));
      }
      ctx.t = lcg.next(0.0, ctx.T);
      compute_kinematics(robot, theta, kin, KinematicsLevel::kAll);
      for (int r = 0; r < robot.reference_dim(); ++r) {
        r_d(r) = kin.f(r) + lcg.next(-0.01, 0.01);
        r_d_dot(r) = lcg.next(-0.05, 0.05);
      }
      try {
        scheme.build(ctx, qp, scheme_data);
        if (qp.lo.array().isNaN().any() || qp.hi.array().isNaN().any()) finite_error = "a bound is NaN";
      } catch (const std::exception& ex) {
        finite_error = ex.what();
        break;
      }
      if constexpr (std::is_same_v<P, Objective>) {
        const auto& obj = static_cast<const Objective&>(*raw);
        if (!obj.potential(ctx)) continue;
        // zeta per unit weight against central differences of the potential.
        const Eigen::VectorXd zeta = qp.zeta / (obj.weight() > 0.0 ? obj.weight() : 1.0);
        const double h = 1e-6;
        for (int j = 0; j < robot.dof(); ++j) {
          Eigen::VectorXd th = theta;
          th(j) = theta(j) + h;
          compute_kinematics(robot, th, kin, KinematicsLevel::kAll);
          const double up = *obj.potential(ctx);
          th(j) = theta(j) - h;
          compute_kinematics(robot, th, kin, KinematicsLevel::kAll);
          const double down = *obj.potential(ctx);
          const double fd = (up - down) / (2.0 * h);
          const double err = std::abs(fd - zeta(j)) / (1.0 + std::abs(zeta(j)));
          worst = std::max(worst, err);
          if (err > 1e-5 && gradient_error.empty()) {
            std::ostringstream s;
            s << "joint " << j + 1 << on << ": zeta = " << zeta(j) << ", central difference = " << fd;
            gradient_error = s.str();
          }
        }
      }
    }
    rec("finite", finite_error.empty(), finite_error.empty() ? "8 random configurations" + on : finite_error + on);
    if constexpr (std::is_same_v<P, Objective>) {
      if (static_cast<const Objective&>(*raw).potential(ctx)) {
        std::ostringstream s;
        s << "largest relative error " << worst << on;
        rec("gradient", gradient_error.empty(), gradient_error.empty() ? s.str() : gradient_error);
      }
    }
  }
  if (built == 0) {
    rec("defaults", false,
        "builds on none of the test robots from its default Config; give every key a default (required keys cannot "
        "be checked)");
  }
}

// Laws and engines: the default Config builds, or is rejected because of a required key.
template <class Entry, class Build>
void check_defaults(const Entry& e, Build build, const Recorder& rec) {
  bool has_required = false;
  for (const auto& k : e.keys) has_required = has_required || k.presence != Presence::kOptional;
  try {
    build();
    rec("defaults", true, "the default Config builds");
  } catch (const std::exception& ex) {
    const std::string what = ex.what();
    const bool expected =
        has_required && (what.find("required") != std::string::npos || what.find("expected") != std::string::npos);
    rec("defaults", expected,
        expected ? "has required keys; the default Config is rejected: " + what : "the default Config fails: " + what);
  }
}

void check_path(const PathRegistry::Entry& e, const Recorder& rec) {
  int built = 0;
  for (int dim : {2, 3}) {
    PathContext ctx;
    ctx.dim = dim;
    ctx.start = Eigen::Vector3d(0.4, -0.2, dim == 3 ? 0.3 : 0.0);
    ctx.duration = 8.0;
    std::unique_ptr<Path> path;
    try {
      path = make_path(e.type, e.defaults, PathPlacement{}, ctx);
    } catch (const std::exception& ex) {
      continue;  // e.g. a spatial-only shape in the plane, or required keys
    }
    ++built;
    const std::string on = " (" + std::to_string(dim) + "-D)";
    Eigen::VectorXd r(dim), v(dim), up(dim), down(dim), dummy(dim);
    path->evaluate(0.0, r, v);
    const Eigen::VectorXd origin = Eigen::VectorXd(ctx.start).head(dim);
    const double start_error = (r - origin).norm();
    rec("starts at origin", start_error < 1e-12, "|r_d(0) - origin| = " + std::to_string(start_error) + on);
    double worst = 0.0;
    const double h = 1e-6;
    for (int k = 1; k < 200; ++k) {
      const double t = ctx.duration * k / 200.0;
      path->evaluate(t, r, v);
      path->evaluate(t + h, up, dummy);
      path->evaluate(t - h, down, dummy);
      worst = std::max(worst, ((up - down) / (2.0 * h) - v).norm() / (1.0 + v.norm()));
    }
    rec("r_d_dot", worst < 1e-5, "largest relative error against central differences " + std::to_string(worst) + on);
  }
  if (built == 0) {
    bool has_required = false;
    for (const auto& k : e.keys) has_required = has_required || k.presence != Presence::kOptional;
    rec("defaults", has_required,
        has_required ? "has required keys; checked by the test suite with its own configs"
                     : "builds in neither 2-D nor 3-D from its default Config");
  }
}

void check_engine(const EngineRegistry::Entry& e, const Recorder& rec) {
  std::unique_ptr<LviEngine> engine;
  try {
    engine = e.make(e.defaults, SolverSettings{});
  } catch (const std::exception& ex) {
    rec("defaults", false, std::string("the default Config fails: ") + ex.what());
    return;
  }
  rec("defaults", true, "the default Config builds");
  // min |x|^2/2 - x1 s.t. x1 + x2 + x3 = 0.3, -0.2 <= x <= 0.4: the solution is x = (0.4, -0.05, -0.05).
  QpProblem qp;
  qp.resize(3, 1, 0);
  qp.clear();
  qp.W.diagonal().setOnes();
  qp.zeta << -1.0, 0.0, 0.0;
  qp.J << 1.0, 1.0, 1.0;
  qp.d << 0.3;
  qp.lo.setConstant(-0.2);
  qp.hi.setConstant(0.4);
  SolverResult result;
  engine->setup(3, 1, 0, result);
  engine->solve(qp, result);
  const Eigen::Vector3d want(0.4, -0.05, -0.05);
  const double err = (result.x - want).norm();
  const bool ok = result.info.status == SolverStatus::kSolved && err < 1e-4;
  rec("solves", ok, std::string("status ") + to_string(result.info.status) + ", |x - x*| = " + std::to_string(err));
}

bool wanted(const std::string& entry_origin, const std::string& origin) {
  return origin.empty() || entry_origin == origin;
}

const std::vector<RobotModel>& robots() {
  static const std::vector<RobotModel> r = test_robots();
  return r;
}

}  // namespace

namespace kind_checks {

void objectives(const std::string& origin, std::vector<ConformanceResult>& out) {
  for (const auto* e : objective_registry().entries()) {
    if (!wanted(e->origin, origin)) continue;
    check_scheme_plugin<Objective>(*e, robots(), objective_common_keys(), make_objective,
                                   Recorder{out, "objective", e->type});
  }
}

void constraints(const std::string& origin, std::vector<ConformanceResult>& out) {
  for (const auto* e : constraint_registry().entries()) {
    if (!wanted(e->origin, origin)) continue;
    check_scheme_plugin<Constraint>(*e, robots(), constraint_common_keys(), make_constraint,
                                    Recorder{out, "constraint", e->type});
  }
}

void tasks(const std::string& origin, std::vector<ConformanceResult>& out) {
  for (const auto* e : task_registry().entries()) {
    if (!wanted(e->origin, origin)) continue;
    check_scheme_plugin<Task>(*e, robots(), task_common_keys(), make_task, Recorder{out, "task", e->type});
  }
}

void velocity_limits(const std::string& origin, std::vector<ConformanceResult>& out) {
  for (const auto* e : velocity_limit_registry().entries()) {
    if (!wanted(e->origin, origin)) continue;
    const Recorder rec{out, "velocity-limit law", e->type};
    check_defaults(
        *e, [e] { (void)e->make(e->defaults); }, rec);
    try {
      const auto law = e->make(e->defaults);
      const auto file = parse_toml_string(toml_text(law->config()), "<" + e->type + " config>");
      const auto again = make_velocity_limit(TableReader::root(file));
      const bool same = toml_text(again->config()) == toml_text(law->config());
      rec("round trip", same, same ? "config() read back" : "config() differs after reading it back");
    } catch (const std::exception&) {
      // Only laws whose defaults build can be round-tripped here (reported under "defaults").
    }
  }
}

void paths(const std::string& origin, std::vector<ConformanceResult>& out) {
  for (const auto* e : path_registry().entries()) {
    if (wanted(e->origin, origin)) check_path(*e, Recorder{out, "path", e->type});
  }
}

void engines(const std::string& origin, std::vector<ConformanceResult>& out) {
  for (const auto* e : engine_registry().entries()) {
    if (wanted(e->origin, origin)) check_engine(*e, Recorder{out, "engine", e->type});
  }
}

}  // namespace kind_checks

std::vector<ConformanceResult> check_registries() { return check_registries(""); }

std::vector<ConformanceResult> check_registries(const std::string& origin) {
  std::vector<ConformanceResult> out;
  for (const PluginKind& kind : plugin_kinds()) kind.check(origin, out);
  return out;
}

}  // namespace redres

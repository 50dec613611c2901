#include "redres/run/ik.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <utility>

#include "redres/common/error.hpp"
#include "redres/control/collision_rows.hpp"
#include "redres/control/controller.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/model/collision.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/model/velocity_limit.hpp"

namespace redres {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// The IK's collision rows reach this far past d_s at least, so that no step jumps a pair from beyond them into
// contact: a step moves a joint by at most max_step (0.25 rad by default), a point 1 m out by 0.25 m.
constexpr double kIkInfluenceReach = 0.25;
// Each iteration may close a pair's distance to its safety distance by at most this fraction.
constexpr double kIkApproach = 0.5;
// A step that makes the error grow is halved at most this often (then it is taken: the stall test ends a seed that
// makes no progress).
constexpr int kMeritHalvings = 8;
// A step that makes two bodies overlap is halved at most this often; then the seed ends where it was.
constexpr int kCollisionHalvings = 12;

// |dx_j| <= step: the IK's trust region, written as the velocity-limit laws of its copy of the robot (with tau = 1
// the QP's x is the change of theta per iteration), which `joint_velocity_limits` turns into bounds.
class StepBound final : public VelocityLimitLaw {
 public:
  explicit StepBound(double step) : VelocityLimitLaw("ik_step"), step_(step) {}
  [[nodiscard]] VelocityBounds bounds(double /*theta*/) const override { return {-step_, step_}; }
  [[nodiscard]] std::string describe() const override {
    std::ostringstream s;
    s << "ik_step(" << step_ << " per iteration)";
    return s.str();
  }

 private:
  void write_config(toml::table& out) const override { out.insert_or_assign("step", step_); }
  double step_;
};

std::string vec(const Eigen::Ref<const Eigen::VectorXd>& v, int digits = 6) {
  std::ostringstream s;
  s.precision(digits);
  s << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s << (i > 0 ? ", " : "") << v(i);
  s << "]";
  return s.str();
}

double wrap_angle(double a) { return std::remainder(a, 2.0 * M_PI); }

// Builds a constraint from a configuration table (`type` and its keys) for `robot`. File keys in the table are
// resolved already (config() writes them so), hence the empty file path.
std::unique_ptr<Constraint> constraint_from(toml::table table, const RobotModel& robot) {
  auto doc = std::make_shared<TomlFile>();
  doc->root = std::move(table);
  return make_constraint(TableReader::root(doc, "inverse kinematics"), robot);
}

double table_number(const toml::table& t, std::string_view key, double fallback) {
  const toml::node* n = t.get(key);
  if (n == nullptr) return fallback;
  if (const auto v = n->value<double>()) return *v;
  return fallback;
}

// The IK's copy of the robot: the same chain, the target's task rows, the step bound as every joint's velocity law,
// no acceleration or jerk limits (an iteration is not a motion).
RobotModel ik_model(const RobotModel& robot, const IkTarget& target, double step) {
  RobotSpec spec = robot.spec();
  spec.task = target.rotation ? TaskRows::kPose : TaskRows::kPosition;
  spec.task_axes = target.rows;
  const auto law = std::make_shared<StepBound>(step);
  for (JointSpec& j : spec.joints) {
    j.velocity_limit = law;
    j.velocity_limit_source.clear();
    j.acceleration_limit = nullptr;
    j.acceleration_limit_source.clear();
    j.jerk_limit = nullptr;
    j.jerk_limit_source.clear();
  }
  return RobotModel(std::move(spec));
}

// One collision constraint of the IK and what it needs to be read back.
struct Clone {
  std::size_t index = 0;  // in the scheme's constraints
  double safety = 0.0;    // its d_s (m)
  std::string name;       // as the scenario named it
};

class IkSolver {
 public:
  IkSolver(const RobotModel& robot, const IkTarget& target, const std::vector<const Constraint*>& collision,
           const IkOptions& options)
      : robot_(robot), target_(target), options_(options), model_(ik_model(robot, target, options.max_step)) {
    const int n = robot.dof();
    margin_ = options.margin.size() == 1 ? Eigen::VectorXd::Constant(n, options.margin(0)) : options.margin;
    lower_ = robot.lower_limits() + margin_;
    upper_ = robot.upper_limits() - margin_;
    std::vector<std::unique_ptr<Objective>> objectives;
    objectives.push_back(objective_registry().create_default("min_velocity_norm", model_));
    std::vector<std::unique_ptr<Constraint>> constraints;
    {
      toml::table t{{"type", "task_tracking"}, {"gain", 1.0}};
      constraints.push_back(constraint_from(std::move(t), model_));
    }
    {
      toml::array m;
      for (int j = 0; j < n; ++j) m.push_back(margin_(j));
      toml::table t{{"type", "joint_angle_margin"}, {"kappa", 1.0}, {"margin", std::move(m)}};
      constraints.push_back(constraint_from(std::move(t), model_));
    }
    constraints.push_back(constraint_from(toml::table{{"type", "joint_velocity_limits"}}, model_));
    std::vector<toml::table> tables;
    bool self = false;
    for (const Constraint* c : collision) {
      if (c == nullptr || !c->active()) continue;
      self = self || c->type() == "self_collision";
      tables.push_back(c->config());
    }
    if (options.self_collision && !self && !robot.link_shapes().empty()) {
      // With every key of its defaults written out (config()), so that its damper is set like the others'.
      tables.push_back(constraint_registry().create_default("self_collision", robot)->config());
    }
    for (toml::table& t : tables) {
      Clone clone;
      clone.index = constraints.size();
      clone.safety = table_number(t, "safety_distance", 0.0);
      // The damper: every pair within reach gets a row, and a step closes at most half of a pair's distance to d_s.
      if (t.contains("influence_distance") && t.contains("safety_distance") && t.contains("xi")) {
        const double di = std::max(table_number(t, "influence_distance", 0.0), clone.safety + kIkInfluenceReach);
        t.insert_or_assign("influence_distance", di);
        t.insert_or_assign("xi", kIkApproach * (di - clone.safety));
      }
      std::string name = t.contains("name") ? std::string(t["name"].value_or(std::string())) : std::string();
      if (name.empty()) name = std::string(t["type"].value_or(std::string("collision")));
      for (const auto& other : constraints) {
        if (other->name() == name) name += " (ik)";
      }
      t.insert_or_assign("name", name);
      t.insert_or_assign("active", true);
      clone.name = name;
      constraints.push_back(constraint_from(std::move(t), model_));
      clones_.push_back(clone);
    }
    scheme_ = std::make_unique<Scheme>(model_, std::move(objectives), std::move(constraints));
    SolverSettings settings;
    settings.tolerance = 1e-12;
    engine_ = make_engine("newton", settings);
    ctrl_ = std::make_unique<Controller>(model_, *scheme_, *engine_, nullptr, 1.0, 1.0);
    ctrl_->set_failure_policy(FailurePolicy::kRelax, options.relax_weight);
    out_ = ctrl_->make_output();
    kin_ = std::make_unique<KinematicsData>(model_);
    r_d_ = Eigen::VectorXd::Zero(model_.reference_dim());
    r_d_dot_ = Eigen::VectorXd::Zero(model_.reference_dim());
    if (target.rotation && model_.kind() == ChainKind::kSpatial) {
      const Eigen::AngleAxisd aa(*target.rotation);
      rotvec_ = aa.angle() * aa.axis();
    }
    if (target.rotation && model_.kind() == ChainKind::kPlanar) {
      phi_ = std::atan2((*target.rotation)(1, 0), (*target.rotation)(0, 0));
    }
  }

  // The errors at theta (into kin_): position and orientation over the target's rows.
  void errors(const Eigen::VectorXd& theta, double& pos, double& rot) {
    compute_kinematics(model_, theta, *kin_, KinematicsLevel::kPosition);
    errors_here(pos, rot);
  }

  void errors_here(double& pos, double& rot) const {
    const int p = model_.position_rows();
    double sp = 0.0, sr = 0.0;
    for (int r = 0; r < p; ++r) {
      if (model_.tracks(r)) sp += std::pow(target_.position(r) - kin_->f(r), 2);
    }
    if (model_.has_orientation_rows()) {
      if (model_.kind() == ChainKind::kPlanar) {
        if (model_.tracks(2)) sr = std::pow(wrap_angle(phi_ - kin_->f(2)), 2);
      } else {
        const Eigen::Vector3d v = orientation_error_vector(*target_.rotation, kin_->ee_pose.linear());
        for (int r = 0; r < 3; ++r) {
          if (model_.tracks(3 + r)) sr += v(r) * v(r);
        }
      }
    }
    pos = std::sqrt(sp);
    rot = std::sqrt(sr);
  }

  // One QP at theta: the step towards the target (out_.theta_dot), the collision distances at theta.
  void step(const Eigen::VectorXd& theta) {
    compute_kinematics(model_, theta, *kin_, KinematicsLevel::kPosition);
    const int p = model_.position_rows();
    r_d_.head(p) = target_.position.head(p);
    if (model_.has_orientation_rows()) {
      if (model_.kind() == ChainKind::kPlanar) {
        r_d_(2) = kin_->f(2) + wrap_angle(phi_ - kin_->f(2));  // the nearest turn of phi
      } else {
        r_d_.tail<3>() = rotvec_;
      }
    }
    ctrl_->step(theta, 0.0, r_d_, r_d_dot_, out_);
    ++iterations_;
  }

  [[nodiscard]] bool collided() const {
    const SchemeData& data = ctrl_->plugin_data();
    for (const Clone& c : clones_) {
      if (scheme_->constraints()[c.index]->violated(data.constraints[c.index].get())) return true;
    }
    return false;
  }

  [[nodiscard]] bool usable() const {
    return out_.info.status == SolverStatus::kSolved || out_.info.status == SolverStatus::kRelaxed;
  }

  void clamp(Eigen::VectorXd& theta) const {
    theta = theta.cwiseMax(robot_.lower_limits()).cwiseMin(robot_.upper_limits());
  }

  // Iterates from one seed; returns the best configuration clear of collisions (or the best at all when none was)
  // and its merit.
  struct Attempt {
    Eigen::VectorXd theta;
    double merit = kInfinity;
    bool clear = false;
    bool converged = false;
    std::string solver_failure;
  };
  Attempt run(Eigen::VectorXd theta) {
    clamp(theta);
    ctrl_->reset();
    Attempt best;
    Eigen::VectorXd prev = theta, x(theta.size());
    bool prev_clear = false, have_prev = false;
    int halvings = 0, since_best = 0;
    for (int it = 0; it < options_.max_iterations; ++it) {
      step(theta);
      const bool clear = !collided();
      if (!clear && have_prev && prev_clear) {
        if (halvings < kCollisionHalvings) {  // the step went into contact: take half of it
          theta = prev + 0.5 * (theta - prev);
          ++halvings;
          continue;
        }
        theta = prev;  // no part of the step stays clear: the seed ends where it was
        step(theta);
        break;
      }
      halvings = 0;
      double pos = 0.0, rot = 0.0;
      errors_here(pos, rot);
      const double merit = pos * pos + rot * rot;
      if ((clear && !best.clear) || ((clear || !best.clear) && merit < best.merit * (1.0 - 1e-3))) {
        since_best = 0;
      } else {
        ++since_best;
      }
      if ((clear && !best.clear) || ((clear || !best.clear) && merit < best.merit)) {
        best.theta = theta;
        best.merit = merit;
        best.clear = clear;
      }
      if (clear && pos <= options_.position_tolerance && rot <= options_.orientation_tolerance) {
        best.converged = true;
        best.theta = theta;
        best.merit = merit;
        best.clear = true;
        return best;
      }
      if (!usable()) {
        best.solver_failure =
            out_.info.diagnosis.empty() ? std::string(to_string(out_.info.status)) : out_.info.diagnosis;
        break;
      }
      if (since_best >= options_.stall_iterations) break;
      x = out_.theta_dot;
      // A step that makes the error grow is halved (the linearisation overshot).
      Eigen::VectorXd candidate = theta + x;
      clamp(candidate);
      for (int h = 0; h < kMeritHalvings; ++h) {
        double cp = 0.0, cr = 0.0;
        errors(candidate, cp, cr);
        if (cp * cp + cr * cr <= merit) break;
        x *= 0.5;
        candidate = theta + x;
        clamp(candidate);
      }
      prev = theta;
      prev_clear = clear;
      have_prev = true;
      theta = candidate;
    }
    return best;
  }

  // "; the target is ... beyond the arm's reach ..." when it is provably out of reach, else "" (uses kin_, at any
  // configuration). A chain of revolute joints reaches no farther from its first joint than the sum of the distances
  // between consecutive joint axes' points and the end effector (each is fixed by the joints before it).
  [[nodiscard]] std::string beyond_reach() const {
    bool all_position = true;
    for (int row = 0; row < model_.position_rows(); ++row) all_position = all_position && model_.tracks(row);
    if (!model_.all_revolute() || !all_position) return {};
    double reach = 0.0;
    for (int j = 0; j + 1 < model_.dof(); ++j) reach += (kin_->origins.col(j + 1) - kin_->origins.col(j)).norm();
    reach += (kin_->ee_pose.translation() - kin_->origins.col(model_.dof() - 1)).norm();
    const double far = (target_.position - kin_->origins.col(0)).head(model_.position_rows()).norm();
    if (!(far > reach)) return {};
    std::ostringstream m;
    m.precision(4);
    m << "; the target is " << far << " m from the first joint, beyond the arm's reach of at most " << reach << " m";
    return m.str();
  }

  // The result at theta, with the distances, and on failure the diagnosis.
  IkResult finish(const Attempt& a, bool converged) {
    IkResult r;
    r.theta = a.theta;
    step(a.theta);
    --iterations_;  // the step that measures the answer is not an iteration
    errors_here(r.position_error, r.orientation_error);
    r.pose = kin_->ee_pose;
    r.converged = converged;
    // The nearest pair of every collision constraint: its distance, and the row that stands for it.
    const QpProblem& qp = ctrl_->qp();
    const SchemeData& data = ctrl_->plugin_data();
    const int base = static_cast<int>(scheme_->objectives().size());
    std::string blocking;
    double blocking_distance = kInfinity;
    for (const Clone& c : clones_) {
      const Constraint& k = *scheme_->constraints()[c.index];
      const PluginData* d = data.constraints[c.index].get();
      const auto* pairs = dynamic_cast<const PairData*>(d);
      if (pairs == nullptr) continue;
      const double dist = pairs->distances[pairs->distances.worst()];
      // The row of the nearest pair: the real row (A_row != 0) with the smallest right-hand side.
      int first = -1, best_row = -1;
      double best_b = kInfinity;
      for (int row = 0; row < qp.m_in(); ++row) {
        if (qp.in_source[static_cast<std::size_t>(row)] != base + static_cast<int>(c.index)) continue;
        if (first < 0) first = row;
        if (qp.A.row(row).squaredNorm() == 0.0) continue;
        if (qp.b(row) < best_b) {
          best_b = qp.b(row);
          best_row = row;
        }
      }
      std::string text = best_row >= 0 ? k.describe_inequality_row(d, best_row - first) : std::string();
      if (!text.empty()) text = "constraint '" + c.name + "': " + text;
      if (dist < r.min_distance) {
        r.min_distance = dist;
        r.nearest_pair = text;
      }
      if (dist <= c.safety + 1e-3 && dist < blocking_distance) {
        blocking_distance = dist;
        blocking = text.empty() ? "constraint '" + c.name + "'" : text;
      }
    }
    if (converged) return r;
    // Why not: what holds the step back at theta. At a configuration where the error stops falling, the error's
    // descent direction g = J' e lies in the cone of the constraints that are active there: joints at a limit that
    // g pushes further out, or a collision pair at its safety distance.
    const Eigen::VectorXd g = qp.J.transpose() * qp.d;
    const double threshold = 1e-3 * qp.d.norm();
    for (int j = 0; j < robot_.dof(); ++j) {
      const double t = a.theta(j);
      if ((t >= upper_(j) - 1e-6 && g(j) > threshold) || (t <= lower_(j) + 1e-6 && g(j) < -threshold)) {
        r.limit_joints.push_back(j);
      }
    }
    std::ostringstream s;
    s.precision(4);
    s << "the closest configuration found, theta = " << vec(a.theta) << ", leaves the end effector " << r.position_error
      << " m";
    if (target_.rotation) s << " and " << r.orientation_error << " rad";
    s << " from the target (reached xyz " << vec(r.pose.translation());
    if (target_.rotation && model_.kind() == ChainKind::kSpatial) {
      const std::array<double, 3> rpy = rpy_of(r.pose.linear());
      s << ", rpy " << vec(Eigen::Vector3d(rpy[0], rpy[1], rpy[2]));
    } else if (target_.rotation) {
      s << ", phi " << kin_->f(2);
    }
    s << "; " << seeds_ << " seed" << (seeds_ == 1 ? "" : "s") << ", " << iterations_ << " iterations)";
    std::string limits;
    for (int j : r.limit_joints) {
      const bool up = a.theta(j) >= upper_(j) - 1e-6;
      std::ostringstream l;
      l.precision(4);
      l << (limits.empty() ? "" : ", ") << "joint " << j + 1 << " ('" << robot_.joint(j).name << "') at its "
        << (up ? "upper" : "lower") << " limit " << (up ? robot_.upper_limits()(j) : robot_.lower_limits()(j));
      if (margin_(j) > 0.0) l << " less the margin " << margin_(j);
      limits += l.str();
    }
    const std::string beyond = beyond_reach();
    if (!a.solver_failure.empty()) {
      r.failure = IkFailure::kSolver;
      r.diagnosis = "a QP of the iteration was not solved (" + a.solver_failure + "); " + s.str() + beyond;
    } else if (!beyond.empty()) {
      r.failure = IkFailure::kUnreachable;
      r.diagnosis = "unreachable: " + s.str() + beyond;
    } else if (!blocking.empty()) {
      r.failure = IkFailure::kCollision;
      r.blocking_pair = blocking;
      r.diagnosis = "blocked by a collision pair at its safety distance: " + blocking + "; " + s.str();
      if (!limits.empty()) r.diagnosis += "; also at a limit: " + limits;
    } else if (!r.limit_joints.empty()) {
      r.failure = IkFailure::kJointLimit;
      r.diagnosis = "stuck at a joint limit: " + limits + " (the target needs it further); " + s.str();
    } else {
      r.failure = IkFailure::kUnreachable;
      r.diagnosis = "unreachable: " + s.str();
    }
    if (!a.clear) r.diagnosis += "; no configuration found is clear of collisions";
    return r;
  }

  IkResult solve(const Eigen::VectorXd& seed) {
    const auto start = std::chrono::steady_clock::now();
    std::mt19937 rng(20261206);
    Attempt best;
    Eigen::VectorXd s = seed;
    for (int k = 0; k <= options_.restarts; ++k) {
      if (k > 0) {
        for (int j = 0; j < robot_.dof(); ++j) {
          const double lo = std::max(lower_(j), -M_PI), hi = std::min(upper_(j), M_PI);
          s(j) = lo < hi ? std::uniform_real_distribution<double>(lo, hi)(rng) : 0.5 * (lower_(j) + upper_(j));
        }
      }
      ++seeds_;
      Attempt a = run(s);
      const bool better = a.converged || best.theta.size() == 0 || (a.clear && !best.clear) ||
                          (a.clear == best.clear && a.merit < best.merit);
      if (better) best = std::move(a);
      if (best.converged) break;
      if (k == 0 && !beyond_reach().empty()) break;  // no other seed can reach it (kin_ holds the last step's)
    }
    IkResult r = finish(best, best.converged);
    r.iterations = iterations_;
    r.seeds = seeds_;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
  }

 private:
  const RobotModel& robot_;
  IkTarget target_;
  IkOptions options_;
  RobotModel model_;
  Eigen::VectorXd margin_, lower_, upper_;
  std::vector<Clone> clones_;
  std::unique_ptr<Scheme> scheme_;
  std::unique_ptr<LviEngine> engine_;
  std::unique_ptr<Controller> ctrl_;
  StepOutput out_;
  std::unique_ptr<KinematicsData> kin_;
  Eigen::VectorXd r_d_, r_d_dot_;
  Eigen::Vector3d rotvec_ = Eigen::Vector3d::Zero();
  double phi_ = 0.0;
  int iterations_ = 0, seeds_ = 0;
};

}  // namespace

IkTarget IkTarget::spatial(const Eigen::Vector3d& position, const std::optional<Eigen::Vector3d>& rpy) {
  IkTarget t;
  t.position = position;
  if (rpy) t.rotation = rpy_matrix({(*rpy)(0), (*rpy)(1), (*rpy)(2)});
  return t;
}

IkTarget IkTarget::planar(double x, double y, std::optional<double> phi) {
  IkTarget t;
  t.position = Eigen::Vector3d(x, y, 0.0);
  if (phi) t.rotation = Eigen::AngleAxisd(*phi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return t;
}

const char* to_string(IkFailure failure) noexcept {
  switch (failure) {
    case IkFailure::kNone: return "none";
    case IkFailure::kUnreachable: return "unreachable";
    case IkFailure::kJointLimit: return "joint_limit";
    case IkFailure::kCollision: return "collision";
    case IkFailure::kSolver: return "solver";
  }
  return "unknown";
}

std::string IkResult::summary() const {
  std::ostringstream s;
  s.precision(3);
  if (converged) {
    s << "converged in " << iterations << " iteration" << (iterations == 1 ? "" : "s") << " (" << seeds << " seed"
      << (seeds == 1 ? "" : "s") << ", " << seconds * 1e3 << " ms): position error " << position_error
      << " m, orientation error " << orientation_error << " rad";
    if (std::isfinite(min_distance)) s << ", nearest collision pair " << min_distance << " m";
    return s.str();
  }
  return "did not converge (" + std::string(to_string(failure)) + "): " + diagnosis;
}

IkResult solve_ik(const RobotModel& robot, const IkTarget& target, const Eigen::VectorXd& seed,
                  const std::vector<const Constraint*>& collision, const IkOptions& options) {
  const int n = robot.dof();
  REDRES_REQUIRE(seed.size() == n && seed.allFinite(), "solve_ik", "the seed has one finite value per joint");
  REDRES_REQUIRE(target.position.allFinite() && (!target.rotation || target.rotation->allFinite()), "solve_ik",
                 "the target is finite");
  REDRES_REQUIRE(!target.rotation || std::abs(target.rotation->determinant() - 1.0) < 1e-6, "solve_ik",
                 "the target's rotation is a rotation matrix");
  REDRES_REQUIRE(options.margin.size() == 1 || options.margin.size() == n, "solve_ik",
                 "the margin is one number or one per joint");
  REDRES_REQUIRE(options.margin.allFinite() && options.margin.minCoeff() >= 0.0, "solve_ik", "the margin is >= 0");
  for (int j = 0; j < n; ++j) {
    const double m = options.margin(options.margin.size() == 1 ? 0 : j);
    REDRES_REQUIRE(2.0 * m < robot.upper_limits()(j) - robot.lower_limits()(j), "solve_ik",
                   "the margin is below half the range of joint '" + robot.joint(j).name + "'");
  }
  REDRES_REQUIRE(std::isfinite(options.max_step) && options.max_step > 0.0, "solve_ik", "max_step > 0");
  REDRES_REQUIRE(options.position_tolerance > 0.0 && options.orientation_tolerance > 0.0, "solve_ik",
                 "the tolerances are > 0");
  REDRES_REQUIRE(options.max_iterations >= 1 && options.stall_iterations >= 1 && options.restarts >= 0, "solve_ik",
                 "max_iterations >= 1, stall_iterations >= 1 and restarts >= 0");
  const bool planar = robot.kind() == ChainKind::kPlanar;
  if (planar && target.rotation) {
    const Eigen::Matrix3d& R = *target.rotation;
    REDRES_REQUIRE(std::abs(R(2, 2) - 1.0) < 1e-9, "solve_ik",
                   "a planar robot's target orientation is a rotation about z (phi)");
  }
  for (const std::string& row : target.rows) {
    const bool orientation = row == "phi" || row == "wx" || row == "wy" || row == "wz";
    REDRES_REQUIRE(!orientation || target.rotation, "solve_ik",
                   "an orientation row ('" + row + "') comes with a target orientation");
  }
  IkSolver solver(robot, target, collision, options);
  return solver.solve(seed);
}

}  // namespace redres

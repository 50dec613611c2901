#include "redres/control/controller.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>

#include "redres/common/hot.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/control/path.hpp"

namespace redres {

namespace {
LviEngine& not_null(const std::unique_ptr<LviEngine>& engine) {
  REDRES_REQUIRE(engine != nullptr, "Controller", "an engine (not null)");
  return *engine;
}
}  // namespace

Controller::Controller(const RobotModel& robot, const Scheme& scheme, std::unique_ptr<LviEngine> engine,
                       const Path* path, double T, double tau)
    : Controller(robot, scheme, not_null(engine), path, T, tau) {
  own_engine_ = std::move(engine);
}

Controller::Controller(const RobotModel& robot, const Scheme& scheme, LviEngine& engine, const Path* path, double T,
                       double tau)
    : robot_(&robot),
      scheme_(&scheme),
      data_(std::make_shared<SchemeData>(scheme.make_data())),
      engine_(&engine),
      path_(path),
      kin_(robot),
      r_d_(Eigen::VectorXd::Zero(robot.reference_dim())),
      r_d_dot_(Eigen::VectorXd::Zero(robot.reference_dim())),
      r_d_ddot_(Eigen::VectorXd::Zero(robot.reference_dim())),
      vlo_(Eigen::VectorXd::Zero(robot.dof())),
      vhi_(Eigen::VectorXd::Zero(robot.dof())),
      prev_(Eigen::VectorXd::Zero(robot.dof())),
      prev2_(Eigen::VectorXd::Zero(robot.dof())),
      pending_(Eigen::VectorXd::Zero(robot.dof())),
      measured_(Eigen::VectorXd::Zero(robot.dof())),
      v_(Eigen::VectorXd::Zero(robot.dof())),
      acc_lo_(Eigen::VectorXd::Zero(robot.dof())),
      acc_hi_(Eigen::VectorXd::Zero(robot.dof())),
      jerk_lo_(Eigen::VectorXd::Zero(robot.dof())),
      jerk_hi_(Eigen::VectorXd::Zero(robot.dof())) {
  REDRES_REQUIRE(&scheme.robot() == &robot, "Controller", "the scheme was built for this robot");
  REDRES_REQUIRE(T > 0.0 && tau > 0.0, "Controller", "T > 0 and tau > 0");
  if (path != nullptr) {
    const int position_rows = robot.position_rows();
    REDRES_REQUIRE(path->dim() == position_rows, "Controller",
                   "the path has one row per task position row (" + std::to_string(position_rows) + ")");
  }
  level_ = scheme.kinematics_level();
  cascade_ = std::make_unique<Cascade>(scheme, *data_, engine);  // every scheme is a list of levels (one QP each)
  ctx_.T = T;
  ctx_.tau = tau;
  ctx_.robot = &robot;
  ctx_.kinematics = &kin_;
  ctx_.r_d = &r_d_;
  ctx_.r_d_dot = &r_d_dot_;
  ctx_.velocity_lower = &vlo_;
  ctx_.velocity_upper = &vhi_;
  if (robot.has_acceleration_limits()) {
    ctx_.acceleration_lower = &acc_lo_;
    ctx_.acceleration_upper = &acc_hi_;
  }
  if (robot.has_jerk_limits()) {
    ctx_.jerk_lower = &jerk_lo_;
    ctx_.jerk_upper = &jerk_hi_;
  }
  ctx_.theta_dot_prev = &prev_;
  ctx_.theta_dot_prev2 = &prev2_;
  ctx_.status_prev = SolverStatus::kNotRun;
  ctx_.order = scheme.order();
  if (ctx_.order == ControlOrder::kAcceleration) {
    ctx_.r_d_ddot = &r_d_ddot_;
    ctx_.theta_dot = &v_;
  }
  // The default policy recovers: a robot with acceleration limits brakes (and catches up by the elastic QP), one
  // without relaxes its rows. Neither stops at once.
  set_failure_policy(robot.has_acceleration_limits() ? FailurePolicy::kBrake : FailurePolicy::kRelax);
}

StepOutput Controller::make_output() const {
  StepOutput out;
  out.theta_dot = Eigen::VectorXd::Zero(robot_->dof());
  out.theta_ddot = Eigen::VectorXd::Zero(robot_->dof());
  out.info.diagnosis.reserve(kDiagnosisCapacity);  // a failed step's text is written here without allocating
  if (scheme_->cascaded()) {                       // one level: info says it all
    out.levels = cascade_->levels();
    for (LevelInfo& level : out.levels) level.diagnosis.reserve(kDiagnosisCapacity);
  }
  return out;
}

void Controller::reset() {
  cascade_->reset();
  orientation_.forget_captured();
  prev_.setZero();
  prev2_.setZero();
  have_pending_ = false;
  started_ = false;
  ctx_.step_index = 0;
  ctx_.status_prev = SolverStatus::kNotRun;
}

void Controller::begin_step() {
  if (!started_) {
    scheme_->start(*data_);  // the plugins forget an earlier run
    started_ = true;
  }
  if (have_pending_) {
    prev2_.swap(prev_);  // same sizes: the buffers change hands, nothing is allocated
    prev_.swap(pending_);
    ctx_.status_prev = pending_status_;
    ++ctx_.step_index;
    have_pending_ = false;
  }
  if (ctx_.order == ControlOrder::kAcceleration) v_ = ctx_.theta_dot_measured != nullptr ? measured_ : prev_;
}

void Controller::end_step(const StepOutput& out) {
  pending_ = out.theta_dot;
  pending_status_ = out.info.status;
  have_pending_ = true;
}

void Controller::set_applied(const Eigen::Ref<const Eigen::VectorXd>& theta_dot) {
  REDRES_REQUIRE(have_pending_, "Controller::set_applied", "a step was made since the last set_applied() or reset()");
  REDRES_REQUIRE(theta_dot.size() == robot_->dof() && theta_dot.allFinite(), "Controller::set_applied",
                 "theta_dot has dof() = " + std::to_string(robot_->dof()) + " finite entries");
  pending_ = theta_dot;
}

void Controller::set_period(double tau) {
  REDRES_REQUIRE(std::isfinite(tau) && tau > 0.0, "Controller::set_period", "tau > 0 and finite");
  ctx_.tau = tau;
}

REDRES_HOT void Controller::step(const Eigen::Ref<const Eigen::VectorXd>& theta, double t, StepOutput& out) {
  REDRES_REQUIRE(path_ != nullptr, "Controller::step", "a path was given (or pass r_d and r_d_dot)");
  begin_step();
  reevaluate(theta, t, out);
  end_step(out);
}

void Controller::step(const Eigen::Ref<const Eigen::VectorXd>& theta,
                      const Eigen::Ref<const Eigen::VectorXd>& theta_dot_measured, double t, StepOutput& out) {
  REDRES_REQUIRE(theta_dot_measured.size() == robot_->dof() && theta_dot_measured.allFinite(), "Controller::step",
                 "theta_dot_measured has dof() = " + std::to_string(robot_->dof()) + " finite entries");
  measured_ = theta_dot_measured;
  ctx_.theta_dot_measured = &measured_;
  try {
    step(theta, t, out);
  } catch (...) {
    ctx_.theta_dot_measured = nullptr;
    throw;
  }
  ctx_.theta_dot_measured = nullptr;
}

REDRES_HOT void Controller::reevaluate(const Eigen::Ref<const Eigen::VectorXd>& theta, double t, StepOutput& out) {
  REDRES_REQUIRE(path_ != nullptr, "Controller::step", "a path was given (or pass r_d and r_d_dot)");
  compute_kinematics(*robot_, theta, kin_, level_);
  const int p = path_->dim();
  if (ctx_.order == ControlOrder::kVelocity) {
    path_->evaluate(t, r_d_.head(p), r_d_dot_.head(p));
    if (robot_->reference_dim() > p) orientation_.evaluate(*robot_, kin_, t, ctx_.T, p, r_d_, r_d_dot_);
  } else {
    path_->evaluate(t, r_d_.head(p), r_d_dot_.head(p), r_d_ddot_.head(p));
    if (robot_->reference_dim() > p) orientation_.evaluate(*robot_, kin_, t, ctx_.T, p, r_d_, r_d_dot_, r_d_ddot_);
  }
  solve(t, out);
}

void Controller::step(const Eigen::Ref<const Eigen::VectorXd>& theta, double t,
                      const Eigen::Ref<const Eigen::VectorXd>& r_d, const Eigen::Ref<const Eigen::VectorXd>& r_d_dot,
                      StepOutput& out) {
  REDRES_REQUIRE(ctx_.order == ControlOrder::kVelocity, "Controller::step",
                 "a velocity-level scheme (an acceleration-level one needs r_d_ddot too)");
  step(theta, t, r_d, r_d_dot, r_d_dot, out);  // r_d_ddot is not read at the velocity level
}

void Controller::step(const Eigen::Ref<const Eigen::VectorXd>& theta, double t,
                      const Eigen::Ref<const Eigen::VectorXd>& r_d, const Eigen::Ref<const Eigen::VectorXd>& r_d_dot,
                      const Eigen::Ref<const Eigen::VectorXd>& r_d_ddot, StepOutput& out) {
  const int m = robot_->reference_dim();
  REDRES_REQUIRE(r_d.size() == m && r_d_dot.size() == m && r_d_ddot.size() == m, "Controller::step",
                 "r_d, r_d_dot and r_d_ddot have reference_dim() = " + std::to_string(m) + " entries (got " +
                     std::to_string(r_d.size()) + ", " + std::to_string(r_d_dot.size()) + " and " +
                     std::to_string(r_d_ddot.size()) + ")");
  REDRES_REQUIRE(r_d.allFinite() && r_d_dot.allFinite() && r_d_ddot.allFinite(), "Controller::step",
                 "r_d, r_d_dot and r_d_ddot are finite");
  begin_step();
  compute_kinematics(*robot_, theta, kin_, level_);
  r_d_ = r_d;
  r_d_dot_ = r_d_dot;
  if (ctx_.order == ControlOrder::kAcceleration) r_d_ddot_ = r_d_ddot;
  solve(t, out);
  end_step(out);
}

REDRES_HOT void Controller::apply(const Eigen::VectorXd& x, StepOutput& out) {
  const double tau = ctx_.tau;
  if (ctx_.order == ControlOrder::kVelocity) {
    out.theta_dot = x;
    out.theta_ddot = (x - prev_) / tau;
  } else {
    out.theta_ddot = x;
    out.theta_dot = v_ + tau * x;
  }
}

REDRES_HOT void Controller::solve(double t, StepOutput& out) {
  REDRES_REQUIRE(out.theta_dot.size() == robot_->dof() && out.theta_ddot.size() == robot_->dof(), "Controller::step",
                 "out was made by make_output() (theta_dot and theta_ddot have n entries)");
  ctx_.t = t;
  out.task_row_error = 0.0;
  const bool several = scheme_->cascaded();
  REDRES_REQUIRE(out.levels.size() == (several ? static_cast<std::size_t>(cascade_->level_count()) : 0),
                 "Controller::step", "out was made by make_output() (one LevelInfo per priority level, if several)");
  keep_diagnosis_capacity(out.info.diagnosis);  // a no-op unless the caller's output lost its reserve
  const Eigen::VectorXd* answer = nullptr;
  try {
    // Every law once per step, read through the Context (and by braking, should the step fail).
    if (ctx_.acceleration_lower != nullptr) robot_->acceleration_limits(kin_.theta, acc_lo_, acc_hi_);
    if (ctx_.jerk_lower != nullptr) robot_->jerk_limits(kin_.theta, jerk_lo_, jerk_hi_);
    robot_->velocity_limits(kin_.theta, vlo_, vhi_);
    answer = cascade_->solve(ctx_, *data_, out.info);
  } catch (const std::invalid_argument& e) {
    // A plugin or a law gave NaN or inf at this state (a user formula that is NaN in a narrow window): a failed step
    // that moves nothing, not the end of the run. The controller's own calls meet build()'s other conditions.
    out.info.status = SolverStatus::kInvalidProblem;
    out.info.iterations = 0;
    out.info.residual = 0.0;
    out.info.engine = engine_->name();
    out.info.diagnosis = e.what();
    // A velocity-limit law that gave NaN or inf is named with where it was configured (the QP's own check saw only
    // the merged bounds).
    for (int j = 0; j < robot_->dof(); ++j) {
      if (std::isfinite(vlo_(j)) && std::isfinite(vhi_(j))) continue;
      const JointSpec& joint = robot_->joint(j);
      std::ostringstream s;
      s << "joint " << j + 1 << " ('" << joint.name << "') velocity limit " << joint.velocity_limit->describe();
      if (!joint.velocity_limit_source.empty()) s << " (" << joint.velocity_limit_source << ")";
      const auto show = [&s](double v) -> std::ostream& { return std::isnan(v) ? s << "nan" : s << v; };
      s << " gave lower ";
      show(vlo_(j)) << ", upper ";
      show(vhi_(j)) << " at theta = " << kin_.theta(j) << ": not finite";
      out.info.diagnosis = s.str();
      break;
    }
    engine_->reset();  // the next step starts cold
    give_up(out);
    return;
  }
  if (several) {
    for (std::size_t l = 0; l < out.levels.size(); ++l)
      out.levels[l] = cascade_->levels()[l];  // reserved: no allocation
  }
  if (answer != nullptr) {
    apply(*answer, out);
    return;
  }
  // The step failed: the policy decides (never the unconverged iterate).
  bool relaxed = false;
  if (policy_ == FailurePolicy::kRelax) {
    relaxed = relax(out);
  } else if (policy_ == FailurePolicy::kBrake) {
    const int p = robot_->position_rows();
    const double error = (r_d_.head(p) - kin_.f.head(p)).norm();
    if (error > recover_error_) relaxed = relax(out);  // behind the target: catch up within the limits
  }
  if (!relaxed) give_up(out);
}

void Controller::give_up(StepOutput& out) {
  if (policy_ != FailurePolicy::kHold && robot_->has_acceleration_limits()) {
    brake(out);
    return;
  }
  out.theta_dot.setZero();  // hold: nothing bounds the deceleration, or the caller chose it
  out.theta_ddot = -base() / ctx_.tau;
}

void Controller::set_relaxation(double weight) {
  REDRES_REQUIRE(std::isfinite(weight) && weight >= 0.0, "Controller::set_relaxation", "weight >= 0 and finite");
  if (weight == 0.0) {
    set_failure_policy(robot_->has_acceleration_limits() ? FailurePolicy::kBrake : FailurePolicy::kHold);
    return;
  }
  set_failure_policy(FailurePolicy::kRelax, weight, recover_error_);
}

void Controller::set_failure_policy(FailurePolicy policy, double relax_weight, double recover_error) {
  REDRES_REQUIRE(std::isfinite(relax_weight) && relax_weight > 0.0, "Controller::set_failure_policy",
                 "relax_weight > 0 and finite");
  REDRES_REQUIRE(std::isfinite(recover_error) && recover_error > 0.0, "Controller::set_failure_policy",
                 "recover_error > 0 and finite");
  const bool limits = robot_->has_acceleration_limits();
  if (policy == FailurePolicy::kHold && limits) {
    throw std::invalid_argument(
        "Controller::set_failure_policy: 'hold' stops every joint at once, a velocity jump that robot '" +
        robot_->name() + "''s acceleration limits forbid; use 'brake' (its default) or 'relax'");
  }
  if (policy == FailurePolicy::kBrake && !limits) {
    const int j = robot_->first_without_acceleration_limit();
    throw std::invalid_argument(
        "Controller::set_failure_policy: 'brake' decelerates within the joints' acceleration "
        "limits, and joint " +
        std::to_string(j + 1) + " ('" + robot_->joint(j).name + "') of robot '" + robot_->name() +
        "' has none (give `acceleration_limit` in the robot file)");
  }
  policy_ = policy;
  const bool elastic = policy == FailurePolicy::kRelax || policy == FailurePolicy::kBrake;
  relax_weight_ = elastic ? relax_weight : 0.0;
  recover_error_ = recover_error;
  if (!elastic) {
    fallback_.release();
    return;
  }
  note_.reserve(kDiagnosisCapacity);
  if (!fallback_.ready()) fallback_.setup(cascade_->problem(0), *engine_);
}

bool Controller::relax(StepOutput& out) {
  // The elastic QP (qp/elastic.hpp): the rows become a penalty of weight rho; bounds and inequality rows stay.
  const double rho = relax_weight_;
  const SolverResult& relaxed = fallback_.solve(cascade_->problem(0), rho);
  const SolverInfo& r = relaxed.info;
  if (r.status != SolverStatus::kSolved) {
    TextSink(out.info.diagnosis).precision(6) << "; the elastic QP (rows relaxed with weight " << rho
                                              << ") failed too: " << to_string(r.status) << ": " << r.diagnosis;
    return false;
  }
  out.task_row_error = fallback_.row_miss();
  apply(relaxed.x, out);
  // The failed solve's text goes after the relaxation's: kept aside in note_ (both reserved, so no allocation).
  note_.assign(out.info.diagnosis);  // note_ is reserved: a copy, so each string keeps its own storage
  keep_diagnosis_capacity(out.info.diagnosis);
  out.info.diagnosis.clear();
  TextSink(out.info.diagnosis).precision(6) << "rows relaxed (weight " << rho << "), missed by " << out.task_row_error
                                            << " at most, after " << to_string(out.info.status) << ": " << note_;
  out.info.status = SolverStatus::kRelaxed;
  out.info.iterations += r.iterations;
  out.info.residual = r.residual;
  return true;
}

void Controller::brake(StepOutput& out) {
  // The braking law (control/brake.hpp): theta_dot = s b, b the velocity before the step.
  const Eigen::VectorXd& b = base();
  // The laws at theta, as the step evaluated them (brake() runs only for a robot with acceleration limits).
  BrakeInput in;
  in.velocity = &b;
  in.acceleration_lower = &acc_lo_;
  in.acceleration_upper = &acc_hi_;
  in.velocity_lower = &vlo_;
  in.velocity_upper = &vhi_;
  in.jerk_lower = ctx_.jerk_lower;
  in.jerk_upper = ctx_.jerk_upper;
  in.previous = &prev_;
  in.previous2 = &prev2_;
  in.tau = ctx_.tau;
  const BrakeScale scale = braking_scale(in);
  const double s = scale.scale;
  const int decides = scale.deciding_joint;
  const bool jerk_yields = scale.jerk_yields;
  const double tau = ctx_.tau;
  out.theta_dot = s * b;
  for (int j = 0; j < robot_->dof(); ++j) {
    if (!std::isfinite(out.theta_dot(j))) out.theta_dot(j) = 0.0;  // never a non-finite command
  }
  out.theta_ddot = (out.theta_dot - b) / tau;
  out.task_row_error = 0.0;
  note_.assign(out.info.diagnosis);
  keep_diagnosis_capacity(out.info.diagnosis);
  out.info.diagnosis.clear();
  TextSink sink(out.info.diagnosis);
  sink.precision(6) << "braked to " << s << " of the previous command";
  if (decides >= 0) sink << " (joint " << decides + 1 << " '" << robot_->joint(decides).name << "' at its limit)";
  if (jerk_yields) sink << ", the jerk limits yielding to the acceleration limits";
  sink << ", after " << to_string(out.info.status) << ": " << note_;
  out.info.status = SolverStatus::kBraked;
}

}  // namespace redres

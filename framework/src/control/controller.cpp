#include "redres/control/controller.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>

#include "redres/control/engine_registry.hpp"
#include "redres/control/path.hpp"

namespace redres {

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
      vlo_(Eigen::VectorXd::Zero(robot.dof())),
      vhi_(Eigen::VectorXd::Zero(robot.dof())),
      prev_(Eigen::VectorXd::Zero(robot.dof())),
      prev2_(Eigen::VectorXd::Zero(robot.dof())),
      pending_(Eigen::VectorXd::Zero(robot.dof())),
      measured_(Eigen::VectorXd::Zero(robot.dof())) {
  REDRES_REQUIRE(&scheme.robot() == &robot, "Controller", "the scheme was built for this robot");
  REDRES_REQUIRE(T > 0.0 && tau > 0.0, "Controller", "T > 0 and tau > 0");
  if (path != nullptr) {
    const int position_rows = robot.position_rows();
    REDRES_REQUIRE(path->dim() == position_rows, "Controller",
                   "the path has one row per task position row (" + std::to_string(position_rows) + ")");
  }
  level_ = scheme.kinematics_level();
  scheme.setup(qp_, *data_);
  engine.setup(qp_.n(), qp_.m_eq(), qp_.m_in(), result_);
  ctx_.T = T;
  ctx_.tau = tau;
  ctx_.robot = &robot;
  ctx_.kinematics = &kin_;
  ctx_.r_d = &r_d_;
  ctx_.r_d_dot = &r_d_dot_;
  ctx_.velocity_lower = &vlo_;
  ctx_.velocity_upper = &vhi_;
  ctx_.theta_dot_prev = &prev_;
  ctx_.theta_dot_prev2 = &prev2_;
  ctx_.status_prev = SolverStatus::kNotRun;
}

StepOutput Controller::make_output() const {
  StepOutput out;
  out.theta_dot = Eigen::VectorXd::Zero(robot_->dof());
  out.info.diagnosis.reserve(kDiagnosisCapacity);  // a failed step's text is written here without allocating
  return out;
}

void Controller::reset() {
  engine_->reset();
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
  if (!have_pending_) return;
  prev2_.swap(prev_);  // same sizes: the buffers change hands, nothing is allocated
  prev_.swap(pending_);
  ctx_.status_prev = pending_status_;
  ++ctx_.step_index;
  have_pending_ = false;
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

void Controller::step(const Eigen::Ref<const Eigen::VectorXd>& theta, double t, StepOutput& out) {
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

void Controller::reevaluate(const Eigen::Ref<const Eigen::VectorXd>& theta, double t, StepOutput& out) {
  REDRES_REQUIRE(path_ != nullptr, "Controller::step", "a path was given (or pass r_d and r_d_dot)");
  compute_kinematics(*robot_, theta, kin_, level_);
  const int p = path_->dim();
  path_->evaluate(t, r_d_.head(p), r_d_dot_.head(p));
  if (robot_->reference_dim() > p) orientation_.evaluate(*robot_, kin_, t, ctx_.T, p, r_d_, r_d_dot_);
  solve(t, out);
}

void Controller::step(const Eigen::Ref<const Eigen::VectorXd>& theta, double t,
                      const Eigen::Ref<const Eigen::VectorXd>& r_d, const Eigen::Ref<const Eigen::VectorXd>& r_d_dot,
                      StepOutput& out) {
  const int m = robot_->reference_dim();
  REDRES_REQUIRE(r_d.size() == m && r_d_dot.size() == m, "Controller::step",
                 "r_d and r_d_dot have reference_dim() = " + std::to_string(m) + " entries (got " +
                     std::to_string(r_d.size()) + " and " + std::to_string(r_d_dot.size()) + ")");
  REDRES_REQUIRE(r_d.allFinite() && r_d_dot.allFinite(), "Controller::step", "r_d and r_d_dot are finite");
  begin_step();
  compute_kinematics(*robot_, theta, kin_, level_);
  r_d_ = r_d;
  r_d_dot_ = r_d_dot;
  solve(t, out);
  end_step(out);
}

void Controller::solve(double t, StepOutput& out) {
  REDRES_REQUIRE(out.theta_dot.size() == robot_->dof(), "Controller::step",
                 "out was made by make_output() (theta_dot has n entries)");
  ctx_.t = t;
  try {
    robot_->velocity_limits(kin_.theta, vlo_, vhi_);
    scheme_->build(ctx_, qp_, *data_);
  } catch (const std::invalid_argument& e) {
    // A plugin or a law gave NaN or inf at this state (a user formula that is NaN in a narrow window): a failed step
    // that moves nothing, not the end of the run. The controller's own calls meet build()'s other conditions.
    out.theta_dot.setZero();
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
    out.task_row_error = 0.0;
    engine_->reset();  // the next step starts cold
    return;
  }
  engine_->solve_valid(qp_, result_);           // build() checked every entry it wrote
  keep_diagnosis_capacity(out.info.diagnosis);  // a no-op unless the caller's output lost its reserve
  out.info = result_.info;
  out.task_row_error = 0.0;
  if (result_.info.status == SolverStatus::kSolved) {
    out.theta_dot = result_.x;
    return;
  }
  out.theta_dot.setZero();  // hold: an unconverged iterate is never integrated
  if (relax_engine_) relax(out);
}

void Controller::set_relaxation(double weight) {
  REDRES_REQUIRE(std::isfinite(weight) && weight >= 0.0, "Controller::set_relaxation", "weight >= 0 and finite");
  relax_weight_ = weight;
  if (weight == 0.0) {
    relax_engine_.reset();
    return;
  }
  if (!relax_engine_) {
    relax_engine_ = make_engine(std::string(engine_->name()), engine_->settings());
    relaxed_.setup(qp_);
    relax_engine_->setup(qp_.n(), 0, qp_.m_in(), relaxed_result_);
    note_.reserve(kDiagnosisCapacity);
    row_miss_.resize(qp_.m_eq());
  }
}

void Controller::relax(StepOutput& out) {
  // The elastic QP (qp/elastic.hpp): the rows become a penalty of weight rho; bounds and inequality rows stay.
  const double rho = relax_weight_;
  relaxed_.build(qp_, rho);
  relax_engine_->solve_valid(relaxed_.problem(), relaxed_result_);
  const SolverInfo& r = relaxed_result_.info;
  if (r.status != SolverStatus::kSolved) {
    TextSink(out.info.diagnosis).precision(6) << "; the elastic QP (rows relaxed with weight " << rho
                                              << ") failed too: " << to_string(r.status) << ": " << r.diagnosis;
    return;
  }
  out.theta_dot = relaxed_result_.x;
  row_miss_.noalias() = qp_.J * out.theta_dot;  // sized at set_relaxation(): no temporary
  row_miss_ -= qp_.d;
  out.task_row_error = qp_.m_eq() > 0 ? row_miss_.cwiseAbs().maxCoeff() : 0.0;
  // The failed solve's text goes after the relaxation's: kept aside in note_ (both reserved, so no allocation).
  note_.assign(out.info.diagnosis);  // note_ is reserved: a copy, so each string keeps its own storage
  keep_diagnosis_capacity(out.info.diagnosis);
  out.info.diagnosis.clear();
  TextSink(out.info.diagnosis).precision(6) << "rows relaxed (weight " << rho << "), missed by " << out.task_row_error
                                            << " at most, after " << to_string(out.info.status) << ": " << note_;
  out.info.status = SolverStatus::kRelaxed;
  out.info.iterations += r.iterations;
  out.info.residual = r.residual;
}

}  // namespace redres

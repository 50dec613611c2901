#include "redres/controller.hpp"

namespace redres {

Controller::Controller(const RobotModel& robot, const Scheme& scheme, LviEngine& engine, const Path* path, double T,
                       double tau)
    : robot_(&robot),
      scheme_(&scheme),
      engine_(&engine),
      path_(path),
      kin_(robot),
      r_d_(Eigen::VectorXd::Zero(robot.task_dim())),
      r_d_dot_(Eigen::VectorXd::Zero(robot.task_dim())) {
  REDRES_REQUIRE(&scheme.robot() == &robot, "Controller", "the scheme was built for this robot");
  REDRES_REQUIRE(T > 0.0 && tau > 0.0, "Controller", "T > 0 and tau > 0");
  if (path != nullptr) {
    const int position_rows = robot.kind() == ChainKind::kPlanar ? 2 : 3;
    REDRES_REQUIRE(path->dim() == position_rows, "Controller",
                   "the path has one row per task position row (" + std::to_string(position_rows) + ")");
  }
  level_ = scheme.kinematics_level();
  scheme.setup(qp_);
  engine.setup(qp_.n(), qp_.m_eq(), qp_.m_in(), result_);
  ctx_.T = T;
  ctx_.tau = tau;
  ctx_.robot = &robot;
  ctx_.kinematics = &kin_;
  ctx_.r_d = &r_d_;
  ctx_.r_d_dot = &r_d_dot_;
}

StepOutput Controller::step(const Eigen::Ref<const Eigen::VectorXd>& theta, double t) {
  REDRES_REQUIRE(path_ != nullptr, "Controller::step", "a path was given (or pass r_d and r_d_dot)");
  compute_kinematics(*robot_, theta, kin_, level_);
  const int p = path_->dim();
  path_->evaluate(t, r_d_.head(p), r_d_dot_.head(p));
  if (robot_->task_dim() > p) {
    const int rest = robot_->task_dim() - p;
    if (robot_->kind() == ChainKind::kPlanar) {
      r_d_(2) = orientation_.z();
    } else {
      r_d_.tail(rest) = orientation_;
    }
    r_d_dot_.tail(rest).setZero();
  }
  return solve(t);
}

StepOutput Controller::step(const Eigen::Ref<const Eigen::VectorXd>& theta, double t,
                            const Eigen::Ref<const Eigen::VectorXd>& r_d,
                            const Eigen::Ref<const Eigen::VectorXd>& r_d_dot) {
  REDRES_REQUIRE(r_d.size() == robot_->task_dim() && r_d_dot.size() == robot_->task_dim(), "Controller::step",
                 "r_d and r_d_dot have task_dim() = " + std::to_string(robot_->task_dim()) + " entries");
  REDRES_REQUIRE(r_d.allFinite() && r_d_dot.allFinite(), "Controller::step", "r_d and r_d_dot are finite");
  compute_kinematics(*robot_, theta, kin_, level_);
  r_d_ = r_d;
  r_d_dot_ = r_d_dot;
  return solve(t);
}

StepOutput Controller::solve(double t) {
  ctx_.t = t;
  scheme_->build(ctx_, qp_);
  engine_->solve(qp_, result_);
  return {result_.x, result_.info};
}

}  // namespace redres

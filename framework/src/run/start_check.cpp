#include "redres/run/start_check.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>

#include <Eigen/SVD>

#include "redres/control/controller.hpp"

namespace redres {

namespace {

std::string num(double v) {
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

std::string vector_text(const Eigen::VectorXd& v) {
  std::ostringstream s;
  s.precision(4);
  s << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s << (i > 0 ? ", " : "") << v(i);
  s << "]";
  return s.str();
}

// The smallest singular value of the task rows' Jacobian at theta (KinematicsData::J holds the task rows only).
double task_sigma_min(const RobotModel& robot, const Eigen::VectorXd& theta, KinematicsData& k) {
  compute_kinematics(robot, theta, k, KinematicsLevel::kGradient);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(k.J);
  return svd.singularValues().size() > 0 ? svd.singularValues().minCoeff() : 0.0;
}

// A configuration near theta whose task Jacobian is well conditioned: the best of random moves of up to 0.2 rad
// (within the limits), a fixed seed so that the suggestion is reproducible.
Eigen::VectorXd nearby_regular(const RobotModel& robot, const Eigen::VectorXd& theta, KinematicsData& k,
                               double& sigma) {
  std::mt19937 rng(26);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  Eigen::VectorXd best = theta, candidate(theta.size());
  sigma = task_sigma_min(robot, theta, k);
  for (int trial = 0; trial < 200; ++trial) {
    for (Eigen::Index j = 0; j < theta.size(); ++j) {
      candidate(j) = std::clamp(theta(j) + u(rng), robot.lower_limits()(j), robot.upper_limits()(j));
    }
    const double s = task_sigma_min(robot, candidate, k);
    if (s > sigma) {
      sigma = s;
      best = candidate;
    }
  }
  return best;
}

}  // namespace

std::string StartReport::text() const {
  std::string out;
  for (const StartProblem& p : problems) {
    if (!out.empty()) out += "\n";
    out += "theta(0) " + p.message;
    if (!p.suggestion.empty()) out += " (" + p.suggestion + ")";
  }
  return out;
}

StartError::StartError(StartReport report)
    : std::runtime_error("the start is not usable:\n" + report.text()), report_(std::move(report)) {}

StartReport check_start(const Scenario& s) {
  const auto start = std::chrono::steady_clock::now();
  StartReport report;
  const RobotModel& robot = *s.robot;
  const Eigen::VectorXd& theta = s.theta0;
  // Limits.
  for (int j = 0; j < robot.dof(); ++j) {
    const double lo = robot.lower_limits()(j), hi = robot.upper_limits()(j);
    if (theta(j) >= lo && theta(j) <= hi) continue;
    report.problems.push_back({"limits",
                               "puts joint " + std::to_string(j + 1) + " ('" + robot.joint(j).name + "') at " +
                                   num(theta(j)) + ", outside its limits [" + num(lo) + ", " + num(hi) + "]",
                               "set `theta0` within the limits"});
  }
  // Collision: step 0 as the run makes it, then what the constraints find violated.
  {
    const auto ctrl = Controller::from_scenario(s);
    StepOutput out = ctrl->make_output();
    ctrl->step(theta, 0.0, out);
    const auto& constraints = s.scheme->constraints();
    const SchemeData& data = ctrl->plugin_data();
    for (std::size_t c = 0; c < constraints.size(); ++c) {
      const Constraint& k = *constraints[c];
      if (!k.active() || !k.violated(data.constraints[c].get())) continue;
      report.problems.push_back(
          {"collision",
           "is in collision: constraint '" + k.name() + "': " + k.describe_violation(data.constraints[c].get()),
           "move `theta0` (or the obstacle) so that the bodies are apart"});
    }
    // The path at t = 0 against the end effector.
    const int p = robot.position_rows();
    double sq = 0.0;
    for (int r = 0; r < p; ++r) {
      if (!robot.tracks(r)) continue;
      sq += std::pow(ctrl->r_d()(r) - ctrl->kinematics().f(r), 2);
    }
    report.path_offset = std::sqrt(sq);
    if (report.path_offset > s.max_task_error) {
      report.problems.push_back(
          {"path",
           "leaves the end effector " + num(report.path_offset) + " m from where the path starts (r_d(0) = " +
               vector_text(ctrl->r_d().head(p)) + ", f(theta(0)) = " + vector_text(ctrl->kinematics().f.head(p)) +
               "), more than [solver] max_task_error = " + num(s.max_task_error) + " m",
           "start the arm at the path's start, or place the path relative to the end effector (`placement = "
           "\"relative\"`)"});
    }
  }
  // Singularity for the task rows.
  KinematicsData k(robot);
  report.sigma_min = task_sigma_min(robot, theta, k);
  report.w = k.w;
  // Under on_infeasible = "relax", chosen by name, a singular start is allowed: the elastic QP moves the arm out of it.
  // The default policy (relax too, for a robot without acceleration limits) does not allow it: a new user learns of
  // the singular start before the run rather than from its relaxed steps.
  if (!(report.sigma_min >= kSingularTolerance) &&
      !(s.on_infeasible == FailurePolicy::kRelax && s.on_infeasible_given)) {
    double sigma = 0.0;
    const Eigen::VectorXd near = nearby_regular(robot, theta, k, sigma);
    std::string suggestion = "on_infeasible = \"relax\" lets the run start there";
    if (sigma >= kSingularTolerance) {
      suggestion = "a nearby configuration that is not: theta0 = " + vector_text(near) + " (smallest singular value " +
                   num(sigma) + "); or " + suggestion;
    }
    report.problems.push_back({"singular",
                               "is singular for the task: the task rows' Jacobian has smallest singular value " +
                                   num(report.sigma_min) + " (< " + num(kSingularTolerance) + "), w = " + num(report.w),
                               suggestion});
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

void require_good_start(const Scenario& s) {
  StartReport report = check_start(s);
  if (!report.ok()) throw StartError(std::move(report));
}

}  // namespace redres

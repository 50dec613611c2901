// 02: call redres from your own control loop.
//
//   example_02_control_loop [robot.toml]
//
// Builds the paper's TVCMM scheme in C++ from typed plugin configurations (no TOML text), then runs a 100 Hz loop
// that moves the end effector 5 cm along -x with a cycloidal profile. Each cycle calls
// Controller::step(theta, t, r_d, r_d_dot, out), which allocates nothing, and checks the solver's status before
// using theta_dot.

#include <cmath>
#include <iostream>
#include <numbers>

#include <redres/constraints/joint_angle_margin.hpp>
#include <redres/constraints/joint_velocity_limits.hpp>
#include <redres/constraints/task_tracking.hpp>
#include <redres/control/controller.hpp>
#include <redres/engines/newton.hpp>
#include <redres/objectives/manipulability.hpp>
#include <redres/objectives/min_velocity_norm.hpp>
#include "redres/control/engine_registry.hpp"
#include "redres/parsers/robot_toml.hpp"

int main(int argc, char** argv) {
  using namespace redres;
  try {
    const RobotModel robot = load_robot(argc > 1 ? argv[1] : REDRES_EXAMPLE_ROBOT);

    // The scheme: |x|^2/2 - p(t) grad w' x with p(t) = 2 sin(pi t / T), the task, the joint-angle safety margin
    // and the push-rod velocity limits. Every plugin is built from its Config; omitted fields keep their defaults.
    std::vector<std::unique_ptr<Objective>> objectives;
    objectives.push_back(std::make_unique<MinVelocityNorm>(MinVelocityNorm::Config{}, robot));
    objectives.push_back(std::make_unique<Manipulability>(
        Manipulability::Config{
            .p = 2.0, .schedule = Manipulability::Schedule::kSine, .measure = Manipulability::Measure::kDet},
        robot));
    std::vector<std::unique_ptr<Constraint>> constraints;
    constraints.push_back(std::make_unique<TaskTracking>(TaskTracking::Config{.gain = 8.0}, robot));
    // By name from the registry, with a config value: the same as the class, for code that picks plugins by name.
    constraints.push_back(constraint_registry().create(
        "joint_angle_margin", JointAngleMargin::Config{.kappa = 4.0, .margin = 0.0349}, robot));
    constraints.push_back(std::make_unique<JointVelocityLimits>(JointVelocityLimits::Config{.scale = 1.0}, robot));
    const Scheme scheme(robot, std::move(objectives), std::move(constraints));
    const auto engine = engine_registry().create("newton", NewtonConfig{}, SolverSettings{.tolerance = 1e-6});

    const double T = 5.0, tau = 0.01;
    Controller controller(robot, scheme, *engine, nullptr, T, tau);
    StepOutput out = controller.make_output();  // sized once; step() writes into it

    Eigen::VectorXd theta = robot.home();
    KinematicsData k(robot);
    compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
    const Eigen::VectorXd start = k.f;
    Eigen::VectorXd r_d = start, r_d_dot = Eigen::VectorXd::Zero(robot.reference_dim());
    constexpr double two_pi = 2.0 * std::numbers::pi;
    for (int i = 0; i <= 500; ++i) {  // the control loop
      const double t = i * tau, u = t / T;
      r_d(0) = start(0) - 0.05 * (u - std::sin(two_pi * u) / two_pi);
      r_d_dot(0) = -0.05 * (1 - std::cos(two_pi * u)) / T;
      controller.step(theta, t, r_d, r_d_dot, out);
      if (out.info.status != SolverStatus::kSolved) {
        std::cerr << "t = " << t << ": " << to_string(out.info.status) << ": " << out.info.diagnosis << "\n";
        return 1;
      }
      theta += tau * out.theta_dot;  // send theta_dot to the drives; here: integrate
      if (i % 100 == 0) {
        std::cout << "t = " << t << " s  error = " << (r_d - controller.kinematics().f).norm()
                  << " m  w = " << controller.kinematics().w << "  iterations = " << out.info.iterations << "\n";
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
}

// 02: call redres from your own control loop.
//
//   example_02_control_loop [robot.toml]
//
// Builds the TVCMM scheme in code (plugins by name, from TOML text), then runs a 100 Hz loop that moves the end
// effector 5 cm along -x with a cycloidal profile. Each cycle calls Controller::step(theta, t, r_d, r_d_dot),
// which allocates nothing, and checks the solver's status before using theta_dot.

#include <cmath>
#include <iostream>

#include <redres/controller.hpp>

int main(int argc, char** argv) {
  try {
    const redres::RobotModel robot = redres::load_robot(argc > 1 ? argv[1] : REDRES_EXAMPLE_ROBOT);
    const auto scheme_toml = redres::parse_toml_string(R"(
      [[objectives]]
      type = "min_velocity_norm"
      [[objectives]]
      type = "manipulability"
      schedule = "sine"
      [[constraints]]
      type = "task_tracking"
      [[constraints]]
      type = "joint_angle_margin"
      [[constraints]]
      type = "joint_velocity_limits"
    )", "<scheme>");
    const redres::Scheme scheme = redres::Scheme::from_toml(redres::TableReader::root(scheme_toml), robot);
    const auto engine = redres::make_engine("newton");
    const double T = 5.0, tau = 0.01;
    redres::Controller controller(robot, scheme, *engine, nullptr, T, tau);

    Eigen::VectorXd theta = robot.home();
    redres::KinematicsData k(robot);
    redres::compute_kinematics(robot, theta, k, redres::KinematicsLevel::kPosition);
    const Eigen::VectorXd start = k.f;
    Eigen::VectorXd r_d = start, r_d_dot = Eigen::VectorXd::Zero(robot.task_dim());
    for (int i = 0; i <= 500; ++i) {  // the control loop
      const double t = i * tau, u = t / T;
      r_d(0) = start(0) - 0.05 * (u - std::sin(2 * M_PI * u) / (2 * M_PI));
      r_d_dot(0) = -0.05 * (1 - std::cos(2 * M_PI * u)) / T;
      const redres::StepOutput out = controller.step(theta, t, r_d, r_d_dot);
      if (out.info.status != redres::SolverStatus::kSolved) {
        std::cerr << "t = " << t << ": " << redres::to_string(out.info.status) << ": " << out.info.diagnosis << "\n";
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

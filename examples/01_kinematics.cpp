// 01: load a robot from TOML and evaluate its kinematics in your own loop.
//
//   example_01_kinematics [robot.toml]
//
// Prints f(theta), w = det(JJ') and grad w along a short joint-space sweep of the paper's arm. The model is
// immutable; KinematicsData holds every buffer, so the loop allocates nothing.

#include <iomanip>
#include <iostream>

#include <redres/model/kinematics.hpp>
#include "redres/parsers/robot_toml.hpp"

int main(int argc, char** argv) {
  try {
    const std::string file = argc > 1 ? argv[1] : REDRES_EXAMPLE_ROBOT;
    const redres::RobotModel robot = redres::load_robot(file);
    redres::KinematicsData k(robot);  // sized once for this robot
    Eigen::VectorXd theta = robot.home();
    std::cout << robot.name() << ": " << robot.dof() << " joints, " << robot.task_dim() << " task rows\n";
    std::cout << std::fixed << std::setprecision(6);
    for (int step = 0; step <= 4; ++step) {
      redres::compute_kinematics(robot, theta, k);  // f, J, dJ/dtheta, w and grad w
      std::cout << "step " << step << "  f = " << k.f.transpose() << "  w = " << k.w
                << "  |grad w| = " << k.grad_w.norm() << "\n";
      // Climb the manipulability gradient a little, staying inside the joint limits.
      theta = (theta + 0.05 * k.grad_w).cwiseMax(robot.lower_limits()).cwiseMin(robot.upper_limits());
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
}

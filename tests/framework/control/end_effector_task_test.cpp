// The end-effector task (docs/tasks.md): `task_tracking` is the frame task on "end_effector" with reference "path"
// on the robot's task rows, held as a constraint. Its rows are eq. 6 (and at the acceleration level the critically
// damped error dynamics), computed here on their own from the kinematics, the path and central differences; a
// [[tasks]] frame task on the same rows writes the same QP rows, entry for entry, at both orders; and only those frame
// tasks work at the acceleration level.

#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "redres/constraints/task_tracking.hpp"
#include "redres/control/controller.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/tasks/frame_task.hpp"
#include "task_rows.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

std::unique_ptr<Task> frame_task(const RobotModel& robot, const std::string& name, const FrameTaskConfig& c,
                                 TaskMode mode = TaskMode::kEquality) {
  auto t = std::make_unique<FrameTask>(c, robot);
  t->set_name(name);
  t->set_mode(mode);
  t->check_mode();
  return t;
}

// One step of a one-level scheme at `order`; the QP's equality rows [J d].
Eigen::MatrixXd equality_rows(const RobotModel& robot, std::vector<std::unique_ptr<Constraint>> constraints,
                              std::vector<std::unique_ptr<Task>> tasks, ControlOrder order,
                              const Eigen::VectorXd& theta, const Eigen::VectorXd& v, const Eigen::VectorXd& r_d,
                              const Eigen::VectorXd& r_d_dot, const Eigen::VectorXd& r_d_ddot) {
  Scheme scheme(robot, {}, std::move(constraints), std::move(tasks), order);
  auto engine = make_engine("newton");
  Controller ctrl(robot, scheme, *engine, nullptr, 10.0, 0.01);
  StepOutput out = ctrl.make_output();
  if (order == ControlOrder::kAcceleration) {
    ctrl.step(theta, 0.0, r_d, r_d_dot, r_d_ddot, out);
    ctrl.set_applied(v);  // theta_dot at the next step
  }
  ctrl.step(theta, 0.01, r_d, r_d_dot, r_d_ddot, out);
  Eigen::MatrixXd rows(ctrl.qp().m_eq(), robot.dof() + 1);
  rows << ctrl.qp().J, ctrl.qp().d;
  return rows;
}

TEST(Tasks, TheEndEffectorTaskIsTheFrameTaskOnTheEndEffectorAndItsRowsAreEquationSix) {
  std::vector<RobotModel> robots;
  robots.push_back(load_robot(source_path("robots/paper_pushrod_6dof.toml")));                       // planar x, y
  robots.push_back(testing::robot_with_task("robots/planar_4link.toml", "\"pose\""));                // planar x, y, phi
  robots.push_back(testing::robot_with_task("robots/franka_panda.toml", "\"pose\""));                // spatial pose
  robots.push_back(testing::robot_with_task("robots/franka_panda.toml", "[\"x\", \"z\", \"wy\"]"));  // a subset
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const RobotModel& robot : robots) {
    const int n = robot.dof(), m = robot.task_dim();
    Eigen::VectorXd gain(m);
    for (int i = 0; i < m; ++i) gain(i) = 2.0 + 3.0 * (1.0 + u(rng));
    TaskTrackingConfig tracking;
    tracking.gain = PerJoint(std::vector<double>(gain.data(), gain.data() + m));
    FrameTaskConfig frame;
    frame.frame = "end_effector";
    frame.reference = "path";
    for (const std::string& row : robot.task_names()) frame.rows.push_back(row == "phi" ? "wz" : row);
    frame.gain = tracking.gain;
    for (int trial = 0; trial < 4; ++trial) {
      Eigen::VectorXd theta = robot.home();
      for (int j = 0; j < n; ++j) theta(j) += 0.3 * u(rng);
      Eigen::VectorXd v(n);
      for (int j = 0; j < n; ++j) v(j) = u(rng);
      KinematicsData k(robot);
      compute_kinematics(robot, theta, k, KinematicsLevel::kJacobian);
      const int rows = robot.reference_dim();
      Eigen::VectorXd r_d = k.f, r_d_dot(rows), r_d_ddot(rows);
      for (int r = 0; r < rows; ++r) {
        r_d(r) += 0.05 * u(rng);
        r_d_dot(r) = u(rng);
        r_d_ddot(r) = u(rng);
      }
      // e = r_d - f in the task rows; a spatial orientation's is the rotation vector of R_d R' (Eigen's AngleAxis).
      Eigen::VectorXd e(m);
      const Eigen::AngleAxisd turn(Eigen::AngleAxisd(r_d.size() == 6 ? r_d.tail<3>().norm() : 0.0,
                                                     r_d.size() == 6 && r_d.tail<3>().norm() > 0
                                                         ? Eigen::Vector3d(r_d.tail<3>().normalized())
                                                         : Eigen::Vector3d::UnitZ())
                                       .toRotationMatrix() *
                                   k.ee_pose.linear().transpose());
      for (int i = 0; i < m; ++i) {
        const int r = robot.task_rows()[static_cast<std::size_t>(i)];
        e(i) = robot.kind() == ChainKind::kSpatial && r >= 3 ? (turn.angle() * turn.axis())(r - 3) : r_d(r) - k.f(r);
      }
      Eigen::VectorXd d_velocity(m), d_acceleration(m);
      const Eigen::VectorXd jdv = testing::jdot_v(robot, theta, v), jv = k.J * v;
      for (int i = 0; i < m; ++i) {
        const int r = robot.task_rows()[static_cast<std::size_t>(i)];
        d_velocity(i) = r_d_dot(r) + gain(i) * e(i);
        d_acceleration(i) = r_d_ddot(r) - jdv(i) + 2.0 * gain(i) * (r_d_dot(r) - jv(i)) + gain(i) * gain(i) * e(i);
      }
      for (ControlOrder order : {ControlOrder::kVelocity, ControlOrder::kAcceleration}) {
        const bool acceleration = order == ControlOrder::kAcceleration;
        std::vector<std::unique_ptr<Constraint>> constraints;
        constraints.push_back(std::make_unique<TaskTracking>(tracking, robot));
        const Eigen::MatrixXd as_constraint =
            equality_rows(robot, std::move(constraints), {}, order, theta, v, r_d, r_d_dot, r_d_ddot);
        std::vector<std::unique_ptr<Task>> tasks;
        tasks.push_back(frame_task(robot, "tool", frame));
        ASSERT_TRUE(tasks.back()->supports(order)) << robot.name();
        const Eigen::MatrixXd as_task =
            equality_rows(robot, {}, std::move(tasks), order, theta, v, r_d, r_d_dot, r_d_ddot);
        EXPECT_EQ(as_constraint, as_task) << robot.name() << (acceleration ? ", acceleration" : ", velocity");
        ASSERT_EQ(as_constraint.rows(), m);
        EXPECT_LT((as_constraint.leftCols(n) - k.J).cwiseAbs().maxCoeff(), 1e-12) << robot.name();
        const Eigen::VectorXd& expected = acceleration ? d_acceleration : d_velocity;
        EXPECT_LT((as_constraint.col(n) - expected).cwiseAbs().maxCoeff(), 1e-6 * (1.0 + expected.norm()))
            << robot.name() << (acceleration ? ", acceleration" : ", velocity")
            << "\nd = " << as_constraint.col(n).transpose() << "\nexpected " << expected.transpose();
        if (acceleration) {
          EXPECT_GT(jdv.norm(), 1e-3) << robot.name();  // J_dot v is in the test
        }
      }
    }
  }
  // The same frame task on another frame, or on a row the robot does not track, is not the robot's task: it stays a
  // velocity-level task.
  const RobotModel panda = load_robot(source_path("robots/franka_panda.toml"));
  FrameTaskConfig elbow;
  elbow.frame = "panda_joint4";
  elbow.reference = "path";
  EXPECT_FALSE(frame_task(panda, "elbow", elbow)->supports(ControlOrder::kAcceleration));
  FrameTaskConfig wrist_turn;
  wrist_turn.reference = "path";
  wrist_turn.rows = {"x", "y", "z", "wz"};
  EXPECT_FALSE(frame_task(panda, "tool", wrist_turn)->supports(ControlOrder::kAcceleration));
  wrist_turn.rows = {"x", "y", "z"};
  EXPECT_TRUE(frame_task(panda, "tool", wrist_turn)->supports(ControlOrder::kAcceleration));
  wrist_turn.upper = std::vector<double>{1.0, 1.0, 1.0};
  EXPECT_FALSE(frame_task(panda, "tool", wrist_turn, TaskMode::kInequality)->supports(ControlOrder::kAcceleration));
}

}  // namespace
}  // namespace redres

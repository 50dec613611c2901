// Frames a task can name (RobotModel::frames(): every link, a URDF's links by name, the end effector) and their
// kinematics from the step's shared KinematicsData (model/frames.hpp): the pose, and the 6 x n Jacobian of a frame
// with an offset point, against central differences of the poses, on random chains with prismatic joints
// (rapidcheck) and on the maker's Panda with its hand and fingers.

#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>
#include <Eigen/Geometry>

#include "random_chain.hpp"
#include "redres/model/frames.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

// The largest difference between J's columns and central differences of the frame's point and orientation.
double jacobian_error(const RobotModel& robot, const Eigen::VectorXd& theta, int frame, const Eigen::Vector3d& point) {
  const int n = robot.dof();
  KinematicsData k(robot);
  compute_kinematics(robot, theta, k, KinematicsLevel::kJacobian);
  Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, n);
  frame_jacobian(robot, k, frame, point, J);
  double worst = 0.0;
  const double h = 1e-6;
  for (int c = 0; c < n; ++c) {
    Eigen::VectorXd plus = theta, minus = theta;
    plus(c) += h;
    minus(c) -= h;
    compute_kinematics(robot, plus, k, KinematicsLevel::kPosition);
    const Eigen::Isometry3d a = frame_pose(robot, k, frame);
    compute_kinematics(robot, minus, k, KinematicsLevel::kPosition);
    const Eigen::Isometry3d b = frame_pose(robot, k, frame);
    const Eigen::Vector3d v = (a * point - b * point) / (2 * h);
    const Eigen::AngleAxisd turn(a.linear() * b.linear().transpose());
    const Eigen::Vector3d w = turn.angle() * turn.axis() / (2 * h);
    worst = std::max({worst, (v - J.col(c).head<3>()).norm(), (w - J.col(c).tail<3>()).norm()});
  }
  return worst;
}

RC_GTEST_PROP(Frames, EveryFramesJacobianIsTheDerivativeOfItsPose, ()) {
  const bool planar = *rc::gen::arbitrary<bool>();
  const int n = *rc::gen::inRange(2, 8);
  const RobotModel robot(planar ? testing::random_planar(n, TaskRows::kPosition)
                                : testing::random_spatial(n, TaskRows::kPosition));
  const Eigen::VectorXd theta = testing::random_theta(robot);
  const int frame = *rc::gen::inRange(0, static_cast<int>(robot.frames().size()));
  const Eigen::Vector3d point(testing::draw(-0.2, 0.2), testing::draw(-0.2, 0.2), testing::draw(-0.2, 0.2));
  RC_ASSERT(jacobian_error(robot, theta, frame, point) < 1e-6);
}

TEST(Frames, EachJointsLinkAndTheEndEffectorAreNamed) {
  const RobotModel robot = load_robot(source_path("robots/kuka_iiwa14.toml"));
  ASSERT_EQ(robot.frames().size(), static_cast<std::size_t>(robot.dof() + 1));
  for (int j = 0; j < robot.dof(); ++j) {
    const int f = robot.find_frame(robot.joint(j).name);
    ASSERT_GE(f, 0) << robot.joint(j).name;
    EXPECT_EQ(robot.frames()[static_cast<std::size_t>(f)].joint, j);
  }
  EXPECT_EQ(robot.find_frame("no such frame"), -1);
  // The end effector's frame is the kinematics' end-effector pose.
  KinematicsData k(robot);
  const Eigen::VectorXd theta = Eigen::VectorXd::LinSpaced(robot.dof(), 0.1, 0.7);
  compute_kinematics(robot, theta, k, KinematicsLevel::kJacobian);
  const int ee = robot.find_frame("end_effector");
  ASSERT_GE(ee, 0);
  EXPECT_LT((frame_pose(robot, k, ee).matrix() - k.ee_pose.matrix()).norm(), 1e-12);
  // Its Jacobian's position rows are the task's J.
  Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, robot.dof());
  frame_jacobian(robot, k, ee, Eigen::Vector3d::Zero(), J);
  EXPECT_LT((J.topRows(3) - k.J.topRows(3)).norm(), 1e-12);
}

TEST(Frames, TheMakersPandaNamesItsUrdfLinksHandAndFingersIncluded) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda_meshes.toml"));
  for (const char* name : {"panda_link1", "panda_link4", "panda_link7", "panda_link8", "panda_hand", "panda_leftfinger",
                           "panda_rightfinger", "end_effector"}) {
    EXPECT_GE(robot.find_frame(name), 0) << name;
  }
  const Eigen::VectorXd theta = (Eigen::VectorXd(7) << 0.1, -0.6, 0.2, -2.2, 0.3, 1.7, 0.6).finished();
  for (const char* name : {"panda_link4", "panda_hand", "panda_leftfinger", "end_effector"}) {
    const int f = robot.find_frame(name);
    EXPECT_LT(jacobian_error(robot, theta, f, Eigen::Vector3d(0.02, -0.03, 0.05)), 1e-6) << name;
  }
  // The hand is fixed to link 8, 0.107 m along link 7's z, turned by -pi/4 (the maker's URDF).
  KinematicsData k(robot);
  compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
  const Eigen::Isometry3d link7 = frame_pose(robot, k, robot.find_frame("panda_link7"));
  const Eigen::Isometry3d hand = frame_pose(robot, k, robot.find_frame("panda_hand"));
  const Eigen::Isometry3d rel = link7.inverse() * hand;
  EXPECT_NEAR(rel.translation().z(), 0.107, 1e-9);
  EXPECT_NEAR(rel.translation().head<2>().norm(), 0.0, 1e-9);
  EXPECT_NEAR(std::atan2(rel.linear()(1, 0), rel.linear()(0, 0)), -M_PI / 4, 1e-9);
}

}  // namespace
}  // namespace redres

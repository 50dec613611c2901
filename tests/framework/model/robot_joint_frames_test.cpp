// Joint frames (`convention = "joints"`: an origin and an axis per joint, as in URDF) and base poses. The Panda
// written with the joint origins of Franka's URDF (tests/data/franka_panda_joints.toml) and the shipped modified-DH
// Panda are one arm: f, J and w agree at 1000 random configurations. A base pose moves and turns everything it
// carries: f, J and the collision shapes' world poses, and nothing else (w is unchanged).

#include <random>

#include <gtest/gtest.h>

#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

TEST(JointFrameChains, ThePandaFromItsUrdfOriginsIsThePandaFromItsDhTable) {
  const RobotModel dh = load_robot(source_path("robots/franka_panda.toml"));
  const RobotModel frames = load_robot(data_path("franka_panda_joints.toml"));
  ASSERT_EQ(frames.convention(), DhConvention::kJointFrames);
  ASSERT_EQ(frames.dof(), dh.dof());
  KinematicsData a(dh), b(frames);
  std::mt19937 rng(7);
  double worst_f = 0.0, worst_j = 0.0, worst_w = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const Eigen::VectorXd theta = random_inside(dh, rng);
    compute_kinematics(dh, theta, a, KinematicsLevel::kManipulability);
    compute_kinematics(frames, theta, b, KinematicsLevel::kManipulability);
    worst_f = std::max(worst_f, (a.f - b.f).cwiseAbs().maxCoeff());
    worst_j = std::max(worst_j, (a.J - b.J).cwiseAbs().maxCoeff());
    worst_w = std::max(worst_w, std::abs(a.w - b.w) / (1e-12 + a.w));
  }
  RecordProperty("max_f_difference", std::to_string(worst_f));
  RecordProperty("max_J_difference", std::to_string(worst_j));
  EXPECT_LE(worst_f, 1e-12);
  EXPECT_LE(worst_j, 1e-12);
  EXPECT_LE(worst_w, 1e-10);
}

TEST(JointFrameChains, ABasePoseMovesAndTurnsTheTaskAndTheShapes) {
  const RobotModel plain = load_robot(source_path("robots/kuka_iiwa14.toml"));
  RobotSpec spec = plain.spec();
  Eigen::Isometry3d P = Eigen::Isometry3d::Identity();
  P.translate(Eigen::Vector3d(0.3, -0.2, 0.75));
  P.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()));
  spec.base = P;
  const RobotModel moved(spec);
  KinematicsData a(plain), b(moved);
  std::mt19937 rng(8);
  for (int k = 0; k < 100; ++k) {
    const Eigen::VectorXd theta = random_inside(plain, rng);
    compute_kinematics(plain, theta, a, KinematicsLevel::kManipulability);
    compute_kinematics(moved, theta, b, KinematicsLevel::kManipulability);
    EXPECT_LE((b.ee_pose.matrix() - (P * a.ee_pose).matrix()).cwiseAbs().maxCoeff(), 1e-12);
    // Position rows turn with the base, and so do the angular rows of the pose task.
    EXPECT_LE((b.J.topRows(3) - P.linear() * a.J.topRows(3)).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LE((b.J.bottomRows(3) - P.linear() * a.J.bottomRows(3)).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_NEAR(b.w, a.w, 1e-12 * (1.0 + a.w));  // det(JJ') is invariant under a rotation of the rows' frame
    for (int j = 0; j < plain.dof(); ++j) {
      EXPECT_LE((b.link_frames[static_cast<std::size_t>(j)].matrix() -
                 (P * a.link_frames[static_cast<std::size_t>(j)]).matrix())
                    .cwiseAbs()
                    .maxCoeff(),
                1e-12);
    }
  }
}

TEST(JointFrameChains, ABaseFromTheRobotFileIsRead) {
  const auto file = parse_toml_string(R"(
name = "based"
kind = "planar"
[base]
xyz = [0.5, -0.25]
angle = 0.3
[[joints]]
name = "j1"
length = 0.4
limits = [-1.0, 1.0]
velocity_limit = { type = "constant", lower = -1.0, upper = 1.0 }
)",
                                      "<test>");
  const RobotModel robot = load_robot(TableReader::root(file, "robot"));
  KinematicsData k(robot);
  compute_kinematics(robot, Eigen::VectorXd::Constant(1, 0.2), k, KinematicsLevel::kPosition);
  EXPECT_NEAR(k.f(0), 0.5 + 0.4 * std::cos(0.5), 1e-15);
  EXPECT_NEAR(k.f(1), -0.25 + 0.4 * std::sin(0.5), 1e-15);
  EXPECT_NEAR(robot.base_angle(), 0.3, 1e-15);
}

}  // namespace
}  // namespace redres

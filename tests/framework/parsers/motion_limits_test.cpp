// Motion limits in the robot file (issue 25): acceleration and jerk laws and the effort limit per joint, read from
// TOML chains and as overrides of URDF joints (effort from the URDF's <limit effort>); the shipped Panda carries
// Franka's published figures in both of its files; a robot without them reads as unbounded.

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>

#include "redres/parsers/robot_toml.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

constexpr std::array<double, 7> kAcceleration = {15, 7.5, 10, 12.5, 15, 20, 20};       // rad/s^2
constexpr std::array<double, 7> kJerk = {7500, 3750, 5000, 6250, 7500, 10000, 10000};  // rad/s^3
constexpr std::array<double, 7> kEffort = {87, 87, 87, 87, 12, 12, 12};                // N m

TEST(MotionLimits, ThePandaCarriesFrankasPublishedFiguresInBothFiles) {
  for (const char* file : {"robots/franka_panda.toml", "robots/franka_panda_urdf.toml"}) {
    SCOPED_TRACE(file);
    const RobotModel robot = load_robot(source_path(file));
    ASSERT_EQ(robot.dof(), 7);
    EXPECT_TRUE(robot.has_acceleration_limits());
    EXPECT_TRUE(robot.has_jerk_limits());
    Eigen::VectorXd lo(7), hi(7), jlo(7), jhi(7);
    // Anywhere in the range: the figures are constants.
    const Eigen::VectorXd theta = robot.home() + Eigen::VectorXd::Constant(7, 0.1);
    robot.acceleration_limits(theta, lo, hi);
    robot.jerk_limits(theta, jlo, jhi);
    for (int j = 0; j < 7; ++j) {
      const auto k = static_cast<std::size_t>(j);
      EXPECT_EQ(hi(j), kAcceleration[k]) << "joint " << j + 1;
      EXPECT_EQ(lo(j), -kAcceleration[k]) << "joint " << j + 1;
      EXPECT_EQ(jhi(j), kJerk[k]) << "joint " << j + 1;
      EXPECT_EQ(jlo(j), -kJerk[k]) << "joint " << j + 1;
      ASSERT_TRUE(robot.joint(j).effort_limit.has_value()) << "joint " << j + 1;
      EXPECT_EQ(*robot.joint(j).effort_limit, kEffort[k]) << "joint " << j + 1;
      EXPECT_NE(robot.joint(j).acceleration_limit_source.find(file), std::string::npos)
          << robot.joint(j).acceleration_limit_source;
    }
  }
}

TEST(MotionLimits, ARobotWithoutThemIsUnbounded) {
  const RobotModel robot = load_robot(source_path("robots/planar_4link.toml"));
  EXPECT_FALSE(robot.has_acceleration_limits());
  EXPECT_FALSE(robot.has_jerk_limits());
  const int n = robot.dof();
  Eigen::VectorXd lo(n), hi(n);
  robot.acceleration_limits(robot.home(), lo, hi);
  for (int j = 0; j < n; ++j) {
    EXPECT_EQ(lo(j), -std::numeric_limits<double>::infinity());
    EXPECT_EQ(hi(j), std::numeric_limits<double>::infinity());
    EXPECT_FALSE(robot.joint(j).effort_limit.has_value());
  }
  EXPECT_THROW(robot.acceleration_limits(Eigen::VectorXd::Zero(n + 1), lo, hi), std::invalid_argument);
}

TEST(MotionLimits, LawsOtherThanConstantsWork) {
  // An acceleration limit that follows the position, as a push-rod joint's velocity limit does.
  const auto dir = scratch_dir("motion_limits_law");
  std::ofstream(dir / "robot.toml") << R"toml(name = "two"
kind = "planar"
[[joints]]
name = "j1"
length = 0.3
limits = [-1.0, 1.0]
velocity_limit = { type = "constant", lower = -1.0, upper = 1.0 }
acceleration_limit = { type = "expression", lower = "-(2 + theta)", upper = "2 + theta" }
jerk_limit = { type = "constant", lower = -100.0, upper = 50.0 }
[[joints]]
name = "j2"
length = 0.2
limits = [-1.0, 1.0]
velocity_limit = { type = "constant", lower = -1.0, upper = 1.0 }
acceleration_limit = { type = "constant", lower = -3.0, upper = 3.0 }
jerk_limit = { type = "constant", lower = -200.0, upper = 200.0 }
)toml";
  const RobotModel robot = load_robot(dir / "robot.toml");
  EXPECT_TRUE(robot.has_acceleration_limits());
  Eigen::VectorXd lo(2), hi(2);
  robot.acceleration_limits(Eigen::Vector2d(0.5, 0.0), lo, hi);
  EXPECT_DOUBLE_EQ(hi(0), 2.5);
  EXPECT_DOUBLE_EQ(lo(0), -2.5);
  EXPECT_EQ(hi(1), 3.0);
  robot.jerk_limits(Eigen::Vector2d(0.0, 0.0), lo, hi);
  EXPECT_EQ(lo(0), -100.0);
  EXPECT_EQ(hi(0), 50.0);
}

TEST(MotionLimits, LimitsOnSomeJointsOnlyAreRefusedNamingTheJointsWithout) {
  // Issue 43: a robot whose joints give acceleration limits to 6 of 7 joints ran with none enforced, silently.
  const auto dir = scratch_dir("motion_limits_partial");
  for (const char* key : {"acceleration_limit", "jerk_limit"}) {
    SCOPED_TRACE(key);
    const std::string joint_keys =
        "limits = [-1.0, 1.0]\nvelocity_limit = { type = \"constant\", lower = -1.0, upper = 1.0 }\n";
    std::ofstream(dir / "robot.toml") << "name = \"three\"\nkind = \"planar\"\n"
                                      << "[[joints]]\nname = \"j1\"\nlength = 0.3\n"
                                      << joint_keys << key << " = { type = \"constant\", lower = -3.0, upper = 3.0 }\n"
                                      << "[[joints]]\nname = \"j2\"\nlength = 0.2\n"
                                      << joint_keys << "[[joints]]\nname = \"j3\"\nlength = 0.1\n"
                                      << joint_keys;
    try {
      (void)load_robot(dir / "robot.toml");
      ADD_FAILURE() << "a robot with limits on one joint of three was loaded";
    } catch (const std::exception& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("robot.toml:3:1"), std::string::npos) << what;  // the first [[joints]] entry
      EXPECT_NE(what.find("key 'joints'"), std::string::npos) << what;
      EXPECT_NE(what.find(std::string(key) + " on every joint or on none"), std::string::npos) << what;
      EXPECT_NE(what.find("1 of 3 joints have one, and 'j2', 'j3' not"), std::string::npos) << what;
    }
  }
}

}  // namespace
}  // namespace redres

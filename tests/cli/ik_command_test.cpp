// `redres robot --ik` and theta0 = { ik = ... } from the command line (run/ik.hpp): the answer reaches the target
// (checked by the forward kinematics of the printed joint values), the JSON says the same, a target that cannot be
// reached is exit code 2 with the diagnosis, and `validate` prints what the IK found.

#include <array>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <Eigen/Geometry>

#include "cli_util.hpp"
#include "redres/model/collision.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"

namespace redres {
namespace {

Eigen::VectorXd theta_of(const nlohmann::json& j) {
  Eigen::VectorXd t(static_cast<Eigen::Index>(j.size()));
  for (std::size_t i = 0; i < j.size(); ++i) t(static_cast<Eigen::Index>(i)) = j[i].get<double>();
  return t;
}

TEST(IkCommand, TheJsonAnswerReachesTheSpatialPose) {
  const Cli r = redres("robot robots/franka_panda.toml --ik 0.45,-0.1,0.35,pi,0.3,0.2 --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["converged"].get<bool>());
  EXPECT_EQ(j["failure"], "none");
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  const Eigen::VectorXd theta = theta_of(j["theta"]);
  ASSERT_EQ(theta.size(), robot.dof());
  KinematicsData k(robot);
  compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
  EXPECT_LE((k.ee_pose.translation() - Eigen::Vector3d(0.45, -0.1, 0.35)).norm(), 1e-9);
  EXPECT_LE(Eigen::AngleAxisd(k.ee_pose.linear() * rpy_matrix({M_PI, 0.3, 0.2}).transpose()).angle(), 1e-9);
  EXPECT_LE(j["position_error"].get<double>(), 1e-9);
  EXPECT_LE(j["orientation_error"].get<double>(), 1e-9);
  EXPECT_GE(j["iterations"].get<int>(), 1);
  for (int q = 0; q < robot.dof(); ++q) {
    EXPECT_GE(theta(q), robot.lower_limits()(q));
    EXPECT_LE(theta(q), robot.upper_limits()(q));
  }
  // The robot has collision shapes: the answer's nearest self-collision pair is apart.
  ASSERT_TRUE(j["min_self_collision_distance"].is_number()) << r.out;
  EXPECT_GT(j["min_self_collision_distance"].get<double>(), 0.0);
  // The pair is named by its links: on a URDF robot, the URDF's link names (a side-branch finger among them).
  const Cli urdf = redres("robot robots/franka_panda_meshes.toml --ik 0.45,-0.1,0.35,pi,0.3,0.2 --json");
  ASSERT_EQ(urdf.code, 0) << urdf.out;
  const nlohmann::json u = nlohmann::json::parse(urdf.out);
  ASSERT_EQ(u["nearest_self_collision_pair"].size(), 2u) << urdf.out;
  for (const auto& name : u["nearest_self_collision_pair"]) {
    const RobotModel meshes = load_robot(source_path("robots/franka_panda_meshes.toml"));
    EXPECT_GE(meshes.find_body(name.get<std::string>()), 0) << name;
    EXPECT_EQ(name.get<std::string>().rfind("panda_joint", 0), std::string::npos) << name;
  }
  // The same answer as text.
  const Cli text = redres("robot robots/franka_panda.toml --ik 0.45,-0.1,0.35,pi,0.3,0.2");
  ASSERT_EQ(text.code, 0) << text.out;
  for (const char* part : {"converged in", "theta   [", "position error", "nearest self-collision pair"}) {
    EXPECT_NE(text.out.find(part), std::string::npos) << part << " in\n" << text.out;
  }
}

TEST(IkCommand, APlanarRobotTakesXYAndPhiAndASeed) {
  const Cli r = redres("robot robots/paper_pushrod_6dof.toml --ik 0.5,1.05,2.0 --seed zeros --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const RobotModel robot = load_robot(source_path("robots/paper_pushrod_6dof.toml"));
  KinematicsData k(robot);
  compute_kinematics(robot, theta_of(j["theta"]), k, KinematicsLevel::kPosition);
  EXPECT_LE((k.ee_pose.translation().head<2>() - Eigen::Vector2d(0.5, 1.05)).norm(), 1e-9);
  EXPECT_NEAR(std::remainder(std::atan2(k.ee_pose.linear()(1, 0), k.ee_pose.linear()(0, 0)) - 2.0, 2 * M_PI), 0.0,
              1e-9);
  // zeros are clamped into the limits (joints 2 to 6 have positive lower limits).
  EXPECT_DOUBLE_EQ(j["seed"][1].get<double>(), robot.lower_limits()(1));
  // A seed of joint values.
  const Cli given = redres("robot robots/paper_pushrod_6dof.toml --ik 0.45,1.1 --seed 0.5,0.3,0.3,0.3,0.1,0.1");
  EXPECT_EQ(given.code, 0) << given.out;
}

TEST(IkCommand, AnUnreachableTargetIsExitCode2WithTheDiagnosis) {
  const Cli far = redres("robot robots/xarm6.toml --ik 3,0,0.5");
  EXPECT_EQ(far.code, 2) << far.out;
  EXPECT_NE(far.out.find("unreachable"), std::string::npos) << far.out;
  EXPECT_NE(far.out.find("from the target"), std::string::npos) << far.out;
  const Cli json = redres("robot robots/xarm6.toml --ik 3,0,0.5 --json");
  EXPECT_EQ(json.code, 2);
  const nlohmann::json j = nlohmann::json::parse(json.out.substr(0, json.out.rfind('}') + 1));
  EXPECT_FALSE(j["converged"].get<bool>());
  EXPECT_EQ(j["failure"], "unreachable");
  EXPECT_GT(j["position_error"].get<double>(), 1.0);
}

TEST(IkCommand, BadOptionsAreExitCode2) {
  const Cli count = redres("robot robots/franka_panda.toml --ik 0.4,0.1");
  EXPECT_EQ(count.code, 2);
  EXPECT_NE(count.out.find("x,y,z or x,y,z,roll,pitch,yaw"), std::string::npos) << count.out;
  const Cli word = redres("robot robots/franka_panda.toml --ik 0.4,zz,0.4");
  EXPECT_EQ(word.code, 2);
  EXPECT_NE(word.out.find("--ik"), std::string::npos) << word.out;
  const Cli seed = redres("robot robots/franka_panda.toml --ik 0.4,0.1,0.4 --seed 1,2");
  EXPECT_EQ(seed.code, 2);
  EXPECT_NE(seed.out.find("--seed: expected 7"), std::string::npos) << seed.out;
  const Cli both = redres("robot robots/franka_panda.toml --ik 0.4,0.1,0.4 --theta 0,0,0,-1,0,1,0");
  EXPECT_EQ(both.code, 2);
  const Cli alone = redres("robot robots/franka_panda.toml --seed home");
  EXPECT_EQ(alone.code, 2);
  EXPECT_NE(alone.out.find("--seed is for --ik"), std::string::npos) << alone.out;
}

TEST(IkCommand, ValidatePrintsWhatTheIkFound) {
  const Cli r = redres("validate configs/panda_ik_start.toml");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("theta0 by inverse kinematics to the path's start"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("converged in"), std::string::npos) << r.out;
  // A target out of reach is exit code 2, at theta0's line, with the diagnosis.
  const Cli far = redres("validate configs/panda_ik_start.toml --set path.origin=[2.5,0,0.5]");
  EXPECT_EQ(far.code, 2) << far.out;
  EXPECT_NE(far.out.find("key 'theta0'"), std::string::npos) << far.out;
  EXPECT_NE(far.out.find("did not converge (unreachable)"), std::string::npos) << far.out;
  // compare prints it too, after the scenario's file.
  const std::string out = ::testing::TempDir() + "redres_ik_compare";
  std::filesystem::remove_all(out);
  const Cli cmp = redres("compare configs/panda_ik_start.toml --no-plots --out " + out);
  EXPECT_EQ(cmp.code, 0) << cmp.out;
  EXPECT_NE(cmp.out.find("configs/panda_ik_start.toml: theta0 by inverse kinematics to the path's start"),
            std::string::npos)
      << cmp.out;
  std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace redres

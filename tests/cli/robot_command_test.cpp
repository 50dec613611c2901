// `redres robot` (issue 26): a bare URDF read as it comes, and what every robot prints: poses, link frames, inertias,
// collision shapes and the self-collision distances at theta, the JSON with the same.

#include <string>

#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_util.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"

namespace redres {
namespace {

TEST(RobotCommand, ABareUrdfPrintsItsFramesShapesAndInertias) {
  const Cli r = redres("robot robots/franka_panda_description/panda.urdf");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* part :
       {"end effector  xyz", "link frames", "collision shapes (10)", "mass (kg)", "self-collision pairs at theta",
        "panda_joint7", "visual elements (11, 11 meshes; drawn by redres view)"}) {
    EXPECT_NE(r.out.find(part), std::string::npos) << part << " in\n" << r.out;
  }
  const Cli tip = redres("robot robots/franka_panda_description/panda.urdf --tip-link no_such_link");
  EXPECT_EQ(tip.code, 2) << tip.out;
  EXPECT_NE(tip.out.find("no_such_link"), std::string::npos) << tip.out;
  const Cli toml = redres("robot robots/franka_panda.toml --tip-link x");
  EXPECT_EQ(toml.code, 2) << toml.out;
}

TEST(RobotCommand, TheJsonGivesPosesAndTheSelfDistancesNearestFirst) {
  const Cli r = redres("robot robots/franka_panda_meshes.toml --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["link_frames"].size(), 7u);
  ASSERT_EQ(j["inertias"].size(), 7u);
  EXPECT_DOUBLE_EQ(j["inertias"][0]["mass"].get<double>(), 2.7);
  const auto& pairs = j["self_collision_distances"];
  ASSERT_GT(pairs.size(), 5u);
  for (std::size_t k = 1; k < pairs.size(); ++k) {
    EXPECT_LE(pairs[k - 1]["distance"].get<double>(), pairs[k]["distance"].get<double>());
  }
  // Shapes and pairs name their URDF links; the fingers are a side branch, their joints held (the second follows the
  // first).
  bool finger = false;
  for (const auto& shape : j["collision_shapes"]) {
    if (shape["link"] == "panda_leftfinger") {
      finger = true;
      EXPECT_TRUE(shape["side_branch"].get<bool>());
      EXPECT_EQ(shape["joint_name"], "panda_joint7");
    }
    if (shape["link"] == "panda_hand") {
      EXPECT_FALSE(shape["side_branch"].get<bool>());
    }
    // Every shape: its kind, pose (xyz, rpy in the link frame) and the mesh it was fitted to.
    EXPECT_EQ(shape["kind"], "capsule");
    EXPECT_EQ(shape["rpy"].size(), 3u);
    EXPECT_NE(shape["source_mesh"].get<std::string>().find(".obj"), std::string::npos) << shape;
  }
  EXPECT_TRUE(finger);
  // The visual elements: the base's link0 and the others on their joints, each mesh found (an absolute path).
  ASSERT_EQ(j["visuals"].size(), 11u);
  EXPECT_EQ(j["visuals"][0]["link"], "panda_link0");
  EXPECT_EQ(j["visuals"][0]["joint"], 0);
  for (const auto& v : j["visuals"]) {
    EXPECT_FALSE(v.contains("problem")) << v;
    EXPECT_TRUE(std::filesystem::path(v["file"].get<std::string>()).is_absolute()) << v;
  }
  ASSERT_EQ(j["held_joints"].size(), 2u);
  bool finger_pair = false;
  for (const auto& p : pairs) {
    if (p["links"][1] == "panda_leftfinger" && p["links"][0] == "panda_link6") finger_pair = true;
  }
  EXPECT_TRUE(finger_pair) << "a side-branch finger is checked against the neighbouring link 6";
  // The end-effector pose is the kinematics' at home.
  const RobotModel robot = load_robot(source_path("robots/franka_panda_meshes.toml"));
  KinematicsData k(robot);
  compute_kinematics(robot, robot.home(), k, KinematicsLevel::kPosition);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(j["end_effector_pose"]["xyz"][a].get<double>(), k.ee_pose.translation()(a), 1e-12);
  }
  // The frames a task can name: every link by its URDF name (the hand and fingers too) and the end effector, each at
  // its pose; the end effector's is the end-effector pose.
  ASSERT_EQ(j["frames"].size(), robot.frames().size());
  bool hand = false, end_effector = false;
  for (const auto& f : j["frames"]) {
    if (f["name"] == "panda_hand") hand = true;
    if (f["name"] == "end_effector") {
      end_effector = true;
      for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(f["position"][a].get<double>(), k.ee_pose.translation()(a), 1e-12);
      }
    }
  }
  EXPECT_TRUE(hand);
  EXPECT_TRUE(end_effector);
  const Cli text = redres("robot robots/franka_panda_meshes.toml");
  EXPECT_NE(text.out.find("frames a task can name"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("panda_leftfinger"), std::string::npos);
}

}  // namespace
}  // namespace redres

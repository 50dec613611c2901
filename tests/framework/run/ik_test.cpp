// Inverse kinematics for the start (run/ik.hpp, docs/ik.md): round trips on the shipped robots (a random
// configuration's pose, reached from another seed, checked by the forward kinematics of the answer), the failures
// and their diagnoses (out of reach, a joint at its limit, a target inside an obstacle), and the scenario keys
// theta0 = { ik = ... } with good and bad input.

#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "random_chain.hpp"
#include "redres/common/error.hpp"
#include "redres/config/toml_reader.hpp"
#include "redres/control/plugin.hpp"
#include "redres/model/collision.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/run/ik.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/start_check.hpp"
#include "scenario_text.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

// The end effector's pose at theta, from the kinematics of the robot as loaded (not the IK's copy).
Eigen::Isometry3d pose_at(const RobotModel& robot, const Eigen::VectorXd& theta) {
  KinematicsData k(robot);
  compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
  return k.ee_pose;
}

double angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle();
}

void expect_within_limits(const RobotModel& robot, const Eigen::VectorXd& theta, double margin = 0.0) {
  ASSERT_EQ(theta.size(), robot.dof());
  for (int j = 0; j < robot.dof(); ++j) {
    EXPECT_GE(theta(j), robot.lower_limits()(j) + margin - 1e-12) << "joint " << j + 1;
    EXPECT_LE(theta(j), robot.upper_limits()(j) - margin + 1e-12) << "joint " << j + 1;
  }
}

// The smallest distance between any link shape of `robot` at theta and the shape `obstacle` (world pose in its spec).
double distance_to(const RobotModel& robot, const Eigen::VectorXd& theta, const ShapeSpec& obstacle) {
  KinematicsData k(robot);
  compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
  std::vector<ShapeSpec> shapes;
  for (const auto& s : robot.link_shapes()) shapes.push_back(s.spec);
  shapes.push_back(obstacle);
  const DistanceQuery query(shapes);
  double nearest = std::numeric_limits<double>::infinity();
  const int o = static_cast<int>(shapes.size()) - 1;
  for (int l = 0; l < o; ++l) {
    const auto& ls = robot.link_shapes()[static_cast<std::size_t>(l)];
    const ShapeDistance d =
        query.distance(l, k.link_frames[static_cast<std::size_t>(ls.link)] * ls.pose, o, obstacle.pose());
    EXPECT_TRUE(d.ok) << d.error;
    nearest = std::min(nearest, d.distance);
  }
  return nearest;
}

struct RoundTrip {
  const char* robot;
  int trials;
};

class IkRoundTrip : public ::testing::TestWithParam<RoundTrip> {};

// A random configuration within the limits gives a pose; the IK from the robot's home reaches it (position and
// orientation) to 1e-9, within the limits, as the forward kinematics of its answer shows.
TEST_P(IkRoundTrip, ReachesTheFullPoseOfARandomConfigurationFromHome) {
  const RobotModel robot = load_robot(source_path(GetParam().robot));
  const bool planar = robot.kind() == ChainKind::kPlanar;
  std::mt19937 rng(1206);
  IkOptions options;
  options.self_collision = false;  // a random configuration may touch itself; the round trip is about the pose
  double worst_p = 0.0, worst_r = 0.0, seconds = 0.0;
  int iterations = 0, max_iterations = 0, restarted = 0;
  for (int trial = 0; trial < GetParam().trials; ++trial) {
    const Eigen::VectorXd q = random_inside(robot, rng, 0.02);
    const Eigen::Isometry3d goal = pose_at(robot, q);
    IkTarget target;
    if (planar) {
      const double phi = std::atan2(goal.linear()(1, 0), goal.linear()(0, 0));
      target = IkTarget::planar(goal.translation().x(), goal.translation().y(), phi);
    } else {
      const std::array<double, 3> rpy = rpy_of(goal.linear());
      target = IkTarget::spatial(goal.translation(), Eigen::Vector3d(rpy[0], rpy[1], rpy[2]));
    }
    const IkResult r = solve_ik(robot, target, robot.home(), {}, options);
    ASSERT_TRUE(r.converged) << GetParam().robot << " trial " << trial << ": " << r.summary();
    EXPECT_EQ(r.failure, IkFailure::kNone);
    EXPECT_TRUE(r.diagnosis.empty());
    expect_within_limits(robot, r.theta);
    const Eigen::Isometry3d got = pose_at(robot, r.theta);
    const double dp = (got.translation() - goal.translation()).norm();
    const double dr = angle_between(got.linear(), goal.linear());
    EXPECT_LE(dp, 1e-9) << "trial " << trial;
    EXPECT_LE(dr, 1e-9) << "trial " << trial;
    // What it reports is what the answer does.
    EXPECT_NEAR(r.position_error, dp, 1e-12);
    EXPECT_NEAR(r.orientation_error, dr, 1e-9);
    EXPECT_LT((r.pose.translation() - got.translation()).norm(), 1e-12);
    worst_p = std::max(worst_p, dp);
    worst_r = std::max(worst_r, dr);
    iterations += r.iterations;
    max_iterations = std::max(max_iterations, r.iterations);
    restarted += r.seeds > 1 ? 1 : 0;
    seconds += r.seconds;
  }
  std::cout << "[ik] " << GetParam().robot << ": " << GetParam().trials << " poses, max position error " << worst_p
            << " m, max orientation error " << worst_r << " rad, mean iterations "
            << static_cast<double>(iterations) / GetParam().trials << " (max " << max_iterations << "), " << restarted
            << " needed another seed, mean " << 1e3 * seconds / GetParam().trials << " ms\n";
}

INSTANTIATE_TEST_SUITE_P(Robots, IkRoundTrip,
                         ::testing::Values(RoundTrip{"robots/paper_pushrod_6dof.toml", 20},
                                           RoundTrip{"robots/franka_panda.toml", 20},
                                           RoundTrip{"robots/franka_panda_meshes.toml", 10},
                                           RoundTrip{"robots/xarm6.toml", 20},
                                           RoundTrip{"robots/kuka_iiwa14.toml", 10}),
                         [](const ::testing::TestParamInfo<RoundTrip>& robot) {
                           std::string name = std::filesystem::path(robot.param.robot).stem().string();
                           for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

// The smallest distance between two links of `robot` at theta that may collide (RobotModel::self_collision_pair).
double self_distance(const RobotModel& robot, const Eigen::VectorXd& theta) {
  KinematicsData k(robot);
  compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
  std::vector<ShapeSpec> shapes;
  for (const auto& s : robot.link_shapes()) shapes.push_back(s.spec);
  const DistanceQuery query(shapes);
  double nearest = std::numeric_limits<double>::infinity();
  const auto& ls = robot.link_shapes();
  for (std::size_t a = 0; a < ls.size(); ++a) {
    for (std::size_t b = a + 1; b < ls.size(); ++b) {
      if (!robot.self_collision_pair(std::min(ls[a].link, ls[b].link), std::max(ls[a].link, ls[b].link))) continue;
      const ShapeDistance d =
          query.distance(static_cast<int>(a), k.link_frames[static_cast<std::size_t>(ls[a].link)] * ls[a].pose,
                         static_cast<int>(b), k.link_frames[static_cast<std::size_t>(ls[b].link)] * ls[b].pose);
      EXPECT_TRUE(d.ok) << d.error;
      nearest = std::min(nearest, d.distance);
    }
  }
  return nearest;
}

// With the robot's self-collision rows on (the default), the full pose of configurations whose links are 2 cm apart
// or more is reached, and the answer's links are apart too.
TEST(Ik, SpatialRoundTripsKeepTheLinksApart) {
  for (const char* file : {"robots/franka_panda.toml", "robots/xarm6.toml"}) {
    SCOPED_TRACE(file);
    const RobotModel robot = load_robot(source_path(file));
    std::mt19937 rng(26);
    int reached = 0;
    for (int trial = 0; trial < 40 && reached < 8; ++trial) {
      const Eigen::VectorXd q = random_inside(robot, rng, 0.05);
      if (self_distance(robot, q) < 0.02) continue;
      const Eigen::Isometry3d goal = pose_at(robot, q);
      const std::array<double, 3> rpy = rpy_of(goal.linear());
      const IkResult r =
          solve_ik(robot, IkTarget::spatial(goal.translation(), Eigen::Vector3d(rpy[0], rpy[1], rpy[2])), robot.home());
      ASSERT_TRUE(r.converged) << r.summary();
      const Eigen::Isometry3d got = pose_at(robot, r.theta);
      EXPECT_LE((got.translation() - goal.translation()).norm(), 1e-9);
      EXPECT_LE(angle_between(got.linear(), goal.linear()), 1e-9);
      EXPECT_GT(self_distance(robot, r.theta), 0.0);
      expect_within_limits(robot, r.theta);
      ++reached;
    }
    EXPECT_EQ(reached, 8);
  }
}

// A position target leaves the orientation free: the planar arm reaches (x, y) of a random configuration from zeros
// clamped into its limits, with its self-collision rows (the default) on.
TEST(Ik, PlanarPositionOnlyFromAnotherSeed) {
  const RobotModel robot = load_robot(source_path("robots/paper_pushrod_6dof.toml"));
  std::mt19937 rng(7);
  const Eigen::VectorXd seed =
      Eigen::VectorXd::Zero(robot.dof()).cwiseMax(robot.lower_limits()).cwiseMin(robot.upper_limits());
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::VectorXd q = random_inside(robot, rng, 0.05);
    const Eigen::Vector3d p = pose_at(robot, q).translation();
    const IkResult r = solve_ik(robot, IkTarget::planar(p.x(), p.y()), seed);
    ASSERT_TRUE(r.converged) << r.summary();
    EXPECT_LE((pose_at(robot, r.theta).translation() - p).head<2>().norm(), 1e-9);
    EXPECT_EQ(r.orientation_error, 0.0);
    expect_within_limits(robot, r.theta);
    EXPECT_GE(r.min_distance, 0.0) << "its links stay apart";
  }
}

// A target out of reach is reported, not answered: the closest configuration, the distance left (the reach is at
// most the sum of the link lengths), the diagnosis.
TEST(Ik, AnUnreachableTargetIsReportedWithTheDistanceLeft) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  const Eigen::Vector3d goal(2.5, 0.0, 0.5);
  const IkResult r = solve_ik(robot, IkTarget::spatial(goal), robot.home());
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.failure, IkFailure::kUnreachable) << r.diagnosis;
  const Eigen::Vector3d reached = pose_at(robot, r.theta).translation();
  EXPECT_NEAR(r.position_error, (reached - goal).norm(), 1e-12);
  EXPECT_GT(r.position_error, 1.0);  // the Panda reaches about 1.2 m from its shoulder
  EXPECT_LT(r.position_error, 2.5);  // and the answer does stretch towards the target
  EXPECT_NE(r.diagnosis.find("unreachable"), std::string::npos) << r.diagnosis;
  EXPECT_NE(r.diagnosis.find("beyond the arm's reach"), std::string::npos) << r.diagnosis;
  EXPECT_NE(r.summary().find("did not converge"), std::string::npos);
  expect_within_limits(robot, r.theta);
}

// A two-link planar arm (1 m links) whose first joint turns only within +-0.5 rad: a point 1.5 m away at 2 rad needs
// joint 1 at 2 -+ 0.72 rad, beyond its limit (joint 2 at -+1.45 rad is well within its own): the diagnosis names
// joint 1 alone, and the same arm with joint 1 free reaches the point.
RobotSpec two_link(double lower1, double upper1) {
  RobotSpec spec;
  spec.name = "two_link";
  spec.kind = ChainKind::kPlanar;
  spec.task = TaskRows::kPosition;
  for (int j = 0; j < 2; ++j) {
    JointSpec joint;
    joint.name = "j" + std::to_string(j + 1);
    joint.length = 1.0;
    joint.lower = j == 0 ? lower1 : -2.5;
    joint.upper = j == 0 ? upper1 : 2.5;
    joint.velocity_limit = testing::constant_law(1.0);
    spec.joints.push_back(joint);
  }
  spec.home = Eigen::Vector2d(0.1, 0.5);
  return spec;
}

TEST(Ik, ATargetBeyondAJointLimitNamesTheJoint) {
  const RobotModel robot(two_link(-0.5, 0.5));
  const Eigen::Vector2d goal = 1.5 * Eigen::Vector2d(std::cos(2.0), std::sin(2.0));
  const IkResult r = solve_ik(robot, IkTarget::planar(goal.x(), goal.y()), robot.home());
  EXPECT_FALSE(r.converged);
  ASSERT_EQ(r.failure, IkFailure::kJointLimit) << r.diagnosis;
  EXPECT_EQ(r.limit_joints, std::vector<int>{0}) << r.diagnosis;
  EXPECT_NEAR(r.theta(0), 0.5, 1e-6);
  EXPECT_NE(r.diagnosis.find("joint 1 ('j1') at its upper limit 0.5"), std::string::npos) << r.diagnosis;
  EXPECT_EQ(r.diagnosis.find("joint 2"), std::string::npos) << r.diagnosis;
  const Eigen::Vector3d reached = pose_at(robot, r.theta).translation();
  EXPECT_NEAR(r.position_error, (reached.head<2>() - goal).norm(), 1e-12);
  EXPECT_GT(r.position_error, 0.1);
  expect_within_limits(robot, r.theta);
  // With joint 1 free the point is reached: the limit was what held it.
  const RobotModel wide(two_link(-3.0, 3.0));
  const IkResult w = solve_ik(wide, IkTarget::planar(goal.x(), goal.y()), wide.home());
  ASSERT_TRUE(w.converged) << w.summary();
  EXPECT_LE((pose_at(wide, w.theta).translation().head<2>() - goal).norm(), 1e-9);
  // The shipped paper arm bends counter-clockwise only (joints 2 to 6 have positive limits): a pose whose angle phi
  // needs joint 1 below its lower limit names joint 1 too.
  const RobotModel paper = load_robot(source_path("robots/paper_pushrod_6dof.toml"));
  Eigen::VectorXd q = paper.lower_limits();
  RobotSpec spec = paper.spec();
  spec.joints[0].lower = -3.0;
  const RobotModel unlimited(spec);
  q(0) = paper.lower_limits()(0) - 0.3;
  const Eigen::Isometry3d p = pose_at(unlimited, q);
  const double phi = std::atan2(p.linear()(1, 0), p.linear()(0, 0));
  const IkResult s = solve_ik(paper, IkTarget::planar(p.translation().x(), p.translation().y(), phi), paper.home());
  EXPECT_FALSE(s.converged);
  ASSERT_EQ(s.failure, IkFailure::kJointLimit) << s.diagnosis;
  EXPECT_EQ(s.limit_joints.front(), 0) << s.diagnosis;
  EXPECT_NE(s.diagnosis.find("joint 1 ('" + paper.joint(0).name + "') at its lower limit"), std::string::npos)
      << s.diagnosis;
  EXPECT_TRUE(
      solve_ik(unlimited, IkTarget::planar(p.translation().x(), p.translation().y(), phi), paper.home()).converged);
}

ShapeSpec sphere(double radius, const Eigen::Vector3d& at) {
  ShapeSpec s;
  s.shape = ShapeSpec::Kind::kSphere;
  s.radius = radius;
  s.xyz = {at.x(), at.y(), at.z()};
  return s;
}

std::unique_ptr<Constraint> obstacle_constraint(const RobotModel& robot, const std::string& obstacles) {
  const auto doc = parse_toml_string("type = \"obstacle_avoidance\"\nobstacles = " + obstacles + "\n", "test");
  return make_constraint(TableReader::root(doc, "constraints"), robot);
}

// A target inside an obstacle: the arm stops at the obstacle's safety distance, clear of it, and the diagnosis names
// the pair that holds it back. A target beside the obstacle is reached, clear of it.
TEST(Ik, ATargetInsideAnObstacleIsReportedAndTheAnswerStaysClear) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  const Eigen::Vector3d centre(0.5, 0.0, 0.35);
  const auto obstacle = obstacle_constraint(robot, "[{ shape = \"sphere\", radius = 0.08, xyz = [0.5, 0.0, 0.35] }]");
  const IkResult r = solve_ik(robot, IkTarget::spatial(centre), robot.home(), {obstacle.get()});
  EXPECT_FALSE(r.converged);
  ASSERT_EQ(r.failure, IkFailure::kCollision) << r.diagnosis;
  EXPECT_NE(r.blocking_pair.find("obstacle 1"), std::string::npos) << r.blocking_pair;
  EXPECT_NE(r.diagnosis.find("obstacle 1"), std::string::npos) << r.diagnosis;
  const double clear = distance_to(robot, r.theta, sphere(0.08, centre));
  EXPECT_GT(clear, 0.0) << "the answer does not touch the obstacle";
  EXPECT_NEAR(r.min_distance, clear, 1e-6);
  EXPECT_GT(r.position_error, 0.08) << "the flange stays outside the sphere";
  expect_within_limits(robot, r.theta);

  const Eigen::Vector3d beside(0.5, 0.25, 0.35);
  const IkResult b = solve_ik(robot, IkTarget::spatial(beside), robot.home(), {obstacle.get()});
  ASSERT_TRUE(b.converged) << b.summary();
  EXPECT_LE((pose_at(robot, b.theta).translation() - beside).norm(), 1e-9);
  EXPECT_GT(distance_to(robot, b.theta, sphere(0.08, centre)), 0.0);
}

TEST(Ik, BadArgumentsAreRefused) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  EXPECT_THROW((void)solve_ik(robot, IkTarget::spatial({0.4, 0, 0.4}), Eigen::VectorXd::Zero(3)),
               std::invalid_argument);
  IkTarget nan = IkTarget::spatial({std::nan(""), 0, 0.4});
  EXPECT_THROW((void)solve_ik(robot, nan, robot.home()), std::invalid_argument);
  IkTarget rows = IkTarget::spatial({0.4, 0, 0.4});
  rows.rows = {"x", "wz"};  // an orientation row without an orientation
  EXPECT_THROW((void)solve_ik(robot, rows, robot.home()), std::invalid_argument);
  IkOptions options;
  options.max_step = 0.0;
  EXPECT_THROW((void)solve_ik(robot, IkTarget::spatial({0.4, 0, 0.4}), robot.home(), {}, options),
               std::invalid_argument);
  options = IkOptions{};
  options.margin = Eigen::VectorXd::Constant(1, 10.0);  // more than half of a joint's range
  EXPECT_THROW((void)solve_ik(robot, IkTarget::spatial({0.4, 0, 0.4}), robot.home(), {}, options),
               std::invalid_argument);
}

// --- the scenario keys ------------------------------------------------------------------------------------------

// Writes a Panda scenario whose theta0 line (line 4) is `theta0`, with `extra` at the end; returns its path.
std::filesystem::path panda_scenario(const std::string& name, const std::string& theta0, const std::string& path,
                                     const std::string& extra = "", const std::string& robot = "franka_panda.toml") {
  const std::filesystem::path file = scratch_dir("ik_" + name) / "s.toml";
  std::ofstream(file) << robot_line(robot) << "duration = 1.0\n"
                      << "step = 0.01\n"
                      << theta0 << "\n"
                      << "[path]\n"
                      << path << "\n"
                      << objective_entry("min_velocity_norm") << constraint_entry("task_tracking")
                      << constraint_entry("joint_angle_margin", "margin = 0.05\n") << extra;
  return file;
}

const char* kLine = "type = \"line\"\ndelta = [0.0, 0.05, 0.0]";

TEST(IkScenario, AGivenPoseIsSolvedAtLoadWithinTheSchemesMargin) {
  const auto file = panda_scenario(
      "pose", "theta0 = { ik = { position = [0.45, 0.1, 0.4], rpy = [\"pi\", 0.2, 0.3] }, seed = \"home\" }", kLine);
  Scenario s = load_scenario(file);
  ASSERT_TRUE(s.ik.has_value());
  EXPECT_TRUE(s.ik->converged);
  EXPECT_EQ(s.theta0, s.ik->theta);
  const Eigen::Isometry3d got = pose_at(*s.robot, s.theta0);
  EXPECT_LE((got.translation() - Eigen::Vector3d(0.45, 0.1, 0.4)).norm(), 1e-9);
  EXPECT_LE(angle_between(got.linear(), rpy_matrix({M_PI, 0.2, 0.3})), 1e-9);
  expect_within_limits(*s.robot, s.theta0, 0.05);  // joint_angle_margin's margin holds too
  // The relative path starts where the IK put the end effector.
  Eigen::VectorXd r(3), r_dot(3);
  s.path->evaluate(0.0, r, r_dot);
  EXPECT_LE((r - Eigen::Vector3d(0.45, 0.1, 0.4)).norm(), 1e-9);
  EXPECT_NE(s.ik_target.find("rpy"), std::string::npos) << s.ik_target;
  const StartReport start = check_start(s);
  EXPECT_TRUE(start.ok()) << start.text();
  // The seed chooses the solution: from another seed the pose is the same, the configuration another.
  Scenario other = load_scenario(file, {"theta0.seed=[0.5, 0.3, -0.4, -1.8, 0.3, 2.0, 0.0]"});
  ASSERT_TRUE(other.ik.has_value());
  const Eigen::Isometry3d again = pose_at(*other.robot, other.theta0);
  EXPECT_LE((again.translation() - got.translation()).norm(), 1e-9);
}

TEST(IkScenario, IkPathAimsAtAnAbsolutePathsStart) {
  const auto file = panda_scenario("path", "theta0 = { ik = \"path\" }",
                                   std::string(kLine) + "\nplacement = \"absolute\"\norigin = [0.4, -0.1, 0.5]");
  Scenario s = load_scenario(file);
  ASSERT_TRUE(s.ik.has_value());
  EXPECT_LE((pose_at(*s.robot, s.theta0).translation() - Eigen::Vector3d(0.4, -0.1, 0.5)).norm(), 1e-9);
  EXPECT_TRUE(check_start(s).ok());
  // A pose task keeps the seed's orientation (the orientation the run then holds).
  Scenario pose = load_scenario(file, {"task=pose"});
  EXPECT_LE(
      angle_between(pose_at(*pose.robot, pose.theta0).linear(), pose_at(*pose.robot, pose.robot->home()).linear()),
      1e-9);
  EXPECT_LE((pose_at(*pose.robot, pose.theta0).translation() - Eigen::Vector3d(0.4, -0.1, 0.5)).norm(), 1e-9);
  // A given orientation with the path's position.
  Scenario turned = load_scenario(file, {"theta0.ik={ position = \"path\", rpy = [3.0, 0.1, 0.0] }"});
  EXPECT_LE(angle_between(pose_at(*turned.robot, turned.theta0).linear(), rpy_matrix({3.0, 0.1, 0.0})), 1e-9);
}

TEST(IkScenario, APlanarScenarioTakesXYAndPhi) {
  const std::filesystem::path file = scratch_dir("ik_planar") / "s.toml";
  std::ofstream(file) << robot_line("paper_pushrod_6dof.toml") << "duration = 1.0\nstep = 0.01\n"
                      << "theta0 = { ik = { position = [0.45, 1.1], phi = 1.9 } }\n"
                      << "[path]\ntype = \"line\"\ndelta = [0.01, 0.0]\n"
                      << objective_entry("min_velocity_norm") << constraint_entry("task_tracking");
  Scenario s = load_scenario(file);
  ASSERT_TRUE(s.ik.has_value());
  KinematicsData k(*s.robot);
  compute_kinematics(*s.robot, s.theta0, k, KinematicsLevel::kPosition);
  EXPECT_LE((k.ee_pose.translation().head<2>() - Eigen::Vector2d(0.45, 1.1)).norm(), 1e-9);
  EXPECT_LE(std::abs(std::remainder(std::atan2(k.ee_pose.linear()(1, 0), k.ee_pose.linear()(0, 0)) - 1.9, 2 * M_PI)),
            1e-9);
  // rpy is the spatial key.
  try {
    (void)load_scenario(file, {"theta0.ik.rpy=[0, 0, 1]"});
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("`phi`"), std::string::npos) << e.what();
  }
}

// Bad input: each is a ConfigError at theta0's line (4) that names the key and says what was expected.
TEST(IkScenario, BadKeysAreReportedAtTheirLocation) {
  struct Case {
    std::string theta0, expected;
  };
  const std::vector<Case> cases = {
      {"theta0 = { ik = 3 }", "key 'ik': expected \"path\" or a table"},
      {"theta0 = { ik = \"start\" }", "key 'ik': expected \"path\""},
      {"theta0 = { seed = \"home\" }", "missing required key 'ik'"},
      {"theta0 = { ik = { position = [0.4, 0.1] } }", "key 'position': expected an array of 3 numbers"},
      {"theta0 = { ik = { position = \"there\" } }", "key 'position': expected an array of 3 numbers or \"path\""},
      {"theta0 = { ik = { position = [0.4, 0.1, 0.4], rpy = [1, 2] } }", "key 'rpy': expected an array of 3"},
      {"theta0 = { ik = { position = [0.4, 0.1, 0.4], phi = 1.0 } }", "key 'phi': is for a planar robot"},
      {"theta0 = { ik = { position = [0.4, 0.1, 0.4], yaw = 1.0 } }", "unknown key 'yaw'"},
      {"theta0 = { ik = { rpy = [0, 0, 0] } }", "missing required key 'position'"},
      {"theta0 = { ik = { position = [0.4, 0.1, 0.4] }, seed = \"near\" }", "key 'seed': expected \"home\", \"zeros\""},
      {"theta0 = { ik = { position = [0.4, 0.1, 0.4] }, seed = [0, 0] }", "key 'seed': expected \"home\""},
      {"theta0 = { ik = { position = [0.4, 0.1, 0.4] }, seed = [9, 0, 0, -2, 0, 2, 0] }", "outside its limits"},
      {"theta0 = { ik = { position = [0.4, 0.1, 0.4] }, start = 1 }", "unknown key 'start'"},
      {"theta0 = { ik = { position = [2000, 0.1, 0.4] } }", "physical range"},
      {"theta0 = { ik = \"path\" }", "relative path starts wherever the arm"},
      {"theta0 = { ik = { position = [3.0, 0.0, 0.4] } }", "did not converge (unreachable)"},
      {"theta0 = 5", "or a table { ik = ..., seed = ... }"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.theta0);
    const auto file = panda_scenario("bad", c.theta0, kLine);
    try {
      (void)load_scenario(file);
      ADD_FAILURE() << "expected a ConfigError";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(file.string() + ":4:", 0), 0U) << what;
      EXPECT_NE(what.find(c.expected), std::string::npos) << what;
    }
  }
}

// The scenario's obstacles keep the IK's answer clear: a target inside one is a ConfigError naming the pair.
TEST(IkScenario, ATargetInsideTheScenariosObstacleIsRefused) {
  const std::string obstacle =
      "[[constraints]]\ntype = \"obstacle_avoidance\"\nobstacles = [{ shape = \"sphere\", radius = 0.08, xyz = [0.5, "
      "0.0, 0.35] }]\n";
  const auto inside = panda_scenario("inside", "theta0 = { ik = { position = [0.5, 0.0, 0.35] } }", kLine, obstacle);
  try {
    (void)load_scenario(inside);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("(collision)"), std::string::npos) << what;
    EXPECT_NE(what.find("obstacle 1"), std::string::npos) << what;
  }
  const auto beside = panda_scenario("beside", "theta0 = { ik = { position = [0.5, 0.25, 0.35] } }", kLine, obstacle);
  Scenario s = load_scenario(beside);
  ASSERT_TRUE(s.ik.has_value());
  EXPECT_GT(distance_to(*s.robot, s.theta0, sphere(0.08, {0.5, 0.0, 0.35})), 0.0);
  EXPECT_LT(s.ik->min_distance, 1.0);  // the obstacle's pairs were measured
  EXPECT_TRUE(check_start(s).ok());
}

}  // namespace
}  // namespace redres

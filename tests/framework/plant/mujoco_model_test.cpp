// The MuJoCo model redres writes (mjcf_from_robot, docs/plant.md), loaded with MuJoCo: for every robot in robots/ and
// a hand-written chain with a prismatic joint and every kind of shape, MuJoCo's end-effector site and body poses equal
// redres's kinematics at random configurations, the limits and mass properties arrive, the shapes and the excluded
// pairs are there, and a robot without mass properties is refused with every such joint named. (Built only with
// REDRES_WITH_MUJOCO.)

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "redres/config/toml_reader.hpp"
#include "redres/model/convex.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/plant/mujoco_model.hpp"

namespace redres {
namespace {

constexpr int kConfigurations = 60;
constexpr double kPoseTolerance = 1e-12;

std::vector<std::filesystem::path> shipped_robots() {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator("robots"))
    if (entry.path().extension() == ".toml") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

bool has_inertia(const JointSpec& joint) { return joint.inertia.has_value(); }
// Mass properties no rigid body has (a maker's tensor kept with a warning).
bool impossible_inertia(const JointSpec& joint) { return joint.inertia && !joint.inertia->invalid().empty(); }

double rotation_error(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.linear() - b.linear()).cwiseAbs().maxCoeff();
}

struct Agreement {
  double position = 0.0;     // the largest |p_mujoco - p_redres| (m) of the end effector
  double orientation = 0.0;  // the largest rotation-matrix entry difference of the end effector
  double links = 0.0;        // the largest difference of any body pose entry against redres's link frames
  double shapes = 0.0;       // the largest difference of a primitive geom's pose against redres's shape pose
  double hulls = 0.0;        // the largest distance of a hull's vertex from MuJoCo's nearest mesh vertex (m)
};

// The geom names mjcf_from_robot gives the shapes: the body's name, "_shape", the shape's index on its link.
std::vector<std::string> geom_names(const RobotModel& robot) {
  std::vector<std::string> names;
  std::vector<int> count(static_cast<std::size_t>(robot.dof()), 0);
  for (const RobotModel::LinkShape& s : robot.link_shapes())
    names.push_back(mjcf_body_name(robot, s.link) + "_shape" +
                    std::to_string(count[static_cast<std::size_t>(s.link)]++));
  return names;
}

// Where MuJoCo has each shape against where redres has it, at the configuration both last computed.
void compare_shapes(const RobotModel& robot, const MujocoModel& mj, const KinematicsData& k, Agreement& worst) {
  const std::vector<std::string> names = geom_names(robot);
  for (std::size_t i = 0; i < names.size(); ++i) {
    const RobotModel::LinkShape& s = robot.link_shapes()[i];
    const int g = mj.geom(names[i]);
    ASSERT_GE(g, 0) << names[i];
    const Eigen::Isometry3d want = k.link_frames[static_cast<std::size_t>(s.link)] * s.pose;
    const Eigen::Isometry3d got = mj.geom_pose(g);
    const double position = (got.translation() - want.translation()).norm();
    switch (s.spec.shape) {
      case ShapeSpec::Kind::kSphere: worst.shapes = std::max(worst.shapes, position); break;
      case ShapeSpec::Kind::kCapsule: {  // symmetric: the centre and the axis, either way along it
        const Eigen::Vector3d a = got.linear().col(2), b = want.linear().col(2);
        worst.shapes =
            std::max({worst.shapes, position, std::min((a - b).cwiseAbs().maxCoeff(), (a + b).cwiseAbs().maxCoeff())});
        break;
      }
      case ShapeSpec::Kind::kBox:
      case ShapeSpec::Kind::kCylinder:
        worst.shapes = std::max({worst.shapes, position, rotation_error(got, want)});
        break;
      case ShapeSpec::Kind::kConvex: {
        const Eigen::Matrix3Xd mesh = mj.mesh_vertices(g);
        ASSERT_EQ(mesh.cols(), static_cast<Eigen::Index>(s.spec.hull->vertices.size())) << names[i];
        for (const Eigen::Vector3d& v : s.spec.hull->vertices)
          worst.hulls = std::max(worst.hulls, (mesh.colwise() - want * v).colwise().norm().minCoeff());
        break;
      }
      default: ADD_FAILURE() << "unexpected shape " << names[i];
    }
  }
}

// MuJoCo's and redres's forward kinematics at kConfigurations random configurations within the limits.
Agreement compare_kinematics(const RobotModel& robot, MujocoModel& mj, unsigned seed) {
  const int site = mj.site("end_effector");
  EXPECT_GE(site, 0);
  std::vector<int> bodies;
  for (int j = 0; j < robot.dof(); ++j) {
    bodies.push_back(mj.body(mjcf_body_name(robot, j)));
    EXPECT_GE(bodies.back(), 0) << mjcf_body_name(robot, j);
  }
  std::mt19937 rng(seed);
  KinematicsData k(robot);
  Agreement worst;
  for (int c = 0; c < kConfigurations; ++c) {
    Eigen::VectorXd theta(robot.dof());
    for (int j = 0; j < robot.dof(); ++j)
      theta(j) = std::uniform_real_distribution<double>(robot.joint(j).lower, robot.joint(j).upper)(rng);
    compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
    mj.kinematics(theta);
    const Eigen::Isometry3d ee = mj.site_pose(site);
    worst.position = std::max(worst.position, (ee.translation() - k.ee_pose.translation()).norm());
    worst.orientation = std::max(worst.orientation, rotation_error(ee, k.ee_pose));
    compare_shapes(robot, mj, k, worst);
    for (int j = 0; j < robot.dof(); ++j) {
      const Eigen::Isometry3d body = mj.body_pose(bodies[static_cast<std::size_t>(j)]);
      const Eigen::Isometry3d& link = k.link_frames[static_cast<std::size_t>(j)];
      worst.links =
          std::max({worst.links, (body.translation() - link.translation()).norm(), rotation_error(body, link)});
    }
  }
  return worst;
}

// What every generated model must hold, checked against the robot it was made from.
void check_model(const RobotModel& robot, MujocoModel& mj, unsigned seed) {
  ASSERT_EQ(mj.nq(), robot.dof());
  ASSERT_EQ(mj.nbody(), robot.dof() + 1);  // the world and one per joint
  double worst_inertia = 0.0;              // the largest tensor difference, relative to the tensor's largest entry
  for (int j = 0; j < robot.dof(); ++j) {
    const JointSpec& joint = robot.joint(j);
    SCOPED_TRACE("joint " + joint.name);
    const int id = mj.joint(joint.name);
    ASSERT_GE(id, 0);
    EXPECT_TRUE(mj.joint_limited(id));
    EXPECT_EQ(mj.joint_range(id)(0), joint.lower);  // printed with 17 digits: the same double
    EXPECT_EQ(mj.joint_range(id)(1), joint.upper);
    if (!has_inertia(joint)) continue;
    const int b = mj.body(mjcf_body_name(robot, j));
    ASSERT_GE(b, 0);
    EXPECT_EQ(mj.body_mass(b), joint.inertia->mass);
    EXPECT_LE((mj.body_com(b) - joint.inertia->com).cwiseAbs().maxCoeff(), 1e-15);
    if (impossible_inertia(joint)) continue;  // balanced by MuJoCo: its largest moment raised
    // MuJoCo keeps the tensor as principal moments and axes; they must give it back, to the accuracy of its 3 x 3
    // eigen-solver (measured: 6.5e-7 of the largest entry for the Panda's first link, whose two largest moments are
    // close; 1e-8 or better elsewhere).
    const Eigen::Matrix3d& I = joint.inertia->tensor;
    const double relative = (mj.body_inertia(b) - I).cwiseAbs().maxCoeff() / I.cwiseAbs().maxCoeff();
    worst_inertia = std::max(worst_inertia, relative);
    EXPECT_LE(relative, 1e-6) << "MuJoCo:\n" << mj.body_inertia(b) << "\nredres:\n" << I;
  }
  // Every shape is a geom; every hull a mesh.
  EXPECT_EQ(mj.ngeom(), static_cast<int>(robot.link_shapes().size()));
  const auto hulls =
      std::count_if(robot.link_shapes().begin(), robot.link_shapes().end(),
                    [](const RobotModel::LinkShape& s) { return s.spec.shape == ShapeSpec::Kind::kConvex; });
  EXPECT_EQ(mj.nmesh(), static_cast<int>(hulls));
  // A pair of bodies is excluded exactly when redres checks none of their bodies against each other; neighbours
  // always are.
  for (int i = 0; i < robot.dof(); ++i)
    for (int k = i + 1; k < robot.dof(); ++k) {
      bool checked = false;
      for (int a = 0; a < static_cast<int>(robot.bodies().size()); ++a)
        for (int b = 0; b < static_cast<int>(robot.bodies().size()); ++b)
          if (robot.bodies()[static_cast<std::size_t>(a)].link == i &&
              robot.bodies()[static_cast<std::size_t>(b)].link == k)
            checked = checked || robot.self_collision_bodies(a, b);
      const bool excluded = mj.excluded(mj.body(mjcf_body_name(robot, i)), mj.body(mjcf_body_name(robot, k)));
      EXPECT_EQ(excluded, !checked) << "links " << i << " and " << k;
      // Neighbours are excluded unless a side branch's body rides on one of them (redres checks those).
      const auto branch_on = [&](int link) {
        return std::any_of(robot.bodies().begin(), robot.bodies().end(),
                           [&](const RobotModel::Body& body) { return body.link == link && body.branch; });
      };
      if (k == i + 1 && !branch_on(i) && !branch_on(k)) {
        EXPECT_TRUE(excluded) << "neighbours " << i << " and " << k;
      }
    }

  const Agreement agreement = compare_kinematics(robot, mj, seed);
  EXPECT_LE(agreement.position, kPoseTolerance);
  EXPECT_LE(agreement.orientation, kPoseTolerance);
  EXPECT_LE(agreement.links, kPoseTolerance);
  EXPECT_LE(agreement.shapes, kPoseTolerance);
  EXPECT_LE(agreement.hulls, 1e-6);  // MuJoCo keeps mesh vertices as floats
  std::cout << "[ mujoco   ] " << robot.name() << ": " << robot.dof() << " joints, " << robot.link_shapes().size()
            << " shapes; largest end-effector difference over " << kConfigurations << " configurations: position "
            << agreement.position << " m, rotation entries " << agreement.orientation << "; inertia tensors (relative) "
            << worst_inertia << "; shapes " << agreement.shapes << ", hull vertices " << agreement.hulls
            << " m; link frames " << agreement.links << "\n";
}

TEST(MujocoModel, EveryShippedRobotHasRedresKinematicsInMujoco) {
  ASSERT_TRUE(mujoco_available());
  const auto files = shipped_robots();
  ASSERT_GE(files.size(), 10U);
  unsigned seed = 1;
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    const RobotModel robot = load_robot(file);
    const bool complete = std::all_of(robot.joints().begin(), robot.joints().end(), has_inertia);
    MjcfOptions options;
    options.placeholder_inertia = !complete;
    options.balance_inertia = std::any_of(robot.joints().begin(), robot.joints().end(), impossible_inertia);
    const std::string xml = mjcf_from_robot(robot, options);
    MujocoModel mj = MujocoModel::from_xml(xml);
    check_model(robot, mj, seed++);
  }
}

TEST(MujocoModel, ARobotWithoutMassPropertiesIsRefusedNamingEveryJoint) {
  int refused = 0;
  for (const auto& file : shipped_robots()) {
    SCOPED_TRACE(file.string());
    const RobotModel robot = load_robot(file);
    if (std::all_of(robot.joints().begin(), robot.joints().end(),
                    [](const JointSpec& j) { return has_inertia(j) && !impossible_inertia(j); })) {
      EXPECT_NO_THROW(static_cast<void>(mjcf_from_robot(robot)));
      continue;
    }
    ++refused;
    try {
      static_cast<void>(mjcf_from_robot(robot));
      ADD_FAILURE() << "a robot without mass properties was written";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      for (const JointSpec& joint : robot.joints()) {
        const bool named = what.find("'" + joint.name + "' (") != std::string::npos;
        EXPECT_EQ(named, !has_inertia(joint) || impossible_inertia(joint)) << joint.name << " in: " << what;
      }
      const bool any_missing = !std::all_of(robot.joints().begin(), robot.joints().end(), has_inertia);
      EXPECT_EQ(what.find("allow placeholder masses") != std::string::npos, any_missing) << what;
      EXPECT_EQ(what.find("balance the principal moments") != std::string::npos,
                std::any_of(robot.joints().begin(), robot.joints().end(), impossible_inertia))
          << what;
    }
  }
  EXPECT_GE(refused, 4);  // the iiwa, the UR5e and the planar robots have none, the xArm6 impossible ones
}

TEST(MujocoModel, TheFullPandaKeepsItsMassPropertiesAndShapes) {
  const RobotModel robot = load_robot("robots/franka_panda.toml");
  ASSERT_TRUE(std::all_of(robot.joints().begin(), robot.joints().end(), has_inertia));
  const std::string xml = mjcf_from_robot(robot);
  EXPECT_EQ(xml.find("placeholder"), std::string::npos);
  EXPECT_NE(xml.find("fullinertia"), std::string::npos);
  // Contacts are filtered by the excluded pairs alone, not by MuJoCo's parent-child rule.
  EXPECT_NE(xml.find("filterparent=\"disable\""), std::string::npos);
  MujocoModel mj = MujocoModel::from_xml(xml);
  double total = 0.0;
  for (int b = 1; b < mj.nbody(); ++b) total += mj.body_mass(b);
  double expected = 0.0;
  for (const JointSpec& joint : robot.joints()) expected += joint.inertia->mass;
  EXPECT_NEAR(total, expected, 1e-12);
  EXPECT_GT(expected, 10.0);  // the Panda's links weigh some 16 kg together
}

// A chain by joint frames with a prismatic joint, a tilted axis, a base and end-effector pose, shapes of every kind
// (a hull among them) and an excluded pair.
RobotModel mixed_chain() {
  const auto file = parse_toml_string(R"(
name = "mixed"
kind = "spatial"
convention = "joints"
task = "pose"
collision_exclude = [["a", "d"]]
[base]
xyz = [0.1, -0.2, 0.3]
rpy = [0.2, -0.1, 0.4]
[end_effector]
xyz = [0.05, 0.0, 0.12]
rpy = [0.3, 0.2, -0.5]
[[joints]]
name = "a"
origin = { xyz = [0, 0, 0.2], rpy = [0, 0, 0] }
axis = [0, 0, 1]
limits = [-2.5, 2.5]
velocity_limit = { type = "constant", lower = -1.0, upper = 1.0 }
inertia = { mass = 2.0, com = [0.01, 0.02, 0.1], ixx = 0.02, iyy = 0.03, izz = 0.015, ixy = 0.001, ixz = -0.002, iyz = 0.0005 }
collision = [{ shape = "capsule", radius = 0.05, from = [0, 0, 0], to = [0, 0, 0.3] }]
[[joints]]
name = "b"
type = "prismatic"
origin = { xyz = [0.1, 0, 0.3], rpy = [0.5, 0.1, -0.2] }
axis = [1, 1, 0]
limits = [-0.2, 0.4]
velocity_limit = { type = "constant", lower = -1.0, upper = 1.0 }
inertia = { mass = 1.5, com = [0.1, 0, 0], ixx = 0.01, iyy = 0.012, izz = 0.013 }
collision = [{ shape = "box", size = [0.3, 0.1, 0.08], xyz = [0.1, 0, 0], rpy = [0.1, 0.2, 0.3] }]
[[joints]]
name = "c"
origin = { xyz = [0.3, 0.05, 0], rpy = [-0.4, 0.7, 0.2] }
axis = [0.3, -0.5, 0.8]
limits = [-1.5, 2.0]
velocity_limit = { type = "constant", lower = -1.0, upper = 1.0 }
inertia = { mass = 1.0, com = [0, 0.05, 0], ixx = 0.004, iyy = 0.005, izz = 0.006, ixz = 0.0002 }
collision = [{ shape = "cylinder", radius = 0.04, length = 0.2, xyz = [0, 0.05, 0], rpy = [1.0, 0, 0] },
             { shape = "capsule", radius = 0.03, length = 0.15, xyz = [0, 0, 0.1], rpy = [0, 0.3, 0] }]
[[joints]]
name = "d"
origin = { xyz = [0, 0.2, 0.05], rpy = [0, 0, 0] }
axis = [0, 1, 0]
limits = [-3.0, 3.0]
velocity_limit = { type = "constant", lower = -1.0, upper = 1.0 }
inertia = { mass = 0.5, com = [0, 0, 0.05], ixx = 0.001, iyy = 0.001, izz = 0.0015 }
collision = [{ shape = "sphere", radius = 0.06, xyz = [0, 0, 0.1] }]
)",
                                      "<mixed>");
  RobotSpec spec = load_robot(TableReader::root(file, "robot")).spec();
  // A hull on the last link: a tetrahedron with a point inside, moved off the link frame's origin.
  const std::vector<Eigen::Vector3d> points = {
      {0.02, 0.01, 0.15}, {0.12, 0.0, 0.14}, {0.05, 0.09, 0.16}, {0.05, 0.03, 0.25}, {0.05, 0.03, 0.18}};
  Eigen::Isometry3d at = Eigen::Isometry3d::Identity();
  at.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, 0.9, 0.1).normalized()).toRotationMatrix();
  at.translation() = Eigen::Vector3d(0.0, 0.02, 0.0);
  spec.joints.back().collision.push_back(convex_shape(points, "tetrahedron.stl").placed(at));
  return RobotModel(spec);
}

TEST(MujocoModel, APrismaticJointTiltedAxesAndEveryShapeKind) {
  const RobotModel robot = mixed_chain();
  ASSERT_EQ(robot.joint(1).type, JointType::kPrismatic);
  const std::string xml = mjcf_from_robot(robot);
  EXPECT_NE(xml.find("type=\"slide\""), std::string::npos);
  EXPECT_NE(xml.find("<mesh "), std::string::npos);
  MujocoModel mj = MujocoModel::from_xml(xml);
  check_model(robot, mj, 99);
  // The excluded pair a-d is not checked by redres, so MuJoCo excludes it; b-d is checked and stays.
  EXPECT_TRUE(mj.excluded(mj.body("a"), mj.body("d")));
  EXPECT_FALSE(mj.excluded(mj.body("b"), mj.body("d")));
}

TEST(MujocoModel, PlaceholderMassesAreOnlyForLinksWithout) {
  const RobotModel robot = load_robot("robots/kuka_iiwa14.toml");
  ASSERT_FALSE(has_inertia(robot.joint(0)));
  MjcfOptions options;
  options.placeholder_inertia = true;
  options.placeholder_mass = 0.25;
  MujocoModel mj = MujocoModel::from_xml(mjcf_from_robot(robot, options));
  for (int j = 0; j < robot.dof(); ++j) EXPECT_EQ(mj.body_mass(mj.body(mjcf_body_name(robot, j))), 0.25);
  options.placeholder_mass = 0.0;
  EXPECT_THROW(static_cast<void>(mjcf_from_robot(robot, options)), std::invalid_argument);
}

TEST(MujocoModel, MujocoRefusingAModelSaysWhy) {
  try {
    static_cast<void>(MujocoModel::from_xml("<mujoco><worldbody><body><joint/></body></worldbody></mujoco>"));
    FAIL() << "a massless moving body was loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("MuJoCo refused the model"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace redres

// Mass properties (issue 26): Inertia::moved and combined against bodies made of point masses, the physical checks,
// the URDF's <inertial> elements gathered per moving link (side branches included), and the robot file's `inertia`.

#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "redres/model/kinematics.hpp"
#include "redres/model/robot.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

struct Points {
  std::vector<double> m;
  std::vector<Eigen::Vector3d> p;
};

// The exact mass properties of point masses.
Inertia of(const Points& b) {
  Inertia out;
  for (std::size_t k = 0; k < b.m.size(); ++k) {
    out.mass += b.m[k];
    out.com += b.m[k] * b.p[k];
  }
  out.com /= out.mass;
  for (std::size_t k = 0; k < b.m.size(); ++k) {
    const Eigen::Vector3d d = b.p[k] - out.com;
    out.tensor += b.m[k] * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  }
  return out;
}

Points random_body(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.3, 0.3), w(0.1, 2.0);
  Points b;
  for (int k = 0; k < 12; ++k) {
    b.m.push_back(w(rng));
    b.p.emplace_back(u(rng), u(rng), u(rng));
  }
  return b;
}

void expect_same(const Inertia& a, const Inertia& b) {
  EXPECT_NEAR(a.mass, b.mass, 1e-12);
  EXPECT_LE((a.com - b.com).norm(), 1e-12);
  EXPECT_LE((a.tensor - b.tensor).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Inertia, MovedAndCombinedAgreeWithPointMasses) {
  std::mt19937 rng(26);
  for (int trial = 0; trial < 50; ++trial) {
    const Points a = random_body(rng), b = random_body(rng);
    const Eigen::Isometry3d pose = Eigen::Translation3d(0.1, -0.2, 0.3) * Eigen::Quaterniond::UnitRandom();
    Points moved = a;
    for (auto& p : moved.p) p = pose * p;
    expect_same(of(a).moved(pose), of(moved));
    Points both = a;
    both.m.insert(both.m.end(), b.m.begin(), b.m.end());
    both.p.insert(both.p.end(), b.p.begin(), b.p.end());
    expect_same(of(a).combined(of(b)), of(both));
    EXPECT_EQ(of(both).invalid(), "");
  }
}

TEST(Inertia, ImpossibleBodiesAreRefusedWithTheReason) {
  Inertia body;
  body.mass = 1.0;
  body.tensor = Eigen::Vector3d(0.1, 0.1, 0.1).asDiagonal();
  EXPECT_EQ(body.invalid(), "");
  Inertia light = body;
  light.mass = -1.0;
  EXPECT_NE(light.invalid().find("mass > 0"), std::string::npos);
  Inertia flat = body;
  flat.tensor = Eigen::Vector3d(0.1, 0.1, 0.3).asDiagonal();  // 0.1 + 0.1 < 0.3: no body has it
  EXPECT_NE(flat.invalid().find("triangle"), std::string::npos);
  Inertia negative = body;
  negative.tensor(0, 0) = -0.1;
  EXPECT_NE(negative.invalid(), "");
}

TEST(Inertia, TheUrdfsInertialsRideWithTheirMovingLink) {
  const RobotModel panda = load_robot(source_path("robots/franka_panda_meshes.toml"));
  const double masses[6] = {2.7, 2.73, 2.04, 2.08, 3.0, 1.3};
  for (int j = 0; j < 6; ++j) {
    ASSERT_TRUE(panda.joint(j).inertia) << "joint " << j + 1;
    EXPECT_DOUBLE_EQ(panda.joint(j).inertia->mass, masses[j]);
    EXPECT_EQ(panda.joint(j).inertia->invalid(), "");
  }
  // Link 7 carries the flange (massless), the hand (0.81 kg) and the two fingers (0.1 kg each).
  ASSERT_TRUE(panda.joint(6).inertia);
  EXPECT_NEAR(panda.joint(6).inertia->mass, 0.2 + 0.81 + 0.1 + 0.1, 1e-12);
  // Link 1's inertial sits at its <origin> (0, -0.04, -0.05) in the link frame.
  EXPECT_LE((panda.joint(0).inertia->com - Eigen::Vector3d(0.0, -0.04, -0.05)).norm(), 1e-12);
  // The xArm6's published link 2 tensor breaks the triangle inequality: kept as given, with a warning.
  const RobotModel xarm = load_robot(source_path("robots/xarm6.toml"));
  ASSERT_TRUE(xarm.joint(1).inertia);
  EXPECT_EQ(xarm.joint(1).inertia->mass, 1.71);
  EXPECT_NE(xarm.joint(1).inertia_warning.find("triangle"), std::string::npos) << xarm.joint(1).inertia_warning;
  EXPECT_NE(xarm.joint(1).inertia_warning.find("link2"), std::string::npos) << xarm.joint(1).inertia_warning;
  EXPECT_EQ(xarm.joint(0).inertia_warning, "");
  // A robot file without inertias has none.
  const RobotModel iiwa = load_robot(source_path("robots/kuka_iiwa14.toml"));
  EXPECT_FALSE(iiwa.joint(0).inertia);
}

TEST(Inertia, TheRobotFileGivesThemPerJointAndRefusesImpossibleOnes) {
  const auto dir = scratch_dir("inertia_file");
  const std::string head = R"(name = "two"
kind = "planar"
[[joints]]
name = "j1"
length = 0.3
limits = [-1.0, 1.0]
velocity_limit = { type = "constant", lower = -1.0, upper = 1.0 }
)";
  std::ofstream(dir / "good.toml") << head
                                   << "inertia = { mass = 1.5, com = [0.15, 0.0, 0.0], ixx = 0.001, iyy = 0.012, "
                                      "izz = 0.012 }\n";
  const RobotModel robot = load_robot(dir / "good.toml");
  ASSERT_TRUE(robot.joint(0).inertia);
  EXPECT_EQ(robot.joint(0).inertia->mass, 1.5);
  EXPECT_EQ(robot.joint(0).inertia->com.x(), 0.15);
  EXPECT_NE(robot.joint(0).inertia_source.find("good.toml:8:"), std::string::npos) << robot.joint(0).inertia_source;
  std::ofstream(dir / "bad.toml") << head << "inertia = { mass = 1.5, ixx = 0.001, iyy = 0.001, izz = 0.012 }\n";
  try {
    (void)load_robot(dir / "bad.toml");
    FAIL() << "expected an error";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.toml:8:"), std::string::npos) << what;
    EXPECT_NE(what.find("triangle"), std::string::npos) << what;
  }
}

// robots/franka_panda.toml carries Franka's published mass properties, given in Craig's link frames and moved to the
// file's (modified DH) link frames. Placed in the world, they must be where the same figures put on the URDF Panda's
// link frames (robots/franka_panda_urdf.toml, whose link frames are Craig's) are: the arm's centre of mass and its
// inertia about it agree at random configurations.
TEST(Inertia, TheTomlPandaCarriesFrankasFiguresInItsOwnFrames) {
  const RobotModel dh = load_robot(source_path("robots/franka_panda.toml"));
  const RobotModel urdf = load_robot(source_path("robots/franka_panda_urdf.toml"));
  ASSERT_EQ(dh.dof(), 7);
  // Franka's figures (franka_description/robots/common/inertial.yaml): mass, com, ixx iyy izz ixy ixz iyz.
  const double maker[7][10] = {
      {4.970684, 0.003875, 0.002081, -0.04762, 0.70337, 0.70661, 0.0091170, -0.00013900, 0.0067720, 0.019169},
      {0.646926, -0.003141, -0.02872, 0.003495, 0.0079620, 2.8110e-02, 2.5995e-02, -3.9250e-3, 1.0254e-02, 7.0400e-04},
      {3.228604, 2.7518e-02, 3.9252e-02, -6.6502e-02, 3.7242e-02, 3.6155e-02, 1.0830e-02, -4.7610e-03, -1.1396e-02,
       -1.2805e-02},
      {3.587895, -5.317e-02, 1.04419e-01, 2.7454e-02, 2.5853e-02, 1.9552e-02, 2.8323e-02, 7.7960e-03, -1.3320e-03,
       8.6410e-03},
      {1.225946, -1.1953e-02, 4.1065e-02, -3.8437e-02, 3.5549e-02, 2.9474e-02, 8.6270e-03, -2.1170e-03, -4.0370e-03,
       2.2900e-04},
      {1.666555, 6.0149e-02, -1.4117e-02, -1.0517e-02, 1.9640e-03, 4.3540e-03, 5.4330e-03, 1.0900e-04, -1.1580e-03,
       3.4100e-04},
      {7.35522e-01, 1.0517e-02, -4.252e-03, 6.1597e-02, 1.2516e-02, 1.0027e-02, 4.8150e-03, -4.2800e-04, -1.1960e-03,
       -7.4100e-04}};
  KinematicsData kd(dh), ku(urdf);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::VectorXd theta(7);
    for (int j = 0; j < 7; ++j) {
      std::uniform_real_distribution<double> u(dh.joint(j).lower, dh.joint(j).upper);
      theta(j) = u(rng);
    }
    compute_kinematics(dh, theta, kd);
    compute_kinematics(urdf, theta, ku);
    Inertia a, b;
    for (int j = 0; j < 7; ++j) {
      ASSERT_TRUE(dh.joint(j).inertia.has_value()) << j;
      const Inertia from_file = dh.joint(j).inertia->moved(kd.link_frames[static_cast<std::size_t>(j)]);
      Inertia own;
      own.mass = maker[j][0];
      own.com = Eigen::Vector3d(maker[j][1], maker[j][2], maker[j][3]);
      own.tensor << maker[j][4], maker[j][7], maker[j][8], maker[j][7], maker[j][5], maker[j][9], maker[j][8],
          maker[j][9], maker[j][6];
      const Inertia from_maker = own.moved(ku.link_frames[static_cast<std::size_t>(j)]);
      a = j == 0 ? from_file : a.combined(from_file);
      b = j == 0 ? from_maker : b.combined(from_maker);
    }
    EXPECT_NEAR(a.mass, 16.062132, 1e-9);
    EXPECT_LE((a.com - b.com).norm(), 1e-9) << "trial " << trial;
    EXPECT_LE((a.tensor - b.tensor).cwiseAbs().maxCoeff(), 1e-9) << "trial " << trial;
  }
}

// A [[links]] entry's `inertia` replaces one URDF link's <inertial> (here the xArm6's impossible link 2 tensor, whose
// warning goes with it); the other links keep the URDF's, and an impossible one given here is an error.
TEST(Inertia, ALinksEntryReplacesAUrdfLinksInertial) {
  const auto dir = scratch_dir("inertia_links");
  const RobotModel shipped = load_robot(source_path("robots/xarm6.toml"));
  const std::string head = "urdf = \"" + source_path("robots/xarm6_description/xarm6_robot.urdf").string() +
                           "\"\nbase_link = \"link_base\"\ntip_link = \"link6\"\ncollision_model = \"none\"\n";
  std::ofstream(dir / "good.toml") << head
                                   << "[[links]]\nname = \"link2\"\ninertia = { mass = 2.0, com = [0.1, 0.0, 0.0], "
                                      "ixx = 0.01, iyy = 0.02, izz = 0.02 }\n";
  const RobotModel robot = load_robot(dir / "good.toml");
  ASSERT_TRUE(robot.joint(1).inertia);
  EXPECT_EQ(robot.joint(1).inertia->mass, 2.0);
  EXPECT_LE((robot.joint(1).inertia->com - Eigen::Vector3d(0.1, 0.0, 0.0)).norm(), 1e-15);
  EXPECT_EQ(robot.joint(1).inertia_warning, "");
  ASSERT_TRUE(robot.joint(0).inertia);
  EXPECT_EQ(robot.joint(0).inertia->mass, shipped.joint(0).inertia->mass);
  std::ofstream(dir / "bad.toml") << head
                                  << "[[links]]\nname = \"link2\"\ninertia = { mass = 2.0, ixx = 0.01, iyy = 0.01, "
                                     "izz = 0.03 }\n";
  try {
    (void)load_robot(dir / "bad.toml");
    FAIL() << "expected an error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("triangle"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bad.toml:7:"), std::string::npos) << e.what();
  }
}
}  // namespace
}  // namespace redres

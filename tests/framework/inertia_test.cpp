// Mass properties (issue 26): Inertia::moved and combined against bodies made of point masses, the physical checks,
// the URDF's <inertial> elements gathered per moving link (side branches included), and the robot file's `inertia`.

#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

#include <gtest/gtest.h>

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
  const RobotModel dh = load_robot(source_path("robots/franka_panda.toml"));
  EXPECT_FALSE(dh.joint(0).inertia);
}

TEST(Inertia, TheRobotFileGivesThemPerJointAndRefusesImpossibleOnes) {
  const auto dir = scratch("inertia_file");
  std::filesystem::create_directories(dir);
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

}  // namespace
}  // namespace redres

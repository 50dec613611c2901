// Mesh collision elements (issue 26): finding the files, reading them through Assimp, fitting capsules that enclose
// every vertex (and are no larger than they must be), all unusable meshes reported at once, and the makers' Panda
// and xArm6 loaded with no hand-written shape.

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "redres/model/kinematics.hpp"
#include "redres/model/mesh.hpp"
#include "redres/parsers/mesh_file.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "shape_samples.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

using testing::cube_obj;

namespace fs = std::filesystem;

// Distance from p to the segment [a, b].
double to_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = ab.squaredNorm() > 0.0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

// The capsule's axis ends (a sphere: its centre twice) in the shape's own frame, and its radius.
void ends(const ShapeSpec& s, Eigen::Vector3d& a, Eigen::Vector3d& b) {
  if (s.shape == ShapeSpec::Kind::kSphere) {
    a = b = Eigen::Vector3d(s.xyz[0], s.xyz[1], s.xyz[2]);
    return;
  }
  a = Eigen::Vector3d((*s.from)[0], (*s.from)[1], (*s.from)[2]);
  b = Eigen::Vector3d((*s.to)[0], (*s.to)[1], (*s.to)[2]);
}

TEST(FitCapsule, EnclosesEveryVertexAndIsTight) {
  std::mt19937 rng(26);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d scale(0.2 + 0.3 * std::abs(g(rng)), 0.05 + 0.05 * std::abs(g(rng)), 0.03);
    const Eigen::Matrix3d rot = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
    std::vector<Eigen::Vector3d> v;
    for (int k = 0; k < 40; ++k) v.push_back(rot * Eigen::Vector3d(g(rng), g(rng), g(rng)).cwiseProduct(scale));
    const ShapeSpec s = fit_capsule(v);
    Eigen::Vector3d a, b;
    ends(s, a, b);
    const double r = *s.radius;
    double farthest = 0.0;
    for (const auto& p : v) {
      const double d = to_segment(p, a, b);
      EXPECT_LE(d, r) << "trial " << trial;
      farthest = std::max(farthest, d);
    }
    EXPECT_NEAR(farthest, r, 1e-9 * (1.0 + r)) << "some vertex is on the surface";
    // Tight ends: shortening the segment by 1e-6 at either end leaves a vertex out.
    if (s.shape == ShapeSpec::Kind::kCapsule) {
      const Eigen::Vector3d u = (b - a).normalized();
      for (const bool at_a : {true, false}) {
        const Eigen::Vector3d a2 = at_a ? Eigen::Vector3d(a + 1e-6 * u) : a,
                              b2 = at_a ? b : Eigen::Vector3d(b - 1e-6 * u);
        double worst = 0.0;
        for (const auto& p : v) worst = std::max(worst, to_segment(p, a2, b2));
        EXPECT_GT(worst, r) << "trial " << trial << (at_a ? ": end a" : ": end b") << " could be shorter";
      }
    }
  }
}

TEST(FitCapsule, ARadiusNoLargerThanTheSmallestCircleAcrossTheAxis) {
  // Points on a circle of radius 0.1 around the z axis, spread along z: the capsule is that circle, exactly.
  std::vector<Eigen::Vector3d> v;
  for (int level = 0; level < 5; ++level) {
    for (int k = 0; k < 12; ++k) {
      const double a = k * 2.0 * M_PI / 12;
      v.emplace_back(0.1 * std::cos(a), 0.1 * std::sin(a), -0.5 + 0.25 * level);
    }
  }
  const ShapeSpec s = fit_capsule(v);
  EXPECT_EQ(s.shape, ShapeSpec::Kind::kCapsule);
  EXPECT_NEAR(*s.radius, 0.1, 1e-9);
}

TEST(Mesh, ReadThroughAssimpScaledWithItsPieces) {
  const fs::path dir = scratch_dir("mesh_read");
  std::ofstream(dir / "two.obj") << cube_obj("a", Eigen::Vector3d(0, 0, 0), 0)
                                 << cube_obj("b", Eigen::Vector3d(5, 0, 0), 8);
  const MeshData m = read_mesh(dir / "two.obj", Eigen::Vector3d(0.5, 1.0, 2.0));
  ASSERT_EQ(m.pieces.size(), 2u);
  EXPECT_EQ(m.vertex_count(), 16u);
  double max_x = -1e9, max_z = -1e9;
  for (const auto& piece : m.pieces) {
    for (const auto& p : piece) {
      max_x = std::max(max_x, p.x());
      max_z = std::max(max_z, p.z());
    }
  }
  EXPECT_NEAR(max_x, 3.0, 1e-6);  // (5 + 1) * 0.5
  EXPECT_NEAR(max_z, 2.0, 1e-6);  // 1 * 2
  EXPECT_THROW((void)read_mesh(dir / "missing.obj", Eigen::Vector3d::Ones()), std::runtime_error);
  std::ofstream(dir / "junk.obj") << "this is not a mesh\n";
  EXPECT_THROW((void)read_mesh(dir / "junk.obj", Eigen::Vector3d::Ones()), std::runtime_error);
}

TEST(Mesh, PackagePathsAreSearchedInOrderAndAMissingMeshSaysWhere) {
  const fs::path dir = scratch("mesh_resolve");
  fs::create_directories(dir / "named" / "m");
  fs::create_directories(dir / "env" / "pkg" / "m");
  fs::create_directories(dir / "urdf" / "pkg" / "m");
  for (const fs::path& p : {dir / "named" / "m" / "x.obj", dir / "env" / "pkg" / "m" / "x.obj",
                            dir / "urdf" / "pkg" / "m" / "x.obj", dir / "urdf" / "rel.obj"}) {
    std::ofstream(p) << "v 0 0 0\n";
  }
  PackagePaths packages;
  EXPECT_EQ(resolve_mesh("package://pkg/m/x.obj", dir / "urdf", packages), dir / "urdf" / "pkg" / "m" / "x.obj");
  ::setenv("REDRES_PACKAGE_PATH", (dir / "env").c_str(), 1);
  EXPECT_EQ(resolve_mesh("package://pkg/m/x.obj", dir / "urdf", packages), dir / "env" / "pkg" / "m" / "x.obj");
  packages.named["pkg"] = dir / "named";
  EXPECT_EQ(resolve_mesh("package://pkg/m/x.obj", dir / "urdf", packages), dir / "named" / "m" / "x.obj");
  ::unsetenv("REDRES_PACKAGE_PATH");
  EXPECT_EQ(resolve_mesh("rel.obj", dir / "urdf", packages), dir / "urdf" / "rel.obj");
  EXPECT_EQ(resolve_mesh("file://" + (dir / "urdf" / "rel.obj").string(), dir, packages), dir / "urdf" / "rel.obj");
  try {
    (void)resolve_mesh("package://nowhere/a.stl", dir / "urdf", packages);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("not found"), std::string::npos) << what;
    EXPECT_NE(what.find((dir / "urdf" / "nowhere" / "a.stl").string()), std::string::npos) << what;
    EXPECT_NE(what.find("packages"), std::string::npos) << what;
  }
}

TEST(Mesh, EveryUnusableMeshIsReportedAtOnce) {
  const fs::path dir = scratch_dir("mesh_many");
  std::ofstream(dir / "arm.urdf") << R"(<robot name="arm">
  <link name="base"/>
  <link name="l1"><collision><geometry><mesh filename="package://gone/l1.stl"/></geometry></collision></link>
  <link name="l2"><collision><geometry><mesh filename="l2_missing.obj"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>)";
  std::ofstream(dir / "arm.toml") << "urdf = \"arm.urdf\"\nbase_link = \"base\"\ntip_link = \"l2\"\n";
  try {
    (void)load_robot(dir / "arm.toml");
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("2 meshes"), std::string::npos) << what;
    EXPECT_NE(what.find("link 'l1'"), std::string::npos) << what;
    EXPECT_NE(what.find("link 'l2'"), std::string::npos) << what;
    EXPECT_NE(what.find("collision_model"), std::string::npos) << what;
  }
  // collision_model = "none": the same robot loads, without shapes (kinematics only).
  std::ofstream(dir / "arm.toml") << "urdf = \"arm.urdf\"\nbase_link = \"base\"\ntip_link = \"l2\"\n"
                                     "collision_model = \"none\"\n";
  const RobotModel robot = load_robot(dir / "arm.toml");
  EXPECT_EQ(robot.link_shapes().size(), 0u);
}

// The makers' Panda: every shape is a fitted capsule that encloses its mesh, and the kinematics are those of the
// hand-written URDF Panda (the same frames): to 1e-11 as published, whose rpy round pi/2 to 1.57079632679 (4.9e-12
// rad off), and to 1e-12 with pi/2 written in full.
TEST(Mesh, TheMakersPandaHasCapsulesAroundItsMeshesAndTheSameKinematics) {
  const RobotModel meshes = load_robot(source_path("robots/franka_panda_meshes.toml"));
  const RobotModel reference = load_robot(source_path("robots/franka_panda_urdf.toml"));
  ASSERT_EQ(meshes.dof(), 7);
  EXPECT_EQ(meshes.link_shapes().size(), 10u);  // links 1-7, the hand and two fingers
  for (const auto& shape : meshes.link_shapes()) EXPECT_EQ(shape.spec.shape, ShapeSpec::Kind::kCapsule);
  // Link 1's capsule encloses every vertex of link1.obj (the link frame is the URDF's).
  const MeshData link1 =
      read_mesh(source_path("robots/franka_panda_description/meshes/collision/link1.obj"), Eigen::Vector3d::Ones());
  const auto& s = meshes.link_shapes().front();
  Eigen::Vector3d a, b;
  ends(s.spec, a, b);
  for (const auto& piece : link1.pieces) {
    for (const auto& p : piece) EXPECT_LE(to_segment(p, a, b), *s.spec.radius + 1e-12);
  }
  // The published URDF with pi/2 in full (and no meshes: kinematics only).
  const fs::path dir = scratch_dir("mesh_panda_pi");
  std::string urdf = read_text(source_path("robots/franka_panda_description/panda.urdf"));
  for (std::size_t at = urdf.find("1.57079632679"); at != std::string::npos; at = urdf.find("1.57079632679", at + 18)) {
    urdf.replace(at, 13, "1.5707963267948966");
  }
  std::ofstream(dir / "panda.urdf") << urdf;
  std::ofstream(dir / "panda.toml")
      << "urdf = \"panda.urdf\"\nbase_link = \"panda_link0\"\ntip_link = \"panda_link8\"\n"
         "collision_model = \"none\"\n";
  const RobotModel full = load_robot(dir / "panda.toml");
  std::mt19937 rng(8);
  KinematicsData km(meshes), kr(reference), kf(full);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::VectorXd theta = random_inside(meshes, rng, 0.1);
    compute_kinematics(meshes, theta, km, KinematicsLevel::kJacobian);
    compute_kinematics(reference, theta, kr, KinematicsLevel::kJacobian);
    compute_kinematics(full, theta, kf, KinematicsLevel::kJacobian);
    EXPECT_LE((km.f - kr.f).cwiseAbs().maxCoeff(), 1e-11);
    EXPECT_LE((km.J - kr.J).cwiseAbs().maxCoeff(), 1e-11);
    EXPECT_LE((kf.f - kr.f).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LE((kf.J - kr.J).cwiseAbs().maxCoeff(), 1e-12);
  }
}

// A bare URDF: from the root to the arm's tip (the most revolute joints; the gripper's fingers, prismatic and mimic,
// left out; then the deepest link: the Panda's grasp target, 0.105 m below the flange), or the links asked for.
TEST(Mesh, ABareUrdfLoadsFromTheRootToTheArmsTip) {
  const fs::path urdf = source_path("robots/franka_panda_description/panda.urdf");
  const RobotModel robot = load_urdf_robot(urdf);
  ASSERT_EQ(robot.dof(), 7);
  EXPECT_EQ(robot.joint(6).name, "panda_joint7");
  KinematicsData k(robot);
  compute_kinematics(robot, Eigen::VectorXd::Zero(7), k, KinematicsLevel::kPosition);
  EXPECT_NEAR(k.ee_pose.translation().z(), 0.926 - 0.105, 1e-12);
  const RobotModel flange = load_urdf_robot(urdf, "panda_link0", "panda_link8");
  KinematicsData kf(flange);
  compute_kinematics(flange, Eigen::VectorXd::Zero(7), kf, KinematicsLevel::kPosition);
  EXPECT_NEAR(kf.ee_pose.translation().z(), 0.926, 1e-12);
  EXPECT_EQ(load_urdf_robot(source_path("robots/xarm6_description/xarm6_robot.urdf")).dof(), 6);
  EXPECT_THROW((void)load_urdf_robot(urdf, "panda_link0", "no_such_link"), std::exception);
}

TEST(Mesh, TheMakersXarm6LoadsWithACapsulePerLink) {
  const RobotModel robot = load_robot(source_path("robots/xarm6.toml"));
  EXPECT_EQ(robot.dof(), 6);
  EXPECT_EQ(robot.link_shapes().size(), 6u);
  for (const auto& shape : robot.link_shapes()) {
    EXPECT_GT(*shape.spec.radius, 0.02);
    EXPECT_LT(*shape.spec.radius, 0.15);
  }
}

}  // namespace
}  // namespace redres

namespace redres {
namespace {

// Visual elements (drawn by `redres view` only): the base's links and the chain's, posed in their frames, their
// materials' colours, and a visual mesh that cannot be found is noted, never an error (nothing is computed from it).
TEST(Mesh, VisualElementsArePosedInTheirFramesAndAMissingOneIsOnlyNoted) {
  const fs::path dir = scratch_dir("mesh_visuals");
  std::ofstream(dir / "cube.obj") << cube_obj("a", Eigen::Vector3d(0, 0, 0), 0);
  std::ofstream(dir / "arm.urdf") << R"(<robot name="arm">
  <material name="red"><color rgba="1 0 0 1"/></material>
  <link name="base"><visual><geometry><box size="0.2 0.2 0.1"/></geometry></visual></link>
  <link name="plate"><visual><origin xyz="0 0 0.05"/><geometry><cylinder radius="0.1" length="0.02"/></geometry>
    <material name="red"/></visual></link>
  <link name="l1"><visual><origin xyz="0 0 0.1" rpy="0 0 1.5707963267948966"/>
    <geometry><mesh filename="cube.obj" scale="0.5 0.5 0.5"/></geometry></visual></link>
  <link name="l2"><visual><geometry><mesh filename="package://gone/l2.stl"/></geometry></visual>
    <visual><geometry><sphere radius="0.03"/></geometry></visual></link>
  <joint name="fix" type="fixed"><parent link="base"/><child link="plate"/><origin xyz="0 0 0.1"/></joint>
  <joint name="j1" type="revolute"><parent link="plate"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>)";
  std::ofstream(dir / "arm.toml") << "urdf = \"arm.urdf\"\nbase_link = \"base\"\ntip_link = \"l2\"\n";
  const RobotModel robot = load_robot(dir / "arm.toml");
  const auto& v = robot.visuals();
  ASSERT_EQ(v.size(), 5U);
  // The base's two, in the base frame: the box at its origin, the plate 0.1 + 0.05 up, red.
  EXPECT_EQ(v[0].joint, -1);
  EXPECT_EQ(v[0].kind, VisualSpec::Kind::kBox);
  EXPECT_EQ(v[1].joint, -1);
  EXPECT_EQ(v[1].link, "plate");
  EXPECT_NEAR(v[1].pose.translation().z(), 0.15, 1e-15);
  ASSERT_TRUE(v[1].rgba.has_value());
  EXPECT_EQ((*v[1].rgba)[0], 1.0);
  // l1's mesh, found beside the URDF (an absolute path, for a viewer run from elsewhere), in joint 1's frame.
  EXPECT_EQ(v[2].joint, 0);
  EXPECT_EQ(v[2].kind, VisualSpec::Kind::kMesh);
  EXPECT_EQ(v[2].file, fs::absolute(dir / "cube.obj"));
  EXPECT_TRUE(v[2].file.is_absolute());
  EXPECT_NEAR(v[2].pose.translation().z(), 0.1, 1e-15);
  EXPECT_NEAR((v[2].pose.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-12);
  // l2's mesh is not found: noted, with where it was looked for; its sphere is kept.
  EXPECT_EQ(v[3].joint, 1);
  EXPECT_TRUE(v[3].file.empty());
  EXPECT_NE(v[3].problem.find("not found"), std::string::npos) << v[3].problem;
  EXPECT_EQ(v[4].kind, VisualSpec::Kind::kSphere);
  EXPECT_EQ(v[4].radius, 0.03);
  // The mesh for drawing: its 12 triangles, scaled.
  const DrawMesh m = read_draw_mesh(v[2].file, v[2].scale);
  EXPECT_EQ(m.triangles(), 12U);
  float top = -1e9F;
  for (const auto& part : m.parts) {
    for (std::size_t i = 2; i < part.positions.size(); i += 3) top = std::max(top, part.positions[i]);
    for (const std::uint32_t i : part.indices) EXPECT_LT(i, part.positions.size() / 3);
  }
  EXPECT_NEAR(top, 0.5F, 1e-6F);
  EXPECT_THROW((void)read_draw_mesh(dir / "none.obj", Eigen::Vector3d::Ones()), std::runtime_error);
}

}  // namespace
}  // namespace redres

// Robots from URDF (urdfdom): the shipped URDF robots (robots/franka_panda_urdf.toml, robots/kuka_iiwa14_urdf.toml)
// are their DH twins (robots/franka_panda.toml, robots/kuka_iiwa14.toml): the same position rows and Jacobian (and w
// for the Panda) at 1000 random configurations, and the same capsules in the world.
// The URDF's own primitive collision elements are read when no [[links]] entry replaces them. Every kind of bad URDF
// is a ConfigError naming the robot file's `urdf` key, the URDF file and the element.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

// The world end points of a capsule of `robot` at the configuration in `k`.
std::pair<Eigen::Vector3d, Eigen::Vector3d> capsule_in_world(const RobotModel& robot, const KinematicsData& k,
                                                             std::size_t s) {
  const auto& shape = robot.link_shapes()[s];
  const Eigen::Isometry3d T = k.link_frames[static_cast<std::size_t>(shape.link)] * shape.pose;
  const Eigen::Vector3d half = T.linear().col(2) * (0.5 * shape.spec.axis_length());
  return {T.translation() - half, T.translation() + half};
}

class UrdfRobots : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

// Each shipped URDF robot is its DH twin: the flange frame (position and orientation), the position rows' Jacobian
// and the capsules in the world agree.
TEST_P(UrdfRobots, TheUrdfRobotIsItsDhTwin) {
  const RobotModel dh = load_robot(source_path(GetParam().first));
  const RobotModel urdf = load_robot(source_path(GetParam().second));
  ASSERT_EQ(urdf.dof(), 7);
  ASSERT_EQ(urdf.link_shapes().size(), dh.link_shapes().size());
  KinematicsData a(dh), b(urdf);
  std::mt19937 rng(21);
  double worst_f = 0.0, worst_j = 0.0, worst_r = 0.0, worst_w = 0.0, worst_w_abs = 0.0, worst_shape = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const Eigen::VectorXd theta = random_inside(dh, rng);
    compute_kinematics(dh, theta, a, KinematicsLevel::kManipulability);
    compute_kinematics(urdf, theta, b, KinematicsLevel::kManipulability);
    worst_f = std::max(worst_f, (a.f.head(3) - b.f.head(3)).cwiseAbs().maxCoeff());
    worst_j = std::max(worst_j, (a.J.topRows(3) - b.J.topRows(3)).cwiseAbs().maxCoeff());
    worst_r = std::max(worst_r, (a.ee_pose.linear() - b.ee_pose.linear()).cwiseAbs().maxCoeff());
    if (dh.task() == urdf.task() && dh.task() == TaskRows::kPosition) {
      worst_w = std::max(worst_w, std::abs(a.w - b.w) / (1e-12 + a.w));
      worst_w_abs = std::max(worst_w_abs, std::abs(a.w - b.w));
    }
    for (std::size_t s = 0; s < dh.link_shapes().size(); ++s) {
      ASSERT_EQ(urdf.link_shapes()[s].link, dh.link_shapes()[s].link);
      ASSERT_EQ(urdf.link_shapes()[s].spec.radius, dh.link_shapes()[s].spec.radius);
      const auto [p0, p1] = capsule_in_world(dh, a, s);
      const auto [q0, q1] = capsule_in_world(urdf, b, s);
      worst_shape = std::max({worst_shape, (p0 - q0).norm(), (p1 - q1).norm()});
    }
  }
  const auto sci = [](double v) {
    std::ostringstream out;
    out << std::scientific << std::setprecision(2) << v;
    return out.str();
  };
  RecordProperty("max_f_difference", sci(worst_f));
  RecordProperty("max_J_difference", sci(worst_j));
  RecordProperty("max_flange_rotation_difference", sci(worst_r));
  RecordProperty("max_w_difference", sci(worst_w_abs));
  RecordProperty("max_w_relative_difference", sci(worst_w));
  RecordProperty("max_capsule_end_difference", sci(worst_shape));
  EXPECT_LE(worst_f, 1e-12);
  EXPECT_LE(worst_j, 1e-12);
  EXPECT_LE(worst_r, 1e-12);
  EXPECT_LE(worst_w_abs, 1e-12);
  EXPECT_LE(worst_w, 1e-10);
  EXPECT_LE(worst_shape, 1e-12);
  for (int i = 0; i < dh.dof(); ++i) {
    for (int j = 0; j < dh.dof(); ++j) EXPECT_EQ(urdf.self_collision_pair(i, j), dh.self_collision_pair(i, j));
  }
}

INSTANTIATE_TEST_SUITE_P(Shipped, UrdfRobots,
                         ::testing::Values(std::pair{"robots/franka_panda.toml", "robots/franka_panda_urdf.toml"},
                                           std::pair{"robots/kuka_iiwa14.toml", "robots/kuka_iiwa14_urdf.toml"}));

// The UR5e (robots/ur5e.toml, from its URDF written from UR's DH table): six joints for a 3-D position task (three
// degrees of redundancy); at theta = 0 its flange sits at (a2 + a3, -(d4 + d6), d1 - d5), the published zero pose.
TEST(Urdf, TheUr5eIsRedundantForItsPositionTaskAndHasItsZeroPose) {
  const RobotModel ur = load_robot(source_path("robots/ur5e.toml"));
  ASSERT_EQ(ur.dof(), 6);
  ASSERT_EQ(ur.task_dim(), 3);
  KinematicsData k(ur);
  compute_kinematics(ur, Eigen::VectorXd::Zero(6), k, KinematicsLevel::kPosition);
  EXPECT_LE((k.f - Eigen::Vector3d(-0.425 - 0.3922, -(0.1333 + 0.0996), 0.1625 - 0.0997)).norm(), 1e-12);
  compute_kinematics(ur, ur.home(), k, KinematicsLevel::kManipulability);
  EXPECT_GT(k.w, 1e-3);
  EXPECT_EQ(ur.link_shapes().size(), 6u);
}

// A scratch directory with a URDF and a robot file that names it.
struct Files {
  std::filesystem::path dir;
  explicit Files(const std::string& name) : dir(std::filesystem::temp_directory_path() / ("redres_urdf_" + name)) {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  ~Files() { std::filesystem::remove_all(dir); }
  std::filesystem::path write(const std::string& file, const std::string& text) const {
    std::ofstream(dir / file) << text;
    return dir / file;
  }
};

const char* const kTwoLinkUrdf = R"(<?xml version="1.0"?>
<robot name="two">
  <link name="base"/>
  <link name="l1">
    <collision><origin xyz="0 0 0.1" rpy="0 0 0"/><geometry><cylinder radius="0.03" length="0.2"/></geometry></collision>
  </link>
  <link name="l2">
    <collision><origin xyz="0.05 0 0" rpy="0 1.5707963267948966 0"/><geometry><box size="0.1 0.02 0.02"/></geometry></collision>
  </link>
  <link name="tool">
    <collision><origin xyz="0 0 0" rpy="0 0 0"/><geometry><sphere radius="0.02"/></geometry></collision>
  </link>
  <joint name="a" type="revolute">
    <parent link="base"/><child link="l1"/><origin xyz="0 0 0.2" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="2" effort="1"/>
  </joint>
  <joint name="b" type="revolute">
    <parent link="l1"/><child link="l2"/><origin xyz="0 0 0.2" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" velocity="3" effort="1"/>
  </joint>
  <joint name="t" type="fixed">
    <parent link="l2"/><child link="tool"/><origin xyz="0.1 0 0" rpy="0 0 0"/>
  </joint>
</robot>
)";

const char* const kRobot = R"(urdf = "two.urdf"
base_link = "base"
tip_link = "tool"
)";

TEST(Urdf, PrimitivesLimitsAndTheFoldedToolComeFromTheUrdf) {
  const Files f("primitives");
  f.write("two.urdf", kTwoLinkUrdf);
  const RobotModel robot = load_robot(f.write("two.toml", kRobot));
  EXPECT_EQ(robot.name(), "two");
  ASSERT_EQ(robot.dof(), 2);
  EXPECT_EQ(robot.axis(1), Eigen::Vector3d::UnitY());
  EXPECT_EQ(robot.upper_limits()(1), 1.0);
  Eigen::VectorXd lo(2), hi(2);
  robot.velocity_limits(Eigen::Vector2d::Zero(), lo, hi);
  EXPECT_EQ(hi(1), 3.0);
  EXPECT_EQ(lo(0), -2.0);
  // Three shapes: l1's cylinder and l2's box ride on joints a and b; the tool's sphere rides on b, 0.1 m out.
  ASSERT_EQ(robot.link_shapes().size(), 3u);
  const auto& cylinder = robot.link_shapes()[0];
  EXPECT_EQ(cylinder.spec.shape, ShapeSpec::Kind::kCylinder);
  EXPECT_EQ(cylinder.link, 0);
  EXPECT_EQ(*cylinder.spec.radius, 0.03);
  EXPECT_EQ(*cylinder.spec.length, 0.2);
  EXPECT_LE(
      (cylinder.pose.matrix() - Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.1)).matrix()).cwiseAbs().maxCoeff(),
      1e-15);
  // The box is turned by pitch pi/2 (rpy through the gimbal-lock branch): its local x axis points along -z.
  const auto& box = robot.link_shapes()[1];
  EXPECT_EQ(box.spec.shape, ShapeSpec::Kind::kBox);
  EXPECT_EQ(box.link, 1);
  EXPECT_LE((box.pose.translation() - Eigen::Vector3d(0.05, 0, 0)).norm(), 1e-15);
  EXPECT_LE((box.pose.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d(0, 0, -1)).norm(), 1e-12);
  EXPECT_LE((box.pose.linear() * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_EQ(robot.link_shapes()[2].link, 1);
  EXPECT_LE((robot.link_shapes()[2].pose.translation() - Eigen::Vector3d(0.1, 0, 0)).norm(), 1e-15);
  KinematicsData k(robot);
  compute_kinematics(robot, Eigen::Vector2d(0.3, 0.5), k, KinematicsLevel::kPosition);
  // Tool at 0.1 m along l2's x axis: joint b turns about y, so x tilts down by 0.5 rad; joint a turns about z.
  const Eigen::Vector3d tool(0.1 * std::cos(0.5) * std::cos(0.3), 0.1 * std::cos(0.5) * std::sin(0.3),
                             0.4 - 0.1 * std::sin(0.5));
  EXPECT_LE((k.f - tool).norm(), 1e-15);
}

struct BadUrdf {
  const char* what;
  std::string urdf;         // the URDF text ("" = no file at all)
  std::string robot_extra;  // appended to the robot file
  std::vector<std::string> says;
};

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

TEST(Urdf, BadUrdfsAreErrorsNamingTheFileAndTheElement) {
  const std::string good = kTwoLinkUrdf;
  const std::vector<BadUrdf> cases = {
      {"missing file", "", "", {"two.urdf: URDF file does not exist"}},
      {"joint names a missing link",
       replace(good, R"(<parent link="l1"/>)", R"(<parent link="nowhere"/>)"),
       "",
       {"two.urdf: not a valid URDF", "nowhere"}},
      {"tip not below base", good, "", {}},  // replaced below: base_link below the tip
      {"floating joint",
       replace(good, R"(name="b" type="revolute")", R"(name="b" type="floating")"),
       "",
       {"joint 'b' is a floating joint"}},
      {"mimic joint",
       replace(good, R"(<axis xyz="0 1 0"/>)", R"(<axis xyz="0 1 0"/><mimic joint="a"/>)"),
       "",
       {"joint 'b' is a mimic of joint 'a', which is on the chain", "not supported"}},
      {"mesh",
       replace(good, R"(<box size="0.1 0.02 0.02"/>)", R"(<mesh filename="l2.stl"/>)"),
       "",
       {"link 'l2'", "mesh 'l2.stl' not found", "[[links]]", "collision_model"}},
      {"continuous without limits",
       replace(good, R"(name="a" type="revolute")", R"(name="a" type="continuous")"),
       "",
       {"joint 'a' is continuous", "give its `limits`"}},
      {"no velocity limit",
       replace(good, R"(velocity="3")", R"(velocity="0")"),
       "",
       {"joint 'b'", "has no velocity limit"}},
      {"unknown joint override", good, "[[joints]]\nname = \"zz\"\n", {"no moving joint named 'zz'"}},
      {"unknown link override",
       good,
       "[[links]]\nname = \"base\"\n",
       {"no link named 'base' that moves", "those are 'l1', 'l2', 'tool'", "the file's links are 'base', 'l1'"}},
      {"unreadable collision geometry",
       replace(good, R"(<cylinder radius="0.03" length="0.2"/>)", R"(<cylinder radius="q"/>)"),
       "",
       {"two.urdf: urdfdom could not read all of it", "Link [l1]"}},
  };
  for (const BadUrdf& c : cases) {
    SCOPED_TRACE(c.what);
    const Files f("bad");
    if (!c.urdf.empty()) f.write("two.urdf", c.urdf);
    std::string robot = std::string(kRobot) + c.robot_extra;
    std::vector<std::string> says = c.says;
    if (std::string(c.what) == "tip not below base") {
      robot = replace(replace(robot, "base_link = \"base\"", "base_link = \"l2\""), "tip_link = \"tool\"",
                      "tip_link = \"l1\"");
      says = {"link 'l1' (tip_link) is not below link 'l2' (base_link)"};
    }
    const auto file = f.write("two.toml", robot);
    try {
      (void)load_robot(file);
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(file.string() + ":", 0), 0u) << what;
      for (const std::string& s : says)
        EXPECT_NE(what.find(s), std::string::npos) << "missing '" << s << "' in: " << what;
    }
  }
}

// A side branch (a camera on a fixed joint, and a finger on a prismatic joint, both hanging from l2 beside the tool)
// rides on the link it hangs from: its shapes are placed there, the finger at its joint's position 0.
TEST(Urdf, SideBranchesRideOnTheLinkTheyHangFrom) {
  const Files f("branch");
  const std::string branch = R"(  <link name="camera">
    <collision><origin xyz="0 0 0.01" rpy="0 0 0"/><geometry><sphere radius="0.015"/></geometry></collision>
  </link>
  <link name="finger">
    <collision><origin xyz="0 0 0.02" rpy="0 0 0"/><geometry><sphere radius="0.01"/></geometry></collision>
  </link>
  <joint name="cam" type="fixed">
    <parent link="l2"/><child link="camera"/><origin xyz="0 0.05 0" rpy="0 0 0"/>
  </joint>
  <joint name="fing" type="prismatic">
    <parent link="camera"/><child link="finger"/><origin xyz="0.03 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.04" velocity="0.1" effort="1"/>
  </joint>
</robot>)";
  f.write("two.urdf", replace(kTwoLinkUrdf, "</robot>", branch));
  const RobotModel robot = load_robot(f.write("two.toml", kRobot));
  ASSERT_EQ(robot.dof(), 2);  // the finger's joint is not part of the chain
  ASSERT_EQ(robot.link_shapes().size(), 5u);
  std::vector<Eigen::Vector3d> on_l2;
  for (const auto& shape : robot.link_shapes()) {
    if (shape.link == 1 && shape.spec.shape == ShapeSpec::Kind::kSphere) on_l2.push_back(shape.pose.translation());
  }
  ASSERT_EQ(on_l2.size(), 3u);  // the tool's sphere, the camera's and the finger's
  const auto has = [&](const Eigen::Vector3d& p) {
    return std::any_of(on_l2.begin(), on_l2.end(), [&](const Eigen::Vector3d& q) { return (q - p).norm() < 1e-15; });
  };
  EXPECT_TRUE(has(Eigen::Vector3d(0.0, 0.05, 0.01)));
  EXPECT_TRUE(has(Eigen::Vector3d(0.03, 0.05, 0.02)));
}

TEST(Urdf, JointOverridesReplaceLimitsAndLaws) {
  const Files f("override");
  f.write("two.urdf", replace(kTwoLinkUrdf, R"(name="a" type="revolute")", R"(name="a" type="continuous")"));
  const RobotModel robot = load_robot(f.write("two.toml", std::string(kRobot) + R"(
[[joints]]
name = "a"
limits = [-1.2, 1.2]
velocity_limit = { type = "push_rod", a = 0.1, b = 0.2, s = 0.1, sigma_min = -0.05, sigma_max = 0.05 }
)"));
  EXPECT_EQ(robot.upper_limits()(0), 1.2);
  EXPECT_EQ(robot.joint(0).velocity_limit->type(), "push_rod");
}

// The message of loading a robot file that names `urdf` (an absolute path) from `base` to `tip`; "" if it loads.
std::string load_error(const Files& f, const std::filesystem::path& urdf, const std::string& base,
                       const std::string& tip) {
  const auto file = f.write(
      "robot.toml", "urdf = \"" + urdf.string() + "\"\nbase_link = \"" + base + "\"\ntip_link = \"" + tip + "\"\n");
  try {
    (void)load_robot(file);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

// `count` moving joints in a chain l0 -> l1 -> ... (each 0.01 m along x), with `branch` fixed links hanging from
// l1 in a line, and `extra` text before </robot>.
std::string generated_urdf(int count, int branch, const std::string& extra = "") {
  std::string x = "<?xml version=\"1.0\"?>\n<robot name=\"generated\">\n<link name=\"l0\"/>\n";
  for (int k = 1; k <= count; ++k) {
    x += "<link name=\"l" + std::to_string(k) + "\"/>\n<joint name=\"j" + std::to_string(k) +
         "\" type=\"revolute\"><origin xyz=\"0.01 0 0\"/><parent link=\"l" + std::to_string(k - 1) +
         "\"/><child link=\"l" + std::to_string(k) +
         "\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" velocity=\"1\" effort=\"1\"/></joint>\n";
  }
  for (int k = 1; k <= branch; ++k) {
    x += "<link name=\"s" + std::to_string(k) +
         "\"><collision><geometry><sphere radius=\"0.01\"/></geometry></collision></link>\n<joint name=\"f" +
         std::to_string(k) + "\" type=\"fixed\"><origin xyz=\"0 0.001 0\"/><parent link=\"" +
         (k == 1 ? std::string("l1") : "s" + std::to_string(k - 1)) + "\"/><child link=\"s" + std::to_string(k) +
         "\"/></joint>\n";
  }
  return x + extra + "</robot>\n";
}

// Hostile URDFs (the second reliability probe's): each is refused with a message naming the element (and its line
// where the file has one), in bounded time and memory, instead of looping, growing without end or overflowing a
// stack.
TEST(UrdfBounds, CyclesSelfParentsAndBadValuesAreRefusedNamingTheElement) {
  const Files f("hostile");
  struct Case {
    const char* file;
    const char* base;
    const char* tip;
    std::vector<std::string> says;
  };
  const std::vector<Case> cases = {
      {"cycle_beside_the_chain.urdf", "base", "tip", {"is on a cycle of joints ('", "a URDF's joints form a tree"}},
      {"own_parent.urdf",
       "base",
       "tip",
       {"own_parent.urdf:10: joint 'loop' has link 'tip' as both its parent and its child"}},
      {"cycle_off_the_chain.urdf",
       "base",
       "tip",
       {"cycle_off_the_chain.urdf:14: joint 'js3' and joint 'js1' both have link 's1' as their child"}},
      {"origin_1e300.urdf",
       "base",
       "tip",
       {"origin_1e300.urdf:11: joint 'j2': <origin> xyz expected |x| <= 1000 m (a physical range), got 1e+300"}},
      {"names.urdf", "base", "tip", {"joint 'red\\x1b[31m': the name is not UTF-8 without control characters"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const std::string what = load_error(f, data_path(std::string("urdf/") + c.file), c.base, c.tip);
    ASSERT_FALSE(what.empty()) << "loaded";
    EXPECT_EQ(what.rfind((f.dir / "robot.toml").string() + ":", 0), 0u) << what;
    for (const std::string& s : c.says)
      EXPECT_NE(what.find(s), std::string::npos) << "missing '" << s << "' in: " << what;
    EXPECT_EQ(what.find('\x1b'), std::string::npos) << "a raw escape character in the message";
  }
  // A name that is not UTF-8 (Latin-1 e-acute), printed escaped.
  const std::string latin = replace(read_text(data_path("urdf/names.urdf")), "red\x1b[31m", "red");
  const std::string what = load_error(f, f.write("latin.urdf", latin), "base", "tip");
  EXPECT_NE(what.find("joint 'latin\\xe9xyz': the name is not UTF-8"), std::string::npos) << what;
  // A declaration closed by '>' alone (TinyXML accepts it) hides nothing from the checks; an unclosed comment is
  // malformed XML.
  std::string open_declaration = read_text(data_path("urdf/own_parent.urdf"));
  open_declaration.replace(open_declaration.find("?>"), 2, "\x1f>");
  const std::string hidden = load_error(f, f.write("open.urdf", open_declaration), "base", "tip");
  EXPECT_NE(hidden.find("joint 'loop' has link 'tip' as both its parent and its child"), std::string::npos) << hidden;
  // The checks read the file as urdfdom does (a fuzz finding, and variants): a second <child> after the first,
  // which urdfdom ignores, an entity in the name and spaces around '=' hide nothing either.
  const std::string own = read_text(data_path("urdf/own_parent.urdf"));
  const std::string self_loop = "<parent link=\"tip\"/><child link=\"tip\"/>";
  for (const std::string& variant :
       {std::string("<parent link=\"tip\"/><child link=\"tip\"/>junk\"/><child link=\"base\"/>"),
        std::string("<parent link=\"tip\"/><child link=\"t&#105;p\"/>"),
        std::string("<parent link = \"tip\"/><child\n link =\n'tip'/>")}) {
    SCOPED_TRACE(variant);
    const std::string text = replace(own, self_loop, variant);
    ASSERT_NE(text, own);
    const std::string said = load_error(f, f.write("variant.urdf", text), "base", "tip");
    EXPECT_NE(said.find("variant.urdf:10: joint 'loop' has link 'tip' as both its parent and its child"),
              std::string::npos)
        << said;
  }
  // XML that TinyXML cannot read is refused with its line and column.
  const std::string broken =
      load_error(f, f.write("broken.urdf", "<robot name=\"r\">\n  <link name=\"a\"></robot>\n"), "a", "b");
  EXPECT_NE(broken.find("broken.urdf:2:"), std::string::npos) << broken;
  EXPECT_NE(broken.find("malformed XML ("), std::string::npos) << broken;
  const std::string comment =
      load_error(f, f.write("comment.urdf", "<robot name=\"r\">\n<!-- never closed\n"), "a", "b");
  EXPECT_NE(comment.find("comment.urdf:2: a comment <!-- is not closed (malformed XML)"), std::string::npos) << comment;
  // Two joints with one child.
  const std::string two =
      generated_urdf(2, 0, "<joint name=\"again\" type=\"fixed\"><parent link=\"l0\"/><child link=\"l2\"/></joint>\n");
  const std::string twice = load_error(f, f.write("two_parents.urdf", two), "l0", "l2");
  EXPECT_NE(twice.find("both have link 'l2' as their child; a link has one parent"), std::string::npos) << twice;
}

TEST(UrdfBounds, DepthElementsLinksAndJointsAreBoundedWithTheBoundInTheMessage) {
  const Files f("bounds");
  // 50,000 nested elements (350 KB) once overflowed TinyXML's stack.
  std::string nested = "<?xml version=\"1.0\"?>\n<robot name=\"deep\">\n";
  for (int k = 0; k < 50000; ++k) nested += "<a>";
  for (int k = 0; k < 50000; ++k) nested += "</a>";
  nested += "</robot>\n";
  std::string what = load_error(f, f.write("deep.urdf", nested), "l0", "l1");
  EXPECT_NE(what.find("deep.urdf:3: <a> is nested 65 elements deep; a URDF nests at most 64"), std::string::npos)
      << what;
  // More elements than the bound, none nested.
  std::string wide = "<robot name=\"wide\">\n";
  for (int k = 0; k <= 500000; ++k) wide += "<a/>";  // one more than the bound
  what = load_error(f, f.write("wide.urdf", wide + "</robot>\n"), "l0", "l1");
  EXPECT_NE(what.find("more than 500000 XML elements"), std::string::npos) << what;
  // A side branch of 12,000 fixed links (once a segfault in add_branch): more links than the bound.
  what = load_error(f, f.write("branch.urdf", generated_urdf(2, 12000)), "l0", "l2");
  EXPECT_NE(what.find("12003 links and 12002 joints; a URDF has at most 10000 of each"), std::string::npos) << what;
  // A chain of 1,200 moving joints (once 3.4 GB): more than kMaxJoints.
  what = load_error(f, f.write("long.urdf", generated_urdf(1200, 0)), "l0", "l1200");
  EXPECT_NE(what.find("joint 'j1001': the chain from 'l0' to 'l1200' has more than 1000 moving joints"),
            std::string::npos)
      << what;
  // The same from a robot file: 1,001 [[joints]].
  std::string toml = "name = \"long\"\nkind = \"planar\"\n";
  for (int k = 0; k <= 1000; ++k) {
    toml += "[[joints]]\nname = \"j" + std::to_string(k) +
            "\"\nlength = 0.1\nlimits = [-1, 1]\nvelocity_limit = { type = \"constant\", lower = -1, upper = 1 }\n";
  }
  try {
    (void)load_robot(f.write("long.toml", toml));
    ADD_FAILURE() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("key 'joints': expected at most 1000 joints, got 1001"), std::string::npos)
        << e.what();
  }
}

// Within the bounds, a long side branch is walked without recursion and every one of its shapes rides on l1.
TEST(UrdfBounds, ALongSideBranchRidesOnItsLink) {
  const Files f("branch");
  const std::string urdf = generated_urdf(2, 9000);
  f.write("branch.urdf", urdf);
  const RobotModel robot =
      load_robot(f.write("robot.toml", "urdf = \"branch.urdf\"\nbase_link = \"l0\"\ntip_link = \"l2\"\n"));
  ASSERT_EQ(robot.link_shapes().size(), 9000u);
  for (const auto& s : robot.link_shapes()) ASSERT_EQ(s.link, 0);
  // The last sphere is 9,000 steps of 1 mm along y from l1's frame.
  EXPECT_NEAR(robot.link_shapes().back().pose.translation().y(), 9.0, 1e-9);
}

// A tree: a head on a revolute joint hanging from l1 (beside l2), a hand fixed to l2 with two fingers, the second a
// mimic of the first. Each side-branch link is a body of its own, named by its link, its joints held.
const char* const kTreeBranches = R"(  <link name="head">
    <collision><origin xyz="0 0 0" rpy="0 0 0"/><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <link name="hand">
    <collision><origin xyz="0 0 0" rpy="0 0 0"/><geometry><sphere radius="0.02"/></geometry></collision>
  </link>
  <link name="finger1">
    <collision><origin xyz="0 0 0.01" rpy="0 0 0"/><geometry><sphere radius="0.01"/></geometry></collision>
  </link>
  <link name="finger2">
    <collision><origin xyz="0 0 0.01" rpy="0 0 0"/><geometry><sphere radius="0.01"/></geometry></collision>
  </link>
  <joint name="neck" type="revolute">
    <parent link="l1"/><child link="head"/><origin xyz="0.2 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  <joint name="wrist" type="fixed">
    <parent link="l2"/><child link="hand"/><origin xyz="0 0 0.05" rpy="0 0 0"/>
  </joint>
  <joint name="f1" type="prismatic">
    <parent link="hand"/><child link="finger1"/><origin xyz="0 0.01 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" velocity="0.1" effort="1"/>
  </joint>
  <joint name="f2" type="prismatic">
    <parent link="hand"/><child link="finger2"/><origin xyz="0 -0.01 0" rpy="0 0 0"/><axis xyz="0 -1 0"/>
    <limit lower="0" upper="0.04" velocity="0.1" effort="1"/><mimic joint="f1" multiplier="1.5" offset="0.001"/>
  </joint>
</robot>)";

// The pose of the first shape of body `name` in its joint's link frame.
Eigen::Vector3d body_position(const RobotModel& robot, const std::string& name) {
  const int b = robot.find_body(name);
  for (const auto& s : robot.link_shapes()) {
    if (s.body == b) return s.pose.translation();
  }
  ADD_FAILURE() << "no shape of body '" << name << "'";
  return Eigen::Vector3d::Constant(std::nan(""));
}

TEST(UrdfTrees, SideBranchLinksAreBodiesNamedByTheirLinksWithTheirJointsHeld) {
  const Files f("tree");
  f.write("two.urdf", replace(kTwoLinkUrdf, "</robot>", kTreeBranches));
  const RobotModel robot = load_robot(f.write("two.toml", kRobot));
  ASSERT_EQ(robot.dof(), 2);
  // The chain's links are named by their URDF links, not their joints.
  EXPECT_EQ(robot.bodies()[static_cast<std::size_t>(robot.body_of_joint(0))].name, "l1");
  EXPECT_EQ(robot.bodies()[static_cast<std::size_t>(robot.body_of_joint(1))].name, "l2");
  for (const char* name : {"head", "hand", "finger1", "finger2", "tool"}) {
    SCOPED_TRACE(name);
    ASSERT_GE(robot.find_body(name), 0);
  }
  const auto body = [&](const char* name) { return robot.bodies()[static_cast<std::size_t>(robot.find_body(name))]; };
  EXPECT_EQ(body("head").link, 0);
  EXPECT_TRUE(body("head").branch);
  EXPECT_EQ(body("hand").link, 1);
  EXPECT_FALSE(body("hand").branch);  // fixed to l2: part of it
  EXPECT_TRUE(body("finger1").branch);
  EXPECT_FALSE(body("tool").branch);
  // Held at 0 by default (the fingers' 0 is within their limits); the mimic follows: 1.5 * 0 + 0.001.
  EXPECT_NEAR((body_position(robot, "head") - Eigen::Vector3d(0.2, 0.0, 0.1)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((body_position(robot, "finger1") - Eigen::Vector3d(0.0, 0.01, 0.06)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((body_position(robot, "finger2") - Eigen::Vector3d(0.0, -0.011, 0.06)).norm(), 0.0, 1e-15);
  ASSERT_EQ(robot.spec().held_joints.size(), 3u);

  // Self-collision: the head (a side branch on joint 1) is checked against l2 on the neighbouring joint; the hand,
  // fixed to l2, is not checked against l1 (neighbours), nor against the fingers on its own joint.
  const auto pair = [&](const char* a, const char* b) {
    return robot.self_collision_bodies(robot.find_body(a), robot.find_body(b));
  };
  EXPECT_TRUE(pair("head", "l2"));
  EXPECT_TRUE(pair("head", "hand"));
  EXPECT_TRUE(pair("finger1", "l1"));
  EXPECT_FALSE(pair("hand", "l1"));
  EXPECT_FALSE(pair("l1", "l2"));
  EXPECT_FALSE(pair("hand", "finger2"));
  EXPECT_FALSE(pair("head", "l1"));

  // Held positions from the robot file move the branch; a mimic follows its leader's; link names are addressable in
  // [[links]] and collision_exclude.
  const RobotModel held =
      load_robot(f.write("held.toml", std::string(kRobot) + R"(held_joints = { neck = 0.5, f1 = 0.02 }
collision_exclude = [["head", "l2"], ["finger1", "a"]]
[[links]]
name = "head"
collision = [{ shape = "sphere", radius = 0.07, xyz = [0.0, 0.0, 0.03] }]
)"));
  const int head = held.find_body("head");
  ASSERT_GE(head, 0);
  int head_shapes = 0;
  for (const auto& s : held.link_shapes()) {
    if (s.body != head) continue;
    ++head_shapes;
    EXPECT_DOUBLE_EQ(*s.spec.radius, 0.07);
    EXPECT_NEAR((s.pose.translation() - Eigen::Vector3d(0.2, 0.0, 0.13)).norm(), 0.0, 1e-15);
  }
  EXPECT_EQ(head_shapes, 1);
  EXPECT_NEAR((body_position(held, "finger1") - Eigen::Vector3d(0.0, 0.03, 0.06)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((body_position(held, "finger2") - Eigen::Vector3d(0.0, -0.041, 0.06)).norm(), 0.0, 1e-15);
  EXPECT_FALSE(held.self_collision_bodies(held.find_body("head"), held.find_body("l2")));
  EXPECT_FALSE(held.self_collision_bodies(held.find_body("finger1"), held.find_body("l1")));  // 'a' moves l1
  EXPECT_TRUE(held.self_collision_bodies(held.find_body("head"), held.find_body("hand")));
}

TEST(UrdfTrees, HeldJointsAreCheckedByNameLimitAndMimic) {
  const Files f("held");
  f.write("two.urdf", replace(kTwoLinkUrdf, "</robot>", kTreeBranches));
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"held_joints = { nope = 0.1 }", {"held_joints", "no held joint named 'nope'", "'neck'", "'f1'"}},
      {"held_joints = { f2 = 0.01 }", {"joint 'f2' is a mimic of joint 'f1'", "hold 'f1' instead"}},
      {"held_joints = { neck = 2.0 }", {"expected joint 'neck' within its limits [-1, 1], got 2"}},
      {"collision_exclude = [[\"head\", \"nowhere\"]]", {"got 'nowhere'", "'head'"}},
  };
  for (const auto& [extra, says] : cases) {
    SCOPED_TRACE(extra);
    const auto file = f.write("bad.toml", std::string(kRobot) + extra + "\n");
    try {
      (void)load_robot(file);
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(file.string() + ":4:", 0), 0u) << what;  // at the key, on line 4
      for (const std::string& s : says)
        EXPECT_NE(what.find(s), std::string::npos) << "missing '" << s << "' in: " << what;
    }
  }
}

// A mimic joint on the chain whose leader is off it (the tip is the second finger) is held like a fixed joint; one
// whose leader is on the chain is refused.
TEST(UrdfTrees, AMimicOnTheChainFollowsALeaderOffIt) {
  const Files f("mimic");
  f.write("two.urdf", replace(kTwoLinkUrdf, "</robot>", kTreeBranches));
  const RobotModel robot = load_robot(f.write(
      "tip.toml", "urdf = \"two.urdf\"\nbase_link = \"base\"\ntip_link = \"finger2\"\nheld_joints = { f1 = 0.02 }\n"));
  EXPECT_EQ(robot.dof(), 2);
  // The tip: hand 0.05 above l2, then finger2's origin, moved 1.5 * 0.02 + 0.001 along -y.
  EXPECT_NEAR((robot.end_effector().translation() - Eigen::Vector3d(0.0, -0.041, 0.05)).norm(), 0.0, 1e-15);
}

TEST(UrdfTrees, EveryProblemOfTheJointsAndLinksIsReportedAtOnce) {
  const Files f("problems");
  std::string urdf = replace(kTwoLinkUrdf, R"(name="a" type="revolute")", R"(name="a" type="continuous")");
  urdf = replace(urdf, R"(velocity="3")", R"(velocity="0")");
  urdf = replace(urdf, R"(<box size="0.1 0.02 0.02"/>)", R"(<mesh filename="l2.stl"/>)");
  f.write("two.urdf", urdf);
  const auto file = f.write("two.toml", std::string(kRobot) + "[[links]]\nname = \"l9\"\n");
  try {
    (void)load_robot(file);
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    for (const char* s : {"4 problems in this robot file", "joint 'a' is continuous", "joint 'b'",
                          "has no velocity limit", "no link named 'l9'", "the file's links are 'base', 'l1', 'l2',",
                          "mesh 'l2.stl' not found", "two.toml:5:8: robot.links[0]: key 'name'"}) {
      EXPECT_NE(what.find(s), std::string::npos) << "missing '" << s << "' in: " << what;
    }
  }
}

TEST(UrdfTrees, AMissingBaseOrTipLinkListsTheFilesLinks) {
  const Files f("missing");
  f.write("two.urdf", kTwoLinkUrdf);
  for (const char* key : {"base_link", "tip_link"}) {
    SCOPED_TRACE(key);
    const std::string robot = replace(kRobot, std::string(key) + (key[0] == 'b' ? " = \"base\"" : " = \"tool\""),
                                      std::string(key) + " = \"nope\"");
    try {
      (void)load_robot(f.write("two.toml", robot));
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("no link named 'nope'"), std::string::npos) << what;
      EXPECT_NE(what.find("the file's 4 links: 'base', 'l1', 'l2', 'tool'"), std::string::npos) << what;
    }
  }
}

// The Panda's fingers as Franka describes them: panda_finger_joint2 mimics panda_finger_joint1. Holding joint 1 open
// by 0.04 m moves the left finger's fitted capsule 0.04 m along the hand's y axis and the right one the other way.
TEST(UrdfTrees, ThePandasFingersOpenTogether) {
  const Files f("panda_fingers");
  const std::string urdf = source_path("robots/franka_panda_description/panda.urdf").string();
  const std::string head = "urdf = \"" + urdf + "\"\nbase_link = \"panda_link0\"\ntip_link = \"panda_link8\"\n";
  const RobotModel closed = load_robot(f.write("closed.toml", head));
  const RobotModel open = load_robot(f.write("open.toml", head + "held_joints = { panda_finger_joint1 = 0.04 }\n"));
  const auto centre = [](const RobotModel& r, const char* link) -> Eigen::Vector3d {
    const int b = r.find_body(link);
    EXPECT_GE(b, 0) << link;
    for (const auto& s : r.link_shapes()) {
      if (s.body == b) return Eigen::Vector3d(s.pose.translation());
    }
    return Eigen::Vector3d::Constant(std::nan(""));
  };
  const Eigen::Vector3d left = centre(open, "panda_leftfinger") - centre(closed, "panda_leftfinger");
  const Eigen::Vector3d right = centre(open, "panda_rightfinger") - centre(closed, "panda_rightfinger");
  EXPECT_NEAR(left.norm(), 0.04, 1e-12);
  EXPECT_NEAR((left + right).norm(), 0.0, 1e-12);
  // Along the hand's y axis, in link 7's frame: the hand is turned -pi/4 about z from link 8.
  EXPECT_NEAR(left.z(), 0.0, 1e-12);
  EXPECT_NEAR(
      left.normalized().dot(Eigen::Vector3d(std::cos(-M_PI / 4 + M_PI / 2), std::sin(-M_PI / 4 + M_PI / 2), 0.0)), 1.0,
      1e-9);
  ASSERT_EQ(open.spec().held_joints.size(), 2u);
  EXPECT_TRUE(open.bodies()[static_cast<std::size_t>(open.find_body("panda_rightfinger"))].branch);
  EXPECT_FALSE(open.bodies()[static_cast<std::size_t>(open.find_body("panda_hand"))].branch);
}
}  // namespace
}  // namespace redres

// A corpus of bad robot files (tests/data/robot_corpus): each must be rejected with a ConfigError that points at
// the right file, line and column and says what was expected. Also: every robot in robots/ loads, and laws given
// as formulas and CSV tables load and evaluate as written.

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

struct Bad {
  const char* file;
  const char* where;  // "line:col" expected after the file name ("" for a file-level error)
  std::vector<const char*> says;
};

const std::vector<Bad>& corpus() {
  static const std::vector<Bad> c = {
      {"unknown_top_key.toml",
       "3:1",
       {"unknown key 'colour'",
        "known keys: base, collision_exclude, collision_model, end_effector, held_joints, home, joints, kind"}},
      {"unknown_joint_key.toml", "6:1", {"unknown key 'mass' in joint 'j1'", "length, limits, name"}},
      {"unknown_law_key.toml", "14:1", {"unknown key 'sigma'", "known keys: a, b, s, sigma_max, sigma_min, type"}},
      {"wrong_type_number.toml",
       "5:10",
       {"key 'length': expected a number or a constant formula", "\"long\" is not a valid formula"}},
      {"wrong_type_string.toml", "1:8", {"key 'name': expected a string, got an integer"}},
      {"missing_name.toml", "1:1", {"missing required key 'name'"}},
      {"missing_kind.toml", "1:1", {"missing required key 'kind'"}},
      {"missing_joints.toml", "1:1", {"missing required key 'joints'"}},
      {"missing_length.toml", "3:1", {"joint 'j1'", "missing required key 'length'"}},
      {"missing_limits.toml", "3:1", {"joint 'j1'", "missing required key 'limits'"}},
      {"missing_velocity_limit.toml", "3:1", {"missing required key 'velocity_limit'"}},
      {"missing_law_parameter.toml", "7:1", {"joint 'j1' velocity_limit", "missing required key 'b'"}},
      {"limits_reversed.toml", "6:10", {"key 'limits'", "lower < upper", "got lower 1 >= upper -1"}},
      {"limits_equal.toml", "6:10", {"key 'limits'", "got lower 0.5 >= upper 0.5"}},
      {"zero_length.toml", "5:10", {"key 'length'", "link length > 0 m, got 0"}},
      {"negative_length.toml", "5:10", {"key 'length'", "got -0.2"}},
      {"nan_value.toml", "5:10", {"key 'length': expected a finite number, got nan"}},
      {"inf_limit.toml", "6:11", {"key 'limits': expected a finite number, got -inf"}},
      {"empty_chain.toml", "3:10", {"expected at least one [[joints]] entry, got none"}},
      {"unknown_kind.toml", "2:8", {"expected one of 'planar', 'spatial', got 'cylindrical'"}},
      {"unknown_joint_type.toml", "6:8", {"expected one of 'revolute', 'prismatic', got 'spherical'"}},
      {"prismatic_in_planar.toml", "5:8", {"expected one of 'revolute', got 'prismatic'"}},
      {"unknown_law.toml",
       "7:27",
       {"unknown velocity-limit law type 'sinusoidal'", "constant, expression, push_rod, table"}},
      {"constant_lower_positive.toml", "7:47", {"key 'lower': expected < 0, got 0.5"}},
      {"acceleration_lower_positive.toml", "8:51", {"key 'lower': expected < 0, got 0.5"}},
      {"effort_negative.toml", "8:16", {"effort_limit", "got -3"}},
      {"push_rod_reaches_cos_zero.toml",
       "7:1",
       {"joint 'j2'", "'push_rod' is invalid at theta = 1.570796327 rad", "cos(theta) = 0"}},
      {"expression_syntax.toml", "9:9", {"key 'lower'", "is not a valid formula"}},
      {"expression_sign.toml", "7:1", {"joint 'j1'", "invalid at theta = 0.5 rad", "expected lower < 0 < upper"}},
      {"table_not_covering.toml", "7:1", {"invalid at theta = -1 rad", "outside the table"}},
      {"table_not_increasing.toml", "9:9", {"expected strictly increasing theta"}},
      {"duplicate_joint.toml", "9:8", {"duplicate joint name 'j1'"}},
      {"home_wrong_length.toml", "3:8", {"key 'home': expected an array of 2 numbers, got 3"}},
      {"home_outside.toml", "3:8", {"joint 'j2' within its limits [-1, 1], got 1.5"}},
      {"syntax_error.toml", "3:17", {"TOML syntax error"}},
      {"spatial_without_convention.toml", "1:1", {"missing required key 'convention'"}},
      {"end_effector_wrong_size.toml", "4:12", {"key 'position': expected an array of 2 numbers, got 3"}},
      {"joints_zero_axis.toml", "6:8", {"joint 'j1': key 'axis': expected a non-zero axis vector"}},
      {"joints_with_dh_key.toml",
       "6:1",
       {"unknown key 'd' in joint 'j1'",
        "armature, axis, collision, damping, effort_limit, inertia, jerk_limit, limits, name, origin"}},
      {"dh_with_axis.toml",
       "6:1",
       {"unknown key 'axis' in joint 'j1'",
        "a, acceleration_limit, alpha, armature, collision, d, damping, effort_limit"}},
      {"joints_origin_unknown_key.toml", "6:31", {"unknown key 'quat' in joint 'j1' origin", "rpy, xyz"}},
      {"planar_base_rpy.toml", "5:1", {"unknown key 'rpy' in base", "angle, position, xyz"}},
  };
  return c;
}

TEST(RobotCorpus, EveryBadFileIsRejectedAtItsLineWithWhatWasExpected) {
  for (const Bad& b : corpus()) {
    SCOPED_TRACE(b.file);
    const std::string path = data_path(std::string("robot_corpus/") + b.file).string();
    try {
      (void)load_robot(path);
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ":" + b.where + ": ", 0), 0u) << what;
      for (const char* s : b.says) EXPECT_NE(what.find(s), std::string::npos) << "missing '" << s << "' in: " << what;
    }
  }
}

// A CSV table's own errors point into the CSV file, not the robot file.
TEST(RobotCorpus, CsvTableErrorsPointIntoTheCsvFile) {
  const std::string csv = data_path("robot_corpus/bad_table.csv").string();
  try {
    (void)load_robot(data_path("robot_corpus/table_bad_csv.toml"));
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(csv + ":3:10: column 'upper': expected a finite number, got 'oops'", 0), 0u)
        << e.what();
  }
}

TEST(RobotFiles, EveryShippedRobotLoads) {
  int count = 0;
  for (const auto& e : std::filesystem::directory_iterator(source_path("robots"))) {
    if (e.path().extension() != ".toml") continue;
    SCOPED_TRACE(e.path().string());
    const RobotModel model = load_robot(e.path());
    EXPECT_GE(model.dof(), 3);
    KinematicsData k(model);
    compute_kinematics(model, model.home(), k, KinematicsLevel::kAll);
    EXPECT_GT(k.w, 0.0);  // the home configurations are not singular
    ++count;
  }
  EXPECT_GE(count, 5);
}

// The Panda's published "ready" pose puts the flange at about (0.307, 0, 0.590) m.
TEST(RobotFiles, PandaFlangeAtTheReadyPose) {
  const RobotModel panda = load_robot(source_path("robots/franka_panda.toml"));
  KinematicsData k(panda);
  compute_kinematics(panda, panda.home(), k, KinematicsLevel::kPosition);
  EXPECT_NEAR(k.f(0), 0.3069, 1e-3);
  EXPECT_NEAR(k.f(1), 0.0, 1e-9);
  EXPECT_NEAR(k.f(2), 0.5903, 1e-3);
}

// The Kinova Gen3's published classic DH table starts with a fixed row 0 (alpha_0 = pi), which the robot file
// gives as its [base] pose. Checked against the table multiplied out here, row 0 included, at random angles; the
// arm stands upright at q = 0; and Kinova's "Home" pose puts the tool interface at the position and the
// orientation (Euler x-y-z angles 90, 0, 90 deg) that Kinova's web application shows there.
TEST(RobotFiles, KinovaGen3MatchesItsPublishedDhTableWithItsBaseRow) {
  const RobotModel gen3 = load_robot(source_path("robots/kinova_gen3.toml"));
  ASSERT_EQ(gen3.dof(), 7);
  const auto dh = [](double alpha, double d, double theta) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.rotate(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()));
    T.translate(Eigen::Vector3d(0.0, 0.0, d));
    T.rotate(Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitX()));
    return T;
  };
  const double d[7] = {-(0.1564 + 0.1284), -(0.0054 + 0.0064), -(0.2104 + 0.2104),
                       -(0.0064 + 0.0064), -(0.2084 + 0.1059), 0.0,
                       -(0.1059 + 0.0615)};
  const auto table = [&](const Eigen::VectorXd& q) {
    Eigen::Isometry3d T = dh(M_PI, 0.0, 0.0);  // row 0
    for (int i = 0; i < 7; ++i) T = T * dh(i == 6 ? M_PI : M_PI / 2, d[i], q(i) + (i == 0 ? 0.0 : M_PI));
    return T;
  };
  KinematicsData k(gen3);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::VectorXd q = random_inside(gen3, rng);
    compute_kinematics(gen3, q, k, KinematicsLevel::kPosition);
    EXPECT_LT((k.ee_pose.matrix() - table(q).matrix()).cwiseAbs().maxCoeff(), 1e-12);
  }
  compute_kinematics(gen3, Eigen::VectorXd::Zero(7), k, KinematicsLevel::kPosition);
  EXPECT_LT((k.f - Eigen::Vector3d(0.0, -0.0246, 1.1873)).norm(), 1e-12) << "upright at q = 0";
  compute_kinematics(gen3, gen3.home(), k, KinematicsLevel::kPosition);
  EXPECT_LT((k.f - Eigen::Vector3d(0.457, 0.001, 0.434)).cwiseAbs().maxCoeff(), 5e-4) << k.f.transpose();
  const Eigen::Matrix3d shown =
      (Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.0, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  EXPECT_LT(Eigen::AngleAxisd(shown * k.ee_pose.linear().transpose()).angle(), 1e-9) << k.ee_pose.linear();
}

TEST(RobotFiles, FormulaAndTableLawsEvaluateAsWritten) {
  const RobotModel model = load_robot(data_path("robot_corpus/good_laws.toml"));
  Eigen::VectorXd lo(2), hi(2);
  for (double th : {-1.0, -0.3, 0.0, 0.4, 1.0}) {
    model.velocity_limits(Eigen::Vector2d(th, th), lo, hi);
    EXPECT_NEAR(lo(0), -1.0 - 0.5 * th * th, 1e-14);
    EXPECT_NEAR(hi(0), 1.5 + 0.5 * std::cos(th), 1e-14);
    // good_table.csv: theta -1, 0, 1 -> lower -0.5, -1.0, -0.5 and upper 0.5, 2.0, 1.0, linear in between.
    const double lo_tab = th <= 0 ? -0.5 + (th + 1.0) * (-0.5) : -1.0 + th * 0.5;
    const double hi_tab = th <= 0 ? 0.5 + (th + 1.0) * 1.5 : 2.0 - th;
    EXPECT_NEAR(lo(1), lo_tab, 1e-14) << th;
    EXPECT_NEAR(hi(1), hi_tab, 1e-14) << th;
  }
}

}  // namespace
}  // namespace redres

// A task on a subset of the pose's rows (`task = ["x", "y", "z", "wx", "wy"]`): J holds exactly those rows of the
// full pose's J and w is det of that J J'; the whole set and the position set give the very runs "pose" and
// "position" give; the Panda, asked for its position and the two tilts only, keeps its flange pointing down while
// its yaw is left free; and a wrong list is a ConfigError at the key.

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "redres/config/toml_reader.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/run/run_summary.hpp"
#include "run_checks.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

RobotModel with_axes(const RobotModel& robot, std::vector<std::string> axes) {
  RobotSpec spec = robot.spec();
  spec.task_axes = std::move(axes);
  return RobotModel(std::move(spec));
}

TEST(TaskAxes, JacobianRowsAreThoseOfTheFullPose) {
  const RobotModel iiwa = load_robot(source_path("robots/kuka_iiwa14.toml"));
  RobotSpec pose_spec = iiwa.spec();
  pose_spec.task = TaskRows::kPose;
  const RobotModel pose(pose_spec);
  const RobotModel subset = with_axes(iiwa, {"x", "z", "wy", "wz"});
  ASSERT_EQ(subset.task(), TaskRows::kPose);
  ASSERT_EQ(subset.task_dim(), 4);
  ASSERT_EQ(subset.reference_dim(), 6);
  EXPECT_EQ(subset.task_names(), (std::vector<std::string>{"x", "z", "wy", "wz"}));
  EXPECT_EQ(subset.task_rows(), (std::vector<int>{0, 2, 4, 5}));
  EXPECT_FALSE(subset.tracks(1));
  EXPECT_TRUE(subset.tracks(4));

  const RobotModel position_only = with_axes(iiwa, {"y", "z"});
  EXPECT_EQ(position_only.task(), TaskRows::kPosition) << "no orientation row: the reference is the position";
  EXPECT_EQ(position_only.reference_dim(), 3);

  std::mt19937 rng(7);
  KinematicsData a(pose), b(subset);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::VectorXd theta = random_inside(iiwa, rng);
    compute_kinematics(pose, theta, a, KinematicsLevel::kManipulability);
    compute_kinematics(subset, theta, b, KinematicsLevel::kManipulability);
    EXPECT_EQ(b.f, a.f) << "the reference keeps every row";
    Eigen::MatrixXd rows(4, iiwa.dof());
    for (int i = 0; i < 4; ++i) rows.row(i) = a.J.row(subset.task_rows()[static_cast<std::size_t>(i)]);
    EXPECT_EQ(b.J, rows);
    const double w = (rows * rows.transpose()).determinant();
    EXPECT_NEAR(b.w, w, 1e-12 * std::max(1.0, std::abs(w)));
  }
}

// Naming every row of a task is that task: the same trajectory, to the last bit.
TEST(TaskAxes, TheWholeSetIsTheNamedTask) {
  for (const auto& [named, whole] : std::vector<std::pair<std::string, std::string>>{
           {"task=\"position\"", "task=[\"x\", \"y\", \"z\"]"},
           {"task=\"pose\"", "task=[\"x\", \"y\", \"z\", \"wx\", \"wy\", \"wz\"]"}}) {
    Scenario a = load_scenario(source_path("configs/panda_helix.toml"), {named, "duration=2.0"});
    Scenario b = load_scenario(source_path("configs/panda_helix.toml"), {whole, "duration=2.0"});
    const RunResult ra = simulate(a), rb = simulate(b);
    ASSERT_EQ(ra.trajectory.columns(), rb.trajectory.columns());
    ASSERT_EQ(ra.trajectory.size(), rb.trajectory.size());
    const std::size_t last = ra.trajectory.size() - 1;
    for (std::size_t c = 0; c < ra.trajectory.columns().size(); ++c) {
      EXPECT_EQ(ra.trajectory(last, c), rb.trajectory(last, c)) << named << ": " << ra.trajectory.columns()[c];
    }
  }
}

// Five rows (position, and the tilts about the world x and y axes) on the Panda that holds its flange pointing
// down: the flange's z axis stays down, while the turn about the vertical is free (two degrees of redundancy).
TEST(TaskAxes, PandaKeepsItsToolAxisWithYawFree) {
  Scenario s = load_scenario(source_path("configs/panda_helix.toml"), {"task=[\"x\", \"y\", \"z\", \"wx\", \"wy\"]"});
  ASSERT_EQ(s.robot->task_dim(), 5);
  const RunResult run = simulate(s);
  const RunSummary sum = summarise(s, run);
  expect_clean_run(sum, 1e-4);

  const Trajectory& tr = run.trajectory;
  KinematicsData k(*s.robot);
  compute_kinematics(*s.robot, s.theta0, k, KinematicsLevel::kPosition);
  const Eigen::Matrix3d R0 = k.ee_pose.linear();
  ASSERT_LT((R0.col(2) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-2) << "the flange starts pointing down";
  double tilt = 0.0, yaw = 0.0, worst_rows = 0.0;
  Eigen::VectorXd theta(s.robot->dof());
  for (std::size_t row = 0; row < tr.size(); ++row) {
    theta = recorded_theta(*s.robot, tr, row);
    compute_kinematics(*s.robot, theta, k, KinematicsLevel::kPosition);
    const Eigen::Matrix3d R = k.ee_pose.linear();
    tilt = std::max(tilt, std::acos(std::clamp(R.col(2).dot(R0.col(2)), -1.0, 1.0)));
    yaw = std::max(yaw, std::abs(std::atan2(R0.col(0).cross(R.col(0)).z(), R0.col(0).dot(R.col(0)))));
    const Eigen::AngleAxisd err(R0 * R.transpose());
    worst_rows = std::max(worst_rows, (err.angle() * err.axis()).head<2>().norm());
  }
  EXPECT_LT(tilt, 1e-4) << "the tool axis is held";
  EXPECT_GT(yaw, 1e-3) << "the yaw, left free, moved: it is not a task row";
  const Metric* m = sum.metric("task_tracking", "max_orientation_error");
  ASSERT_NE(m, nullptr);
  EXPECT_NEAR(m->values.at(0), worst_rows, 1e-9) << "the error of the task's orientation rows";
}

TEST(TaskAxes, WrongListsAreConfigErrors) {
  const auto message = [](const std::string& set) {
    try {
      (void)load_scenario(source_path("configs/panda_helix.toml"), {set});
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("task=[\"x\", \"phi\"]").find("got 'phi'"), std::string::npos) << message("task=[\"x\", \"phi\"]");
  EXPECT_NE(message("task=[\"y\", \"x\"]").find("'x' is out of place"), std::string::npos);
  EXPECT_NE(message("task=[\"x\", \"x\"]").find("out of place"), std::string::npos);
  EXPECT_NE(message("task=[]").find("non-empty array"), std::string::npos);
  EXPECT_NE(message("task=[1, 2]").find("array of strings"), std::string::npos);
  EXPECT_EQ(message("task=[\"x\", \"y\"]"), "no error");
  // Built in code, the model checks the names against its kind: a planar robot has x, y and phi.
  const RobotModel planar = load_robot(source_path("robots/planar_4link.toml"));
  EXPECT_EQ(with_axes(planar, {"x", "phi"}).task_dim(), 2);
  EXPECT_THROW((void)with_axes(planar, {"x", "z"}), std::invalid_argument);
  EXPECT_THROW((void)with_axes(planar, {"phi", "x"}), std::invalid_argument);
}

// configs/kinova_gen3_tool_axis.toml: five task rows (position, tilts about y and z) keep the Gen3's tool axis
// along the world x axis while the roll about it is free; the log-det manipulability term ends with a higher w than
// the minimum-velocity-norm scheme on the same path, within the limits and apart from itself.
TEST(TaskAxes, KinovaHoldsItsToolAxisAndGainsManipulability) {
  Scenario s = load_scenario(source_path("configs/kinova_gen3_tool_axis.toml"));
  Scenario mvn = load_scenario(source_path("configs/kinova_gen3_tool_axis.toml"), {"objectives.1.p=0"});
  ASSERT_EQ(s.robot->task_names(), (std::vector<std::string>{"x", "y", "z", "wy", "wz"}));
  const RunResult run = simulate(s), run_mvn = simulate(mvn);
  const RunSummary sum = summarise(s, run), sum_mvn = summarise(mvn, run_mvn);
  for (const RunSummary* r : {&sum, &sum_mvn}) {
    expect_clean_run(*r, 1e-4);
    const Metric* self = r->metric("self_collision", "min_self_distance");
    ASSERT_NE(self, nullptr);
    EXPECT_GT(self->values.at(0), 0.01);
  }
  EXPECT_GT(sum.manipulability.final, 1.1 * sum_mvn.manipulability.final);

  const Trajectory& tr = run.trajectory;
  KinematicsData k(*s.robot);
  double tilt = 0.0, roll = 0.0;
  Eigen::VectorXd theta(s.robot->dof());
  compute_kinematics(*s.robot, s.theta0, k, KinematicsLevel::kPosition);
  const Eigen::Matrix3d R0 = k.ee_pose.linear();
  ASSERT_LT((R0.col(2) - Eigen::Vector3d::UnitX()).norm(), 1e-7) << "the tool starts pointing along x";
  for (std::size_t row = 0; row < tr.size(); ++row) {
    theta = recorded_theta(*s.robot, tr, row);
    compute_kinematics(*s.robot, theta, k, KinematicsLevel::kPosition);
    const Eigen::Matrix3d R = k.ee_pose.linear();
    tilt = std::max(tilt, std::acos(std::clamp(R.col(2).x(), -1.0, 1.0)));
    roll = std::max(roll, Eigen::AngleAxisd(R0.transpose() * R).angle());
  }
  EXPECT_LT(tilt, 1e-4) << "the tool axis stays along x";
  EXPECT_GT(roll, 1e-2) << "the roll about it, not a task row, was used";
}

}  // namespace
}  // namespace redres

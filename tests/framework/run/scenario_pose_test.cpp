// A spatial arm with a full 6-D pose task (configs/iiwa_pose_circle.toml): the position and the orientation errors
// stay below the tolerances that scenario documents (1e-4 m and 1e-4 rad), the orientation reference is the
// flange's orientation at t = 0, and task_tracking's summary metric agrees with an independent computation.

#include <cmath>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "redres/run/run_summary.hpp"
#include "run_checks.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

Eigen::Matrix3d rotation(const Eigen::Vector3d& v) {
  return v.norm() == 0.0 ? Eigen::Matrix3d::Identity() : Eigen::AngleAxisd(v.norm(), v.normalized()).toRotationMatrix();
}

TEST(PoseTask, IiwaHoldsItsOrientationWhileItDrawsACircle) {
  Scenario s = load_scenario(source_path("configs/iiwa_pose_circle.toml"));
  ASSERT_EQ(s.robot->task(), TaskRows::kPose);
  ASSERT_EQ(s.robot->task_dim(), 6);
  const RunResult run = simulate(s);
  const RunSummary sum = summarise(s, run);
  expect_clean_run(sum, 1e-4);

  const Trajectory& tr = run.trajectory;
  KinematicsData k(*s.robot);
  compute_kinematics(*s.robot, s.theta0, k, KinematicsLevel::kPosition);
  const Eigen::Matrix3d R0 = k.ee_pose.linear();
  double worst = 0.0, moved = 0.0;
  Eigen::VectorXd theta(s.robot->dof());
  for (std::size_t row = 0; row < tr.size(); ++row) {
    Eigen::Vector3d rd;
    for (int i = 0; i < 3; ++i) rd(i) = tr(row, tr.column(std::string("rd_") + "w" + "xyz"[i]));
    EXPECT_LT((rotation(rd) - R0).norm(), 1e-12) << "the reference is the orientation at t = 0";
    // The actual orientation, from the recorded joint angles (independent of the recorded r_ columns).
    theta = recorded_theta(*s.robot, tr, row);
    compute_kinematics(*s.robot, theta, k, KinematicsLevel::kPosition);
    worst = std::max(worst, Eigen::AngleAxisd(R0 * k.ee_pose.linear().transpose()).angle());
    moved = std::max(moved, (theta - s.theta0).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-4);
  EXPECT_GT(moved, 0.01) << "the joints moved, so holding the orientation was a real task";
  const Metric* m = sum.metric("task_tracking", "max_orientation_error");
  ASSERT_NE(m, nullptr);
  EXPECT_NEAR(m->values.at(0), worst, 1e-9);
}

// The scenario chooses the task rows: the Panda's robot file says "position", and `task = "pose"` in the scenario
// (here through --set) makes the same run hold the flange's orientation too; the robot file is not copied.
TEST(PoseTask, TheScenarioChoosesTheTaskRows) {
  Scenario position = load_scenario(source_path("configs/panda_helix.toml"));
  Scenario pose = load_scenario(source_path("configs/panda_helix.toml"), {"task=pose"});
  ASSERT_EQ(position.robot->task_dim(), 3);
  ASSERT_EQ(pose.robot->task_dim(), 6);
  EXPECT_EQ(pose.robot->name(), position.robot->name());
  const RunResult run = simulate(pose);
  const RunSummary sum = summarise(pose, run);
  EXPECT_EQ(sum.solver.failures, 0) << sum.solver.first_failure;
  EXPECT_LT(sum.max_position_error, 1e-4);
  const Metric* orientation = sum.metric("task_tracking", "max_orientation_error");
  ASSERT_NE(orientation, nullptr);
  EXPECT_LT(orientation->values.at(0), 1e-4);
  EXPECT_THROW((void)load_scenario(source_path("configs/panda_helix.toml"), {"task=\"orientation\""}), ConfigError);
}

// The Panda holds its flange pointing down: a rotation by an angle of about pi, where the rotation vector
// (|w| <= pi) flips sign with every wobble. The recorded columns keep one continuous representation instead: no jump
// between steps, although the angle goes both below and above pi; and orientation_error is the angle of R_d R'.
TEST(PoseTask, RotationVectorColumnsHaveNoJumpsAtPi) {
  Scenario s = load_scenario(source_path("configs/panda_helix.toml"), {"task=pose"});
  const RunResult run = simulate(s);
  const Trajectory& tr = run.trajectory;
  double below = 0.0, above = 0.0, jump = 0.0, worst_error = 0.0;
  Eigen::Vector3d prev = Eigen::Vector3d::Zero();
  for (std::size_t r = 0; r < tr.size(); ++r) {
    const Eigen::Vector3d w(tr.at(r, "r_wx"), tr.at(r, "r_wy"), tr.at(r, "r_wz"));
    const Eigen::Vector3d wd(tr.at(r, "rd_wx"), tr.at(r, "rd_wy"), tr.at(r, "rd_wz"));
    below = std::max(below, M_PI - w.norm());
    above = std::max(above, w.norm() - M_PI);
    if (r > 0) jump = std::max(jump, (w - prev).cwiseAbs().maxCoeff());
    prev = w;
    const double angle = Eigen::AngleAxisd(rotation(wd) * rotation(w).transpose()).angle();
    EXPECT_NEAR(tr.at(r, "orientation_error"), angle, 1e-12);
    worst_error = std::max(worst_error, angle);
  }
  EXPECT_GT(below, 0.0);  // the angle was below pi ...
  EXPECT_GT(above, 0.0);  // ... and above it: without care the vector would have flipped
  EXPECT_LT(jump, 1e-4);
  EXPECT_LT(worst_error, 1e-4);
}

// [orientation] turn: the flange turns by 0.6 rad about the world z axis over the run (slerp, cycloidal timing)
// while it draws the circle: the actual orientation follows (error < 1e-4 rad at every step), is halfway at T/2,
// and ends at Rz(0.6) R_0. A turn needs orientation rows.
TEST(PoseTask, TheOrientationTurnsFromItsStartByTheGivenRotation) {
  Scenario s =
      load_scenario(source_path("configs/iiwa_pose_manipulability.toml"), {"orientation.turn=[0.0, 0.0, 0.6]"});
  const RunResult run = simulate(s);
  const RunSummary sum = summarise(s, run);
  EXPECT_EQ(sum.solver.failures, 0) << sum.solver.first_failure;
  const Trajectory& tr = run.trajectory;
  const auto R = [&](std::size_t r) {
    return rotation(Eigen::Vector3d(tr.at(r, "r_wx"), tr.at(r, "r_wy"), tr.at(r, "r_wz")));
  };
  double worst = 0.0;
  for (std::size_t r = 0; r < tr.size(); ++r) worst = std::max(worst, tr.at(r, "orientation_error"));
  EXPECT_LT(worst, 1e-4);
  const Eigen::Matrix3d R0 = R(0);
  const auto turned = [&](double angle) {
    return Eigen::Matrix3d(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R0);
  };
  EXPECT_LT(Eigen::AngleAxisd(R(tr.size() - 1) * turned(0.6).transpose()).angle(), 1e-4);
  EXPECT_LT(Eigen::AngleAxisd(R((tr.size() - 1) / 2) * turned(0.3).transpose()).angle(), 1e-4);  // s(T/2) = 1/2
  EXPECT_GT(Eigen::AngleAxisd(R(tr.size() - 1) * R0.transpose()).angle(), 0.59);
  EXPECT_THROW((void)load_scenario(source_path("configs/panda_helix.toml"), {"orientation.turn=[0.0, 0.0, 0.6]"}),
               ConfigError);
}

// The shipped pose configs with manipulability maximisation (URDF robots, full pose held): errors, limits, newton on
// every step, and w at the end above the minimum-velocity-norm scheme's on the same path (the manipulability term
// switched off), by at least 20 %.
class PoseManipulability : public ::testing::TestWithParam<const char*> {};

TEST_P(PoseManipulability, HoldsThePoseWithinTheLimitsAndEndsWithAHigherW) {
  const std::string file = std::string("configs/") + GetParam() + ".toml";
  Scenario tvcmm = load_scenario(source_path(file));
  Scenario mvn = load_scenario(source_path(file), {"objectives.1.active=false"});
  ASSERT_EQ(tvcmm.robot->task_dim(), 6);
  const RunResult a = simulate(tvcmm), b = simulate(mvn);
  const RunSummary sa = summarise(tvcmm, a), sb = summarise(mvn, b);
  for (const RunSummary* sum : {&sa, &sb}) {
    EXPECT_EQ(sum->solver.failures, 0) << sum->solver.first_failure;
    EXPECT_LT(sum->max_position_error, 1e-4);
    const Metric* orientation = sum->metric("task_tracking", "max_orientation_error");
    ASSERT_NE(orientation, nullptr);
    EXPECT_LT(orientation->values.at(0), 1e-4);
    EXPECT_LE(sum->max_joint_angle_violation, 0.0);
    EXPECT_LE(sum->max_joint_velocity_violation, 0.0);
  }
  EXPECT_EQ(a.engine(), "newton");
  RecordProperty("w_final_tvcmm", std::to_string(sa.manipulability.final));
  RecordProperty("w_final_mvn", std::to_string(sb.manipulability.final));
  EXPECT_GT(sa.manipulability.final, 1.2 * sb.manipulability.final);
}

INSTANTIATE_TEST_SUITE_P(Configs, PoseManipulability,
                         ::testing::Values("panda_pose_manipulability", "iiwa_pose_manipulability"));

}  // namespace
}  // namespace redres

// State between steps (issue 25): what a plugin reads of the previous steps through the Context. A recording
// constraint (it writes no row) logs, at each of its contributions, theta_dot_prev, theta_dot_prev2, the measured
// velocity, tau, the previous status and the step index; the tests hold them against the commands the controller
// handed out: Euler and Heun runs (Heun's second stage sees the same previous command as its first, and the next step
// sees the average that was applied), held steps (a zero command), reset() (the plugins' start() call, zeros again),
// set_period() and the measured-velocity overload.

#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "redres/constraints/joint_velocity_limits.hpp"
#include "redres/constraints/task_tracking.hpp"
#include "redres/control/controller.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/objectives/min_velocity_norm.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/paths/circle.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

struct Seen {
  Eigen::VectorXd prev, prev2;
  bool measured = false;
  Eigen::VectorXd measured_value;
  double tau = 0.0;
  SolverStatus status_prev = SolverStatus::kNotRun;
  long index = -1;
};

struct RecorderData : PluginData {
  std::vector<Seen> seen;
  int starts = 0;
};

struct NoConfig {
  static const Schema<NoConfig>& schema() {
    static const Schema<NoConfig> s{{}};
    return s;
  }
};

class Recorder final : public Configured<Constraint, NoConfig> {
 public:
  explicit Recorder(const RobotModel& /*robot*/) : Configured("test_recorder", NoConfig{}) {}
  [[nodiscard]] std::unique_ptr<PluginData> make_data() const override { return std::make_unique<RecorderData>(); }
  void start(PluginData* data) const override { ++static_cast<RecorderData*>(data)->starts; }

 private:
  void add_to(const Context& ctx, QpBuilder& /*b*/, PluginData* data) const override {
    Seen s;
    s.prev = *ctx.theta_dot_prev;
    s.prev2 = *ctx.theta_dot_prev2;
    s.measured = ctx.theta_dot_measured != nullptr;
    if (s.measured) s.measured_value = *ctx.theta_dot_measured;
    s.tau = ctx.tau;
    s.status_prev = ctx.status_prev;
    s.index = ctx.step_index;
    static_cast<RecorderData*>(data)->seen.push_back(std::move(s));
  }
};

const RecorderData& recorded(const Controller& c) {
  const auto& d = c.plugin_data().constraints.back();
  return *static_cast<const RecorderData*>(d.get());
}

struct StepRig {
  RobotModel robot = load_robot(source_path("robots/planar_4link.toml"));
  std::unique_ptr<Scheme> scheme;
  std::unique_ptr<LviEngine> engine = make_engine("newton");
  std::unique_ptr<Path> path;
  explicit StepRig(double speed) {
    std::vector<std::unique_ptr<Objective>> o;
    o.push_back(std::make_unique<MinVelocityNorm>(MinVelocityNorm::Config{}, robot));
    std::vector<std::unique_ptr<Constraint>> c;
    c.push_back(std::make_unique<TaskTracking>(TaskTracking::Config{}, robot));
    c.push_back(std::make_unique<JointVelocityLimits>(JointVelocityLimits::Config{}, robot));
    c.push_back(std::make_unique<Recorder>(robot));
    scheme = std::make_unique<Scheme>(robot, std::move(o), std::move(c));
    KinematicsData k(robot);
    compute_kinematics(robot, robot.home(), k, KinematicsLevel::kPosition);
    PathContext ctx;
    ctx.dim = 2;
    ctx.start.head(2) = k.f.head(2);
    ctx.duration = 1.0;
    path = make_path("circle", CircleConfig{.radius = 0.05 * speed}, PathPlacement{}, ctx);
  }
};

TEST(StepState, EachStepSeesTheCommandsHandedOutBeforeIt) {
  StepRig rig(1.0);
  Controller ctrl(rig.robot, *rig.scheme, *rig.engine, rig.path.get(), 1.0, 0.01);
  StepOutput out = ctrl.make_output();
  Eigen::VectorXd theta = rig.robot.home();
  std::vector<Eigen::VectorXd> commands;
  for (int k = 0; k < 5; ++k) {
    ctrl.step(theta, k * 0.01, out);
    commands.push_back(out.theta_dot);
    theta += 0.01 * out.theta_dot;
  }
  const auto& seen = recorded(ctrl).seen;
  ASSERT_EQ(seen.size(), 5U);
  EXPECT_EQ(recorded(ctrl).starts, 1);
  EXPECT_TRUE(seen[0].prev.isZero(0.0)) << "the first step has no previous command";
  EXPECT_EQ(seen[0].status_prev, SolverStatus::kNotRun);
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_EQ(seen[k].index, static_cast<long>(k));
    EXPECT_EQ(seen[k].tau, 0.01);
    EXPECT_FALSE(seen[k].measured);
    if (k >= 1) {
      EXPECT_EQ(seen[k].prev, commands[k - 1]) << "step " << k;
      EXPECT_EQ(seen[k].status_prev, SolverStatus::kSolved);
    }
    if (k >= 2) {
      EXPECT_EQ(seen[k].prev2, commands[k - 2]) << "step " << k;
    }
  }
  EXPECT_FALSE(commands[1].isZero(1e-12)) << "the arm moves, so the test can fail";

  // reset(): the plugins are told, and the next step has no previous command again.
  ctrl.reset();
  ctrl.step(theta, 0.0, out);
  EXPECT_EQ(recorded(ctrl).starts, 2);
  EXPECT_TRUE(recorded(ctrl).seen.back().prev.isZero(0.0));
  EXPECT_EQ(recorded(ctrl).seen.back().index, 0);

  // A measured velocity, for one step only; another period.
  const Eigen::VectorXd measured = Eigen::VectorXd::LinSpaced(rig.robot.dof(), 0.1, 0.4);
  ctrl.set_period(0.002);
  ctrl.step(theta, measured, 0.01, out);
  EXPECT_TRUE(recorded(ctrl).seen.back().measured);
  EXPECT_EQ(recorded(ctrl).seen.back().measured_value, measured);
  EXPECT_EQ(recorded(ctrl).seen.back().tau, 0.002);
  ctrl.step(theta, 0.012, out);
  EXPECT_FALSE(recorded(ctrl).seen.back().measured);
  EXPECT_THROW(ctrl.step(theta, Eigen::VectorXd(measured.head(2)), 0.014, out), std::invalid_argument);
  EXPECT_THROW(ctrl.set_period(0.0), std::invalid_argument);
}

TEST(StepState, HeunsSecondStageSeesTheSamePreviousCommandAndTheNextStepTheAverage) {
  StepRig rig(1.0);
  Controller ctrl(rig.robot, *rig.scheme, *rig.engine, rig.path.get(), 1.0, 0.01);
  StepOutput out = ctrl.make_output(), out2 = ctrl.make_output();
  Eigen::VectorXd theta = rig.robot.home();
  ctrl.step(theta, 0.0, out);
  const Eigen::VectorXd first = out.theta_dot;
  ctrl.reevaluate(theta + 0.01 * first, 0.01, out2);
  const auto& seen = recorded(ctrl).seen;
  ASSERT_EQ(seen.size(), 2U);
  EXPECT_EQ(seen[1].prev, seen[0].prev) << "the second stage is the same step";
  EXPECT_EQ(seen[1].index, seen[0].index);
  const Eigen::VectorXd applied = 0.5 * (first + out2.theta_dot);
  ctrl.set_applied(applied);
  ctrl.step(theta + 0.01 * applied, 0.01, out);
  EXPECT_EQ(recorded(ctrl).seen.back().prev, applied);
  EXPECT_EQ(recorded(ctrl).seen.back().prev2, Eigen::VectorXd::Zero(rig.robot.dof()));
}

TEST(StepState, AHeldStepLeavesAZeroCommand) {
  // A path far faster than the joints: steps fail and are held (theta_dot = 0, the policy chosen by name), and the
  // next step sees zeros.
  StepRig rig(40.0);
  Controller ctrl(rig.robot, *rig.scheme, *rig.engine, rig.path.get(), 1.0, 0.01);
  ctrl.set_failure_policy(FailurePolicy::kHold);
  StepOutput out = ctrl.make_output();
  Eigen::VectorXd theta = rig.robot.home();
  int held = 0;
  for (int k = 0; k < 60; ++k) {
    ctrl.step(theta, k * 0.01, out);
    const auto& seen = recorded(ctrl).seen;
    if (k > 0 && seen[seen.size() - 2].index >= 0 && seen.back().status_prev != SolverStatus::kSolved) {
      EXPECT_TRUE(seen.back().prev.isZero(0.0)) << "step " << k << " after a held step";
      ++held;
    }
    theta += 0.01 * out.theta_dot;
  }
  EXPECT_GT(held, 0) << "the path makes steps fail";
}

}  // namespace
}  // namespace redres

// The per-step API: Controller::step allocates nothing over long runs with every built-in per-step plugin and the
// real-time engines; outputs are the caller's (two never alias); the orientation reference of pose tasks is the
// Controller's; a solve that has not run says so.

#include <gtest/gtest.h>

#include "alloc_counter.hpp"
#include "redres/constraints/joint_angle_margin.hpp"
#include "redres/constraints/joint_velocity_limits.hpp"
#include "redres/constraints/task_tracking.hpp"
#include "redres/control/controller.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/objectives/joint_centering.hpp"
#include "redres/objectives/manipulability.hpp"
#include "redres/objectives/min_velocity_norm.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/paths/circle.hpp"
#include "redres/paths/helix.hpp"
#include "redres/paths/letter_r.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

using M = Manipulability;

// Every built-in objective and constraint that runs per step, with `manipulability` in the given form.
std::unique_ptr<Scheme> full_scheme(const RobotModel& robot, const M::Config& manipulability) {
  std::vector<std::unique_ptr<Objective>> objectives;
  objectives.push_back(std::make_unique<MinVelocityNorm>(MinVelocityNorm::Config{}, robot));
  objectives.push_back(std::make_unique<Manipulability>(manipulability, robot));
  objectives.push_back(std::make_unique<JointCentering>(JointCentering::Config{.lambda = 0.1}, robot));
  std::vector<std::unique_ptr<Constraint>> constraints;
  constraints.push_back(std::make_unique<TaskTracking>(TaskTracking::Config{}, robot));
  constraints.push_back(std::make_unique<JointAngleMargin>(JointAngleMargin::Config{.margin = 0.02}, robot));
  constraints.push_back(std::make_unique<JointVelocityLimits>(JointVelocityLimits::Config{.scale = 0.95}, robot));
  return std::make_unique<Scheme>(robot, std::move(objectives), std::move(constraints));
}

std::unique_ptr<Path> path_for(const RobotModel& robot, const Eigen::VectorXd& theta0, double T) {
  KinematicsData k(robot);
  compute_kinematics(robot, theta0, k, KinematicsLevel::kPosition);
  PathContext ctx;
  ctx.dim = robot.kind() == ChainKind::kPlanar ? 2 : 3;
  ctx.start.head(ctx.dim) = k.f.head(ctx.dim);
  ctx.duration = T;
  if (ctx.dim == 2) return make_path("letter_r", LetterRConfig{.height = 0.05}, PathPlacement{}, ctx);
  return make_path("helix", HelixConfig{.radius = 0.02, .pitch = 0.01, .turns = 1.0}, PathPlacement{}, ctx);
}

struct Case {
  const char* robot;
  M::Config manipulability;
  const char* engine;
};

TEST(ControllerRealTime, ThousandStepsWithEveryPerStepPluginAllocateNothing) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  // The push-rod arm (push_rod laws), a planar pose-task arm with every kind of velocity-limit law, and a 7-joint
  // spatial arm with a pose task; every manipulability measure and schedule, the expression schedule included.
  const std::vector<Case> cases = {
      {"robots/paper_pushrod_6dof.toml", {.schedule = M::Schedule::kSine}, "projection"},
      {"robots/paper_pushrod_6dof.toml", {.schedule = M::Schedule::kSmoothstep}, "newton"},
      {"tests/data/robots/planar_laws_pose.toml",
       {.schedule = M::Schedule::kExpression, .formula = "0.5*sin(pi*t/T)^2"},
       "newton"},
      {"tests/data/robots/planar_laws_pose.toml",
       {.p = 0.2, .schedule = M::Schedule::kConstant, .measure = M::Measure::kYoshikawa},
       "projection"},
      {"robots/kuka_iiwa14.toml", {.p = 0.5, .measure = M::Measure::kYoshikawa}, "newton"},
      {"robots/kuka_iiwa14.toml", {.p = 0.1, .schedule = M::Schedule::kConstant}, "projection"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.robot) + " with " + c.engine);
    const RobotModel robot = load_robot(source_path(c.robot));
    const double T = 10.0, tau = 0.01;
    const auto scheme = full_scheme(robot, c.manipulability);
    const auto engine = make_engine(c.engine);
    Eigen::VectorXd theta = robot.home();
    const auto path = path_for(robot, theta, T);
    Controller ctrl(robot, *scheme, *engine, path.get(), T, tau);
    ctrl.set_kinematics_level(KinematicsLevel::kAll);
    StepOutput out = ctrl.make_output();
    ctrl.step(theta, 0.0, out);  // first step: warm start and orientation capture happen here
    long allocations = 0;
    int solved = 0;
    {
      const testing::AllocationCounter counter;
      for (int k = 1; k <= 1000; ++k) {
        ctrl.step(theta, k * tau, out);
        solved += out.info.status == SolverStatus::kSolved ? 1 : 0;
        theta += tau * out.theta_dot;
      }
      allocations = counter.count();
    }
    EXPECT_EQ(allocations, 0);
    EXPECT_EQ(solved, 1000) << "last: " << to_string(out.info.status) << ": " << out.info.diagnosis;
    EXPECT_EQ(out.info.engine, c.engine == std::string("newton") ? "newton" : "projection");
  }
}

// Steps that fail allocate nothing either, diagnosis included: for each engine with a real-time path and each policy
// (hold: theta_dot = 0; relax: the elastic QP), on scenes whose steps fail for different reasons: a sphere on the
// Panda's hand path (the task rows against collision rows), the same sphere beside the point-cloud scenario's cloud,
// and the paper's arm asked for a path 50 times faster than its joints can follow (the task rows against the
// velocity bounds). The first failed step is counted too: the texts are written into storage sized at setup.
TEST(ControllerRealTime, FailedStepsAllocateNothingWhateverTheEngineAndPolicy) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  struct Scene {
    const char* config;
    std::vector<std::string> overrides;
  };
  const std::string sphere =
      "{ shape = \"sphere\", radius = 0.03, xyz = [0.607, 0.0, 0.59] }";  // on the circle of the hand
  const std::vector<Scene> scenes = {
      {"configs/panda_table_pole.toml", {"constraints.3.obstacles=[" + sphere + "]"}},
      {"configs/panda_point_cloud.toml",
       {"constraints.3.obstacles=[{ shape = \"points\", file = \"clouds/panda_workcell.ply\", resolution = 0.01, "
        "radius = 0.005 }, " +
        sphere + "]"}},
      {"configs/paper_r_tvcmm.toml", {"duration=0.8"}},
  };
  for (const Scene& scene : scenes) {
    for (const char* engine : {"newton", "projection"}) {
      for (const bool relax : {false, true}) {
        SCOPED_TRACE(std::string(scene.config) + ", " + engine + (relax ? ", relax" : ", hold"));
        std::vector<std::string> o = scene.overrides;
        o.push_back(std::string("solver.engine=") + engine);
        if (relax) o.emplace_back("solver.on_infeasible=relax");
        Scenario s = load_scenario(source_path(scene.config), o);
        const auto ctrl = Controller::from_scenario(s);
        StepOutput out = ctrl->make_output();
        Eigen::VectorXd theta = s.theta0;
        ctrl->step(theta, 0.0, out);
        theta += s.tau * out.theta_dot;
        const int steps = static_cast<int>(std::lround(s.duration / s.tau));
        long allocations = 0;
        int failed = 0;
        std::string last;
        for (int k = 1; k < steps && failed < 20; ++k) {  // 20 failed steps make the case
          {
            const testing::AllocationCounter counter;
            ctrl->step(theta, k * s.tau, out);
            allocations += counter.count();
          }
          if (out.info.status != SolverStatus::kSolved) {
            ++failed;
            last = out.info.diagnosis;
          }
          theta += s.tau * out.theta_dot;
        }
        EXPECT_GE(failed, 3) << "the scene makes steps fail";
        EXPECT_EQ(allocations, 0) << failed << " failed steps; the last: " << last;
      }
    }
  }
}

TEST(Controller, OutputsBelongToTheCallerAndNeverAlias) {
  const RobotModel robot = load_robot(source_path("robots/paper_pushrod_6dof.toml"));
  const auto scheme = full_scheme(robot, {});
  const auto engine = make_engine("newton");
  const auto path = path_for(robot, paper_theta0(), 40.0);
  Controller ctrl(robot, *scheme, *engine, path.get(), 40.0, 0.01);
  StepOutput a = ctrl.make_output(), b = ctrl.make_output();
  EXPECT_EQ(a.info.status, SolverStatus::kNotRun);
  EXPECT_STREQ(to_string(a.info.status), "not_run");
  ctrl.step(paper_theta0(), 5.0, a);
  const Eigen::VectorXd first = a.theta_dot;
  Eigen::VectorXd other = paper_theta0();
  other(1) += 0.05;
  ctrl.step(other, 5.0, b);
  EXPECT_EQ(a.theta_dot, first);  // untouched by the second step
  EXPECT_GT((b.theta_dot - a.theta_dot).norm(), 1e-6);
  EXPECT_EQ(a.info.status, SolverStatus::kSolved);
  StepOutput wrong;
  EXPECT_THROW(ctrl.step(paper_theta0(), 5.0, wrong), std::invalid_argument);
}

TEST(Controller, HoldsTheOrientationItFindsAtTheFirstStepUnlessTold) {
  const RobotModel robot = load_robot(source_path("robots/kuka_iiwa14.toml"));
  ASSERT_EQ(robot.task_dim(), 6);
  const auto scheme = full_scheme(robot, {});
  const auto engine = make_engine("newton");
  const Eigen::VectorXd theta0 = robot.home();
  const auto path = path_for(robot, theta0, 10.0);
  Controller ctrl(robot, *scheme, *engine, path.get(), 10.0, 0.01);
  StepOutput out = ctrl.make_output();
  KinematicsData k(robot);
  compute_kinematics(robot, theta0, k, KinematicsLevel::kPosition);
  ctrl.step(theta0, 0.0, out);
  EXPECT_EQ(ctrl.orientation_reference(), Eigen::Vector3d(k.f.tail<3>()));
  EXPECT_EQ(ctrl.r_d().tail<3>(), k.f.tail<3>());
  // Later steps hold it, wherever the arm is.
  Eigen::VectorXd moved = theta0;
  moved(6) += 0.3;
  ctrl.step(moved, 0.01, out);
  EXPECT_EQ(ctrl.r_d().tail<3>(), k.f.tail<3>());
  EXPECT_EQ(ctrl.r_d_dot().tail<3>(), Eigen::Vector3d::Zero());
  // reset() forgets a captured reference; an explicit one stays.
  ctrl.reset();
  ctrl.step(moved, 0.0, out);
  compute_kinematics(robot, moved, k, KinematicsLevel::kPosition);
  EXPECT_EQ(ctrl.r_d().tail<3>(), k.f.tail<3>());
  ctrl.set_orientation_reference(Eigen::Vector3d(0.1, 0.2, 0.3));
  ctrl.reset();
  ctrl.step(theta0, 0.0, out);
  EXPECT_EQ(ctrl.r_d().tail<3>(), Eigen::Vector3d(0.1, 0.2, 0.3));
}

}  // namespace
}  // namespace redres

namespace redres {
namespace {

// The whole run, recording included, allocates only at setup: simulate() of the paper's TVCMM makes as many
// allocations over 2,000 steps as over 500 (the trajectory's storage is reserved once for every row), for each
// engine, with the run's progress reported.
TEST(SimulationRealTime, TheRunAllocatesTheSameWhateverItsLength) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  for (const char* engine : {"newton", "projection"}) {
    long counts[2] = {0, 0};
    for (int i = 0; i < 2; ++i) {
      Scenario s = load_scenario(source_path("configs/paper_r_tvcmm.toml"),
                                 {std::string("solver.engine=") + engine, i == 0 ? "duration=5.0" : "duration=20.0"});
      int reports = 0;
      const testing::AllocationCounter counter;
      const RunResult run = simulate(s, [&reports](double, double) { ++reports; });
      counts[i] = counter.count();
      ASSERT_EQ(run.failures, 0) << run.first_failure;
      ASSERT_GT(reports, 100);
    }
    EXPECT_EQ(counts[0], counts[1]) << engine << ": allocations grow with the number of steps";
  }
}

}  // namespace
}  // namespace redres

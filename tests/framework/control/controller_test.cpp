// The per-step API: Controller::step allocates nothing over long runs with every built-in per-step plugin and the
// real-time engines; outputs are the caller's (two never alias); the orientation reference of pose tasks is the
// Controller's, and its r_d_ddot rows are the derivative of its r_d_dot rows; a solve that has not run says so.

#include <cmath>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "alloc_counter.hpp"
#include "redres/constraints/joint_angle_margin.hpp"
#include "redres/constraints/joint_velocity_limits.hpp"
#include "redres/constraints/task_tracking.hpp"
#include "redres/control/controller.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/control/orientation_reference.hpp"
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

struct RealTimeCase {
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
  const std::vector<RealTimeCase> cases = {
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
  for (const RealTimeCase& c : cases) {
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

// A cascade of priority levels (docs/tasks.md) allocates nothing either: the shipped three-level scenario, the same
// with the elbow's bound above where the elbow starts (its level cannot be met at first: the least-squares retry with
// slack variables), and the conflicting tasks (a soft level below the hand's), with each engine.
TEST(ControllerRealTime, ACascadeOfPriorityLevelsAllocatesNothing) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  struct Run {
    const char* config;
    std::vector<std::string> overrides;
  };
  const std::vector<Run> runs = {
      {"configs/panda_tool_elbow_posture.toml", {}},
      {"configs/panda_tool_elbow_posture.toml", {"tasks.1.lower=[0.7]"}},
      {"configs/panda_conflict_tool_first.toml", {}},
      {"configs/panda_tool_elbow_posture.toml", {"solver.engine=\"projection\""}},
  };
  int relaxed = 0;
  for (const Run& r : runs) {
    SCOPED_TRACE(std::string(r.config) + (r.overrides.empty() ? "" : " " + r.overrides.front()));
    Scenario s = load_scenario(source_path(r.config), r.overrides);
    const auto ctrl = Controller::from_scenario(s);
    StepOutput out = ctrl->make_output();
    ASSERT_EQ(out.levels.size(), s.scheme->levels().size());
    ASSERT_GE(out.levels.size(), 2U);
    Eigen::VectorXd theta = s.theta0;
    ctrl->step(theta, 0.0, out);
    theta += s.tau * out.theta_dot;
    long allocations = 0;
    int usable_steps = 0;
    {
      const testing::AllocationCounter counter;
      for (int k = 1; k <= 600; ++k) {
        ctrl->step(theta, k * s.tau, out);
        usable_steps += usable(out.info.status) ? 1 : 0;
        for (const LevelInfo& level : out.levels) relaxed += level.status == SolverStatus::kRelaxed ? 1 : 0;
        theta += s.tau * out.theta_dot;
      }
      allocations = counter.count();
    }
    EXPECT_EQ(allocations, 0);
    EXPECT_EQ(usable_steps, 600) << to_string(out.info.status) << ": " << out.info.diagnosis;
  }
  EXPECT_GT(relaxed, 0) << "the least-squares retry ran";
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

// The orientation rows of r_d_ddot, for a planar (the z angle) and a spatial (a rotation vector) pose task turning
// with cycloidal timing: they are the central differences of the r_d_dot rows (the angular velocity, itself checked
// against the rotations of r_d), equal turn s''(t) = turn 2 pi sin(2 pi t / T) / T^2, are zero while the orientation
// is held and outside [0, T], leave the position rows alone, and the overload without them writes the same r_d and
// r_d_dot bit for bit.
TEST(OrientationReference, AngularAccelerationIsTheDerivativeOfTheAngularVelocity) {
  struct Turn {
    const char* robot;
    Eigen::Vector3d start, turn;
  };
  for (const Turn& c : {Turn{"tests/data/robots/planar_laws_pose.toml", {0.0, 0.0, 0.4}, {0.0, 0.0, 0.9}},
                        Turn{"robots/kuka_iiwa14.toml", {0.1, 0.2, 0.3}, {0.3, -0.5, 0.4}},
                        Turn{"robots/kuka_iiwa14.toml", {0.5, -1.2, 2.0}, {-2.0, 1.5, 2.5}}}) {
    SCOPED_TRACE(c.robot);
    const RobotModel robot = load_robot(source_path(c.robot));
    ASSERT_TRUE(robot.has_orientation_rows());
    const bool planar = robot.kind() == ChainKind::kPlanar;
    const int m = robot.reference_dim(), p = planar ? 2 : 3, rest = m - p;
    const KinematicsData kin(robot);  // not read: the orientation is set
    OrientationReference ref, ref3;
    ref.set(c.start);
    ref.set_turn(c.turn);
    ref3.set(c.start);
    ref3.set_turn(c.turn);
    const double T = 10.0, h = 1e-5;
    Eigen::VectorXd r(m), v(m), a(m), r3(m), v3(m), rp(m), vp(m), rm(m), vm(m), ap(m);
    const auto fill = [&] {
      for (Eigen::VectorXd* x : {&r, &v, &a, &r3, &v3, &rp, &vp, &rm, &vm, &ap}) x->setConstant(7.0);
    };
    // The rotation the r_d rows describe.
    const auto rotation = [&](const Eigen::VectorXd& x) {
      return planar ? Eigen::Matrix3d(Eigen::AngleAxisd(x(2), Eigen::Vector3d::UnitZ()))
                    : rotation_from_vector(x.tail<3>());
    };
    double worst = 0.0, worst_omega = 0.0, peak = 0.0;
    for (double t = 0.013; t < T; t += 0.0371) {
      fill();
      ref.evaluate(robot, kin, t, T, p, r, v, a);
      ref3.evaluate(robot, kin, t, T, p, r3, v3);
      EXPECT_EQ(r, r3);  // bit for bit
      EXPECT_EQ(v, v3);
      EXPECT_EQ(a.head(p), Eigen::VectorXd::Constant(p, 7.0));  // the path's rows are not the reference's
      ref.evaluate(robot, kin, t + h, T, p, rp, vp, ap);
      ref.evaluate(robot, kin, t - h, T, p, rm, vm, ap);
      worst = std::max(worst, ((vp - vm).tail(rest) / (2 * h) - a.tail(rest)).cwiseAbs().maxCoeff());
      const Eigen::VectorXd expected = c.turn.tail(rest) * 2.0 * M_PI * std::sin(2.0 * M_PI * t / T) / (T * T);
      EXPECT_LT((a.tail(rest) - expected).cwiseAbs().maxCoeff(), 1e-15);
      peak = std::max(peak, a.tail(rest).cwiseAbs().maxCoeff());
      // r_d_dot's rows are the world angular velocity of r_d's rotation: R(t+h) R(t-h)^T = exp(2h [omega]).
      const Eigen::AngleAxisd step(rotation(rp) * rotation(rm).transpose());
      const Eigen::Vector3d omega = step.angle() * step.axis() / (2 * h);
      for (int i = 0; i < rest; ++i) {  // the last `rest` entries of each (an element loop: GCC 12 misreads tail())
        worst_omega = std::max(worst_omega, std::abs(omega(3 - rest + i) - v(v.size() - rest + i)));
      }
    }
    // |a| <= |turn| 2 pi / T^2 (~0.16 rad/s^2 at most here); the differences' error is O(h^2) and roundoff ~1e-11.
    EXPECT_GT(peak, 0.9 * c.turn.tail(rest).cwiseAbs().maxCoeff() * 2.0 * M_PI / (T * T));
    EXPECT_LT(worst, 1e-9);
    EXPECT_LT(worst_omega, 1e-8);
    // Outside [0, T] the turn has not started or is over: the rows rest.
    for (double t : {-1.0, -1e-9, T + 1e-9, T + 1.0}) {
      fill();
      ref.evaluate(robot, kin, t, T, p, r, v, a);
      EXPECT_EQ(a.tail(rest), Eigen::VectorXd::Zero(rest)) << "t = " << t;
      EXPECT_EQ(v.tail(rest), Eigen::VectorXd::Zero(rest)) << "t = " << t;
    }
    // Held: zero.
    ref.set_turn(Eigen::Vector3d::Zero());
    fill();
    ref.evaluate(robot, kin, 2.5, T, p, r, v, a);
    EXPECT_EQ(a.tail(rest), Eigen::VectorXd::Zero(rest));
    EXPECT_EQ(r.tail(rest), c.start.tail(rest));
  }
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

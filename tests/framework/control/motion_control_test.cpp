// Motion a real arm can follow (issue 25): the acceleration and jerk constraints, braking after a failed step and the
// recovery after it, no velocity jump in any shipped scenario (nor under forced failures), and the acceleration-level
// scheme (its task, J_dot theta_dot against central differences, MAN against an independent solve).

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "alloc_counter.hpp"
#include "mujoco_configs.hpp"
#include "qp_util.hpp"
#include "redres/config/toml_reader.hpp"
#include "redres/constraints/joint_acceleration_limits.hpp"
#include "redres/control/controller.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/run/run_summary.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"
#include "scenario_text.hpp"
#include "task_rows.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

std::unique_ptr<RobotModel> panda() {
  return std::make_unique<RobotModel>(load_robot(source_path("robots/franka_panda.toml")));
}

// A constraint that makes every step with t in [from, to) infeasible (an empty box for joint 1): forced failures.
struct NoConfig {
  static const Schema<NoConfig>& schema() {
    static const Schema<NoConfig> s{{}};
    return s;
  }
};
class Blocker final : public Configured<Constraint, NoConfig> {
 public:
  Blocker(double from, double to) : Configured("test_blocker", NoConfig{}), from_(from), to_(to) {}
  [[nodiscard]] bool supports(ControlOrder /*order*/) const override { return true; }

 private:
  void add_to(const Context& ctx, QpBuilder& b, PluginData* /*data*/) const override {
    if (ctx.t >= from_ && ctx.t < to_) b.intersect_bound(0, 1.0, -1.0);
  }
  double from_, to_;
};

// A scheme read from `text` with a Blocker added.
std::unique_ptr<Scheme> with_blocker(const std::string& text, const RobotModel& robot, double from, double to) {
  auto file = parse_toml_string(text, "scheme.toml");
  const TableReader root = TableReader::root(file);
  std::vector<std::unique_ptr<Objective>> objectives;
  std::vector<std::unique_ptr<Constraint>> constraints;
  for (const TableReader& t : root.tables("objectives")) objectives.push_back(make_objective(t, robot));
  for (const TableReader& t : root.tables("constraints")) constraints.push_back(make_constraint(t, robot));
  constraints.push_back(std::make_unique<Blocker>(from, to));
  return std::make_unique<Scheme>(robot, std::move(objectives), std::move(constraints));
}

Eigen::VectorXd accel_limit(const RobotModel& robot, const Eigen::VectorXd& theta, bool upper) {
  Eigen::VectorXd lo(robot.dof()), hi(robot.dof());
  robot.acceleration_limits(theta, lo, hi);
  return upper ? hi : lo;
}

const std::string kPlain = objective_entry("min_velocity_norm") + constraint_entry("joint_acceleration_limits");

TEST(AccelerationLimits, BoundsComeFromThePreviousCommandAndEveryJointCanStillStop) {
  const auto robot = panda();
  const int n = robot->dof();
  const auto scheme = scheme_from_text(kPlain, *robot);
  auto engine = make_engine("newton");
  const double tau = 0.01;
  Controller ctrl(*robot, *scheme, *engine, nullptr, 1.0, tau);
  StepOutput out = ctrl.make_output();
  const Eigen::VectorXd r = Eigen::VectorXd::Zero(robot->reference_dim());
  Eigen::VectorXd theta = robot->home();
  theta(0) = robot->upper_limits()(0) - 0.02;  // joint 1 near its upper limit
  ctrl.step(theta, 0.0, r, r, out);
  Eigen::VectorXd prev = Eigen::VectorXd::Constant(n, 0.3);
  prev(0) = 0.5;  // moving towards that limit
  ctrl.set_applied(prev);
  ctrl.step(theta, tau, r, r, out);
  const Eigen::VectorXd a_lo = accel_limit(*robot, theta, false), a_hi = accel_limit(*robot, theta, true);
  const QpProblem& qp = ctrl.qp();
  for (int j = 1; j < n; ++j) {  // far from the limits: prev +- tau a
    EXPECT_NEAR(qp.lo(j), prev(j) + tau * a_lo(j), 1e-12) << "joint " << j + 1;
    EXPECT_NEAR(qp.hi(j), prev(j) + tau * a_hi(j), 1e-12) << "joint " << j + 1;
  }
  // Joint 1: the braking term binds below prev + tau a^+, and braking from it at a^- stops before the limit.
  EXPECT_LT(qp.hi(0), prev(0) + tau * a_hi(0) - 1e-3);
  EXPECT_GE(qp.hi(0), prev(0) + tau * a_lo(0) - 1e-12);  // never asks for more than a^- to brake
  double v = qp.hi(0), travelled = 0.0;
  while (v > 0.0) {
    travelled += tau * v;
    v += tau * a_lo(0);
  }
  EXPECT_LE(travelled, 0.02 + 1e-12);
  // ... and the bound is the fastest that does, with the jerk ramp counted (the Panda has jerk limits): moving on at
  // x for tau + |a^-| / j^+, then braking at a^-.
  Eigen::VectorXd j_lo(n), j_hi(n);
  robot->jerk_limits(theta, j_lo, j_hi);
  const double a = -a_lo(0), c = tau + a / j_hi(0);
  EXPECT_NEAR(qp.hi(0), stopping_speed(0.02, a, c), 1e-12);
  EXPECT_NEAR(c * qp.hi(0) + qp.hi(0) * qp.hi(0) / (2.0 * a), 0.02, 1e-12);
  EXPECT_EQ(out.info.status, SolverStatus::kSolved);
  for (int j = 0; j < n; ++j) {
    EXPECT_NEAR(out.theta_ddot(j), (out.theta_dot(j) - prev(j)) / tau, 1e-9);
    EXPECT_LE(out.theta_ddot(j), a_hi(j) + 1e-9);
    EXPECT_GE(out.theta_ddot(j), a_lo(j) - 1e-9);
  }
}

TEST(AccelerationLimits, ARobotWithoutThemIsRefusedWithTheJointNamed) {
  const auto robot = std::make_unique<RobotModel>(load_robot(source_path("robots/paper_pushrod_6dof.toml")));
  try {
    (void)scheme_from_text(kPlain, *robot);
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("acceleration_limit"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("joint 1"), std::string::npos) << e.what();
  }
}

TEST(JerkLimits, BoundTheChangeOfAccelerationFromTheLastTwoCommands) {
  const auto robot = panda();
  const int n = robot->dof();
  const auto scheme = scheme_from_text(objective_entry("min_velocity_norm") + constraint_entry("joint_jerk_limits") +
                                           constraint_entry("joint_acceleration_limits", "active = false\n"),
                                       *robot);
  auto engine = make_engine("newton");
  const double tau = 0.001;
  Controller ctrl(*robot, *scheme, *engine, nullptr, 1.0, tau);
  StepOutput out = ctrl.make_output();
  const Eigen::VectorXd r = Eigen::VectorXd::Zero(robot->reference_dim());
  const Eigen::VectorXd theta = robot->home();
  const Eigen::VectorXd p2 = Eigen::VectorXd::Constant(n, 0.10), p1 = Eigen::VectorXd::Constant(n, 0.102);
  ctrl.step(theta, 0.0, r, r, out);
  ctrl.set_applied(p2);
  ctrl.step(theta, tau, r, r, out);
  ctrl.set_applied(p1);
  ctrl.step(theta, 2 * tau, r, r, out);
  Eigen::VectorXd j_lo(n), j_hi(n);
  robot->jerk_limits(theta, j_lo, j_hi);
  for (int j = 0; j < n; ++j) {
    const double a_prev = (p1(j) - p2(j)) / tau;  // 2 rad/s^2
    EXPECT_NEAR(ctrl.qp().lo(j), p1(j) + tau * (a_prev + tau * j_lo(j)), 1e-12) << "joint " << j + 1;
    EXPECT_NEAR(ctrl.qp().hi(j), p1(j) + tau * (a_prev + tau * j_hi(j)), 1e-12) << "joint " << j + 1;
  }
  // The MVN answer brakes as hard as the jerk allows.
  EXPECT_EQ(out.info.status, SolverStatus::kSolved);
  EXPECT_NEAR(out.theta_dot(0), ctrl.qp().lo(0), 1e-9);
}

// Joint centering drives joints 1 and 4 at full speed onto their position limits (no angle margin). Near the limit
// the braking term of joint_acceleration_limits asks for more deceleration than the jerk limit allows in one step;
// the jerk bounds yield (they are added last and clipped to the others), so no step is infeasible, the positions and
// accelerations stay within their limits, and the jerk exceeds its limit only on those steps.
TEST(JerkLimits, YieldToTheBrakingTermAtAPositionLimit) {
  const auto robot = panda();
  const int n = robot->dof();
  Eigen::VectorXd ref = robot->home();
  ref(0) = robot->upper_limits()(0) + 1.0;
  ref(3) = robot->upper_limits()(3) + 1.0;
  std::ostringstream centering;
  centering << "lambda = 20.0\ntheta_ref = [";
  for (int j = 0; j < n; ++j) centering << (j > 0 ? ", " : "") << ref(j);
  centering << "]\n";
  // The jerk limits listed first: the scheme still adds them after the others.
  const auto scheme =
      scheme_from_text(constraint_entry("joint_jerk_limits") + objective_entry("min_velocity_norm") +
                           objective_entry("joint_centering", centering.str()) +
                           constraint_entry("joint_velocity_limits") + constraint_entry("joint_acceleration_limits"),
                       *robot);
  auto engine = make_engine("newton");
  const double tau = 0.001;
  Controller ctrl(*robot, *scheme, *engine, nullptr, 3.0, tau);
  StepOutput out = ctrl.make_output();
  const Eigen::VectorXd r = Eigen::VectorXd::Zero(robot->reference_dim());
  Eigen::VectorXd theta = robot->home(), prev = Eigen::VectorXd::Zero(n), prev2 = prev;
  Eigen::VectorXd a_lo(n), a_hi(n), j_lo(n), j_hi(n);
  int over_jerk = 0;
  for (int k = 0; k <= 3000; ++k) {
    ctrl.step(theta, k * tau, r, r, out);
    ASSERT_EQ(out.info.status, SolverStatus::kSolved) << "t = " << k * tau << ": " << out.info.diagnosis;
    robot->acceleration_limits(theta, a_lo, a_hi);
    robot->jerk_limits(theta, j_lo, j_hi);
    bool jerk_exceeded = false;
    for (int j = 0; j < n; ++j) {
      const double a = (out.theta_dot(j) - prev(j)) / tau, a_prev = (prev(j) - prev2(j)) / tau;
      EXPECT_GE(a, a_lo(j) - 1e-6) << "t = " << k * tau << ", joint " << j + 1;
      EXPECT_LE(a, a_hi(j) + 1e-6) << "t = " << k * tau << ", joint " << j + 1;
      const double jerk = (a - a_prev) / tau;
      jerk_exceeded = jerk_exceeded || jerk < j_lo(j) * (1.0 + 1e-9) - 1e-6 || jerk > j_hi(j) * (1.0 + 1e-9) + 1e-6;
    }
    over_jerk += jerk_exceeded ? 1 : 0;
    theta += tau * out.theta_dot;
    ASSERT_LE(theta(0), robot->upper_limits()(0) + 1e-9) << "t = " << k * tau;
    ASSERT_LE(theta(3), robot->upper_limits()(3) + 1e-9) << "t = " << k * tau;
    prev2 = prev;
    prev = out.theta_dot;
  }
  // Both joints reached their limits and stopped there.
  EXPECT_GT(theta(0), robot->upper_limits()(0) - 1e-3);
  EXPECT_GT(theta(3), robot->upper_limits()(3) - 1e-3);
  EXPECT_LT(prev.norm(), 1e-6);
  // The yielding happened (the case is exercised) and stayed rare.
  EXPECT_GE(over_jerk, 1);
  EXPECT_LE(over_jerk, 20);
}

TEST(Brake, AFailedStepDeceleratesAlongThePreviousCommandWithinTheLimits) {
  const auto robot = panda();
  const int n = robot->dof();
  const auto scheme = with_blocker(kPlain, *robot, 0.015, 10.0);
  auto engine = make_engine("newton");
  const double tau = 0.01;
  Controller ctrl(*robot, *scheme, *engine, nullptr, 10.0, tau);
  EXPECT_EQ(ctrl.failure_policy(), FailurePolicy::kBrake);  // the default for a robot with acceleration limits
  StepOutput out = ctrl.make_output();
  const Eigen::VectorXd r = Eigen::VectorXd::Zero(robot->reference_dim());
  Eigen::VectorXd theta = robot->home();
  ctrl.step(theta, 0.0, r, r, out);
  EXPECT_EQ(out.info.status, SolverStatus::kSolved) << out.info.diagnosis;
  Eigen::VectorXd prev(n);
  prev << 0.5, -0.4, 0.3, 0.6, -0.2, 0.1, 0.7;  // the arm moves at prev (two commands: no acceleration) ...
  ctrl.set_applied(prev);
  ctrl.step(theta, tau, r, r, out);
  ctrl.set_applied(prev);
  int braked = 0;
  for (int step = 2; step < 40; ++step) {  // ... and every later step fails
    const double t = step * tau;
    ctrl.step(theta, t, r, r, out);
    ASSERT_EQ(out.info.status, SolverStatus::kBraked) << out.info.diagnosis;
    ++braked;
    EXPECT_NE(out.info.diagnosis.find("test_blocker"), std::string::npos) << out.info.diagnosis;
    const Eigen::VectorXd a_lo = accel_limit(*robot, theta, false), a_hi = accel_limit(*robot, theta, true);
    // Along the previous command: theta_dot = s prev, 0 <= s <= 1, as low as one joint's limit lets it be.
    const double s = prev.norm() > 0.0 ? out.theta_dot.dot(prev) / prev.squaredNorm() : 0.0;
    EXPECT_LE((out.theta_dot - s * prev).norm(), 1e-12);
    EXPECT_GE(s, 0.0);
    EXPECT_LE(s, 1.0);
    bool at_limit = s == 0.0;
    for (int j = 0; j < n; ++j) {  // never a jump
      const double a = (out.theta_dot(j) - prev(j)) / tau;
      EXPECT_LE(a, a_hi(j) + 1e-9) << "t = " << t << ", joint " << j + 1;
      EXPECT_GE(a, a_lo(j) - 1e-9) << "t = " << t << ", joint " << j + 1;
      EXPECT_NEAR(out.theta_ddot(j), a, 1e-9);
      at_limit = at_limit || std::abs(a - a_lo(j)) < 1e-9 || std::abs(a - a_hi(j)) < 1e-9;
    }
    EXPECT_TRUE(at_limit) << "t = " << t << ": s = " << s << " is not the hardest braking the limits allow";
    theta += tau * out.theta_dot;
    prev = out.theta_dot;
  }
  EXPECT_EQ(braked, 38);
  EXPECT_EQ(prev.norm(), 0.0);  // at rest: 0.7 rad/s at 20 rad/s^2 takes 4 steps, 0.4 at 7.5 takes 6
}

// A run blocked for 0.5 s brakes, then catches up: after the window the task is tracked again.
void expect_recovery(const std::string& policy) {
  Scenario s = load_scenario(source_path("configs/panda_helix.toml"),
                             {"duration=6.0", "solver.on_infeasible=\"" + policy + "\""});
  s.scheme = with_blocker(objective_entry("min_velocity_norm") + constraint_entry("task_tracking", "gain = 8.0\n") +
                              constraint_entry("joint_angle_margin", "kappa = 4.0\nmargin = 0.05\n") +
                              constraint_entry("joint_velocity_limits") +
                              constraint_entry("joint_acceleration_limits") + constraint_entry("joint_jerk_limits"),
                          *s.robot, 2.0, 2.5);
  const RunResult run = simulate(s);
  EXPECT_EQ(run.braked_steps, 50) << policy;
  EXPECT_EQ(run.failures, 50) << policy;
  EXPECT_GT(run.relaxed_steps, 0) << policy << ": the catch-up relaxes the task";
  EXPECT_EQ(run.steps_over_acceleration_limit, 0) << policy;
  EXPECT_FALSE(run.stopped);
  const std::size_t c = run.trajectory.column("position_error"), ct = run.trajectory.column("t");
  double during = 0.0, late = 0.0;
  for (std::size_t r = 0; r < run.trajectory.size(); ++r) {
    const double t = run.trajectory(r, ct), e = run.trajectory(r, c);
    if (t >= 2.0 && t <= 3.0) during = std::max(during, e);
    if (t >= 4.5) late = std::max(late, e);
  }
  EXPECT_GT(during, 5e-3) << policy << ": the blocked arm falls behind";
  EXPECT_LT(late, 1e-3) << policy << ": and tracks again once nothing blocks it";
  EXPECT_LT(late, during / 20.0) << policy;
  // The summary says how long the task was lost (every row not solved as asked: braked, then relaxed while catching
  // up) and when it came back.
  const SolverStats stats = summarise(s, run).solver;
  const std::size_t cs = run.trajectory.column("solver_status");
  long lost = 0;
  double back = -1.0;
  for (std::size_t r = 0; r < run.trajectory.size(); ++r) {
    const bool solved = run.trajectory(r, cs) == 0.0;
    lost += solved ? 0 : 1;
    if (solved && back < 0.0 && run.trajectory(r, ct) > 2.5) back = run.trajectory(r, ct);
  }
  EXPECT_NEAR(stats.task_lost_time, static_cast<double>(lost) * s.tau, 1e-12) << policy;
  EXPECT_GE(lost, 50 + run.relaxed_steps) << policy;
  EXPECT_GE(stats.task_lost_spells, 1) << policy;
  EXPECT_EQ(stats.longest_task_loss.rfind("t = 2 s to ", 0), 0u) << policy << ": " << stats.longest_task_loss;
  std::ostringstream back_text;
  back_text << "back at " << back << " s";
  EXPECT_NE(stats.longest_task_loss.find(back_text.str()), std::string::npos)
      << policy << ": " << stats.longest_task_loss;
  EXPECT_GT(back, 2.5) << policy;
  EXPECT_LT(back, 4.5) << policy;
}

TEST(Brake, ARunRecoversAfterAWindowOfFailedStepsUnderBrake) { expect_recovery("brake"); }
TEST(Brake, ARunRecoversAfterAWindowOfFailedStepsUnderRelax) { expect_recovery("relax"); }

TEST(Brake, HoldIsRefusedForARobotWithAccelerationLimitsAndBrakeForOneWithout) {
  const auto message = [](const std::filesystem::path& file, const std::vector<std::string>& o) {
    try {
      (void)load_scenario(file, o);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("(loaded)");
  };
  const std::string hold = message(source_path("configs/panda_helix.toml"), {"solver.on_infeasible=\"hold\""});
  EXPECT_NE(hold.find("velocity jump"), std::string::npos) << hold;
  EXPECT_NE(hold.find("on_infeasible"), std::string::npos) << hold;
  const std::string brake = message(source_path("configs/paper_r_tvcmm.toml"), {"solver.on_infeasible=\"brake\""});
  EXPECT_NE(brake.find("acceleration_limit"), std::string::npos) << brake;
  const std::string heun = message(source_path("configs/panda_helix_acceleration.toml"), {"integrator=\"heun\""});
  EXPECT_NE(heun.find("integrator"), std::string::npos) << heun;
  Scenario paper = load_scenario(source_path("configs/paper_r_tvcmm.toml"));
  EXPECT_EQ(paper.on_infeasible, FailurePolicy::kRelax);  // the default for a robot without acceleration limits
}

// Every shipped scenario whose robot gives acceleration limits: no command beyond them, as shipped and with every
// solve forced to fail (an iteration cap of 1), where every step brakes.
TEST(NoVelocityJump, EveryShippedScenarioAndForcedFailures) {
  int checked = 0, turned_off = 0;
  for (const auto& entry : std::filesystem::directory_iterator(source_path("configs"))) {
    if (entry.path().extension() != ".toml") continue;
    if (mujoco_config_without_mujoco(entry.path())) continue;
    Scenario probe = load_scenario(entry.path());
    if (!probe.robot->has_acceleration_limits()) continue;
    // A scenario that turns the robot's acceleration limits off on purpose (to show what they prevent) is not held
    // to them.
    const auto& constraints = probe.scheme->constraints();
    if (std::any_of(constraints.begin(), constraints.end(),
                    [](const auto& c) { return c->type() == "joint_acceleration_limits" && !c->active(); })) {
      ++turned_off;
      continue;
    }
    // At most 600 steps of each (the same path, faster: harder on the limits).
    const int steps = std::min(probe.steps(), 600);
    const std::string duration = "duration=" + std::to_string(steps * probe.tau);
    for (const bool forced : {false, true}) {
      std::vector<std::string> o = {duration};
      if (forced) {  // no solve converges: one projection iteration to a tolerance of 1e-14
        o.emplace_back("solver.engine=\"projection\"");
        o.emplace_back("solver.max_iterations=1");
        o.emplace_back("solver.tolerance=1e-14");
      }
      Scenario s = load_scenario(entry.path(), o);
      const RunResult run = simulate(s);
      SCOPED_TRACE(entry.path().filename().string() + (forced ? " (forced failures)" : ""));
      EXPECT_EQ(run.steps_over_acceleration_limit, 0);
      for (double v : run.max_joint_acceleration_violation) EXPECT_LE(v, 1e-9);
      if (forced) {
        EXPECT_GT(run.braked_steps, 0);
      }
      // braked_steps counts every braked row, the last one's too.
      const std::size_t status = run.trajectory.column("solver_status");
      int braked_rows = 0;
      for (std::size_t r = 0; r < run.trajectory.size(); ++r) braked_rows += run.trajectory(r, status) == 7.0 ? 1 : 0;
      EXPECT_EQ(run.braked_steps, braked_rows);
      ++checked;
    }
  }
  EXPECT_GE(checked, 8);     // the Panda's scenarios, twice each
  EXPECT_LE(turned_off, 1);  // panda_helix_fast_unlimited_mujoco.toml alone
}

TEST(AccelerationLevel, TheTaskHoldsOnASmoothPath) {
  Scenario s = load_scenario(source_path("configs/panda_helix_acceleration.toml"));
  const RunResult run = simulate(s);
  EXPECT_EQ(run.failures, 0);
  const std::size_t c = run.trajectory.column("position_error");
  double worst = 0.0;
  for (std::size_t r = 0; r < run.trajectory.size(); ++r) worst = std::max(worst, run.trajectory(r, c));
  EXPECT_LT(worst, 1e-5);
  EXPECT_EQ(run.steps_over_acceleration_limit, 0);
  // theta_ddot is x, theta_dot integrates it.
  const std::size_t a = run.trajectory.column("theta_ddot_2"), v = run.trajectory.column("theta_dot_2");
  for (std::size_t r = 1; r < run.trajectory.size() - 1; ++r) {
    EXPECT_NEAR(run.trajectory(r, v), run.trajectory(r - 1, v) + s.tau * run.trajectory(r, a), 1e-12);
  }
}

// An acceleration-level scheme of the task rows alone (the robot's motion limits off).
const std::string kTaskOnly = "[scheme]\nlevel = \"acceleration\"\n" + objective_entry("min_acceleration_norm") +
                              constraint_entry("task_tracking") +
                              constraint_entry("joint_acceleration_limits", "active = false\n") +
                              constraint_entry("joint_jerk_limits", "active = false\n");

// At theta with velocity v, r_d = f, r_d_dot = J v, r_d_ddot = 0: the task rows' d is -J_dot v; against central
// differences of J along v.
TEST(AccelerationLevel, JdotThetaDotMatchesCentralDifferences) {
  const auto robot = panda();
  const int n = robot->dof();
  const auto scheme = scheme_from_text(kTaskOnly, *robot);
  auto engine = make_engine("newton");
  std::mt19937 rng(25);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    Controller ctrl(*robot, *scheme, *engine, nullptr, 1.0, 0.01);
    StepOutput out = ctrl.make_output();
    const Eigen::VectorXd theta = random_inside(*robot, rng, 0.1);
    Eigen::VectorXd v(n);
    for (int j = 0; j < n; ++j) v(j) = u(rng);
    KinematicsData k(*robot);
    compute_kinematics(*robot, theta, k, KinematicsLevel::kJacobian);
    const Eigen::VectorXd jdv = testing::jdot_v(*robot, theta, v);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(robot->reference_dim());
    ctrl.step(theta, 0.0, k.f, zero, zero, out);
    ctrl.set_applied(v);  // the velocity at the next step
    ctrl.step(theta, 0.01, k.f, k.J * v, zero, out);
    const Eigen::VectorXd d = ctrl.qp().d;
    ASSERT_EQ(d.size(), jdv.size());
    EXPECT_LT((d + jdv).norm(), 1e-7 * (1.0 + jdv.norm()))
        << "d = " << d.transpose() << "\n-J_dot v = " << -jdv.transpose();
    EXPECT_GT(jdv.norm(), 1e-3);  // a real test: the term is not zero
  }
}

// The same for a task that names a subset of the rows (x and z): KinematicsData::J holds those rows only, and the
// acceleration-level rows must read J theta_dot and J_dot theta_dot by task row, not by reference row.
TEST(AccelerationLevel, JdotThetaDotOfASubsetTaskReadsItsOwnRows) {
  const RobotModel robot = testing::robot_with_task("robots/franka_panda.toml", "[\"x\", \"z\"]");
  ASSERT_EQ(robot.task_dim(), 2);
  const auto scheme = scheme_from_text(kTaskOnly, robot);
  auto engine = make_engine("newton");
  std::mt19937 rng(52);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    Controller ctrl(robot, *scheme, *engine, nullptr, 1.0, 0.01);
    StepOutput out = ctrl.make_output();
    const Eigen::VectorXd theta = random_inside(robot, rng, 0.1);
    Eigen::VectorXd v(robot.dof());
    for (int j = 0; j < robot.dof(); ++j) v(j) = u(rng);
    KinematicsData k(robot);
    compute_kinematics(robot, theta, k, KinematicsLevel::kJacobian);
    const Eigen::VectorXd jdv = testing::jdot_v(robot, theta, v);  // the task rows x, z
    ASSERT_EQ(jdv.size(), 2);
    // r_d_dot's reference rows x, y, z: the task's velocity in x and z, anything in y (not a task row).
    const Eigen::VectorXd jv = k.J * v;
    Eigen::VectorXd r_d_dot(3), zero = Eigen::VectorXd::Zero(3);
    r_d_dot << jv(0), 7.0, jv(1);
    ctrl.step(theta, 0.0, k.f, zero, zero, out);
    ctrl.set_applied(v);
    ctrl.step(theta, 0.01, k.f, r_d_dot, zero, out);
    EXPECT_LT((ctrl.qp().d + jdv).norm(), 1e-7 * (1.0 + jdv.norm()))
        << ctrl.qp().d.transpose() << " vs " << -jdv.transpose();
  }
}

// MAN at the acceleration level (W = I, zeta = damping theta_dot, J x = d, bounds on x) at random states: the
// controller's answer meets the KKT conditions and equals NLopt's.
TEST(AccelerationLevel, MinimumAccelerationNormAgreesWithAnIndependentSolve) {
  const auto robot = panda();
  const int n = robot->dof();
  const auto scheme = scheme_from_text(
      "[scheme]\nlevel = \"acceleration\"\n" + objective_entry("min_acceleration_norm", "damping = 2.0\n") +
          constraint_entry("task_tracking") + constraint_entry("joint_velocity_limits") +
          constraint_entry("joint_acceleration_limits"),
      *robot);
  auto engine = make_engine("newton");
  auto nlopt = make_engine("nlopt");
  std::mt19937 rng(2025);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int compared = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Controller ctrl(*robot, *scheme, *engine, nullptr, 1.0, 0.01);
    StepOutput out = ctrl.make_output();
    const Eigen::VectorXd theta = random_inside(*robot, rng, 0.3);
    Eigen::VectorXd v(n);
    for (int j = 0; j < n; ++j) v(j) = 0.3 * u(rng);
    KinematicsData k(*robot);
    compute_kinematics(*robot, theta, k, KinematicsLevel::kJacobian);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(robot->reference_dim());
    Eigen::VectorXd r_d_dot = k.J * v, r_d_ddot(robot->reference_dim());
    for (int r = 0; r < r_d_ddot.size(); ++r) r_d_ddot(r) = 0.5 * u(rng);
    ctrl.step(theta, 0.0, k.f, zero, zero, out);
    ctrl.set_applied(v);
    ctrl.step(theta, 0.01, k.f, r_d_dot, r_d_ddot, out);
    if (out.info.status != SolverStatus::kSolved) continue;
    const QpProblem& qp = ctrl.qp();
    EXPECT_TRUE(qp.zeta.isApprox(2.0 * v, 1e-12));  // damping theta_dot
    EXPECT_LT(testing::kkt_residual(qp, ctrl.result()), 1e-7);
    SolverResult other;
    nlopt->setup(qp.n(), qp.m_eq(), qp.m_in(), other);
    nlopt->solve(qp, other);
    ASSERT_EQ(other.info.status, SolverStatus::kSolved) << other.info.diagnosis;
    EXPECT_LT((other.x - out.theta_ddot).norm(), 1e-5 * (1.0 + out.theta_ddot.norm()));
    EXPECT_TRUE(out.theta_dot.isApprox(v + 0.01 * out.theta_ddot, 1e-12));
    ++compared;
  }
  EXPECT_GE(compared, 15);
}

// Runs of robots without motion limits (the paper's among them) keep their policy and their numbers: theta(T) as the
// code before the motion limits computed it, recorded from its release build. Bit for bit in an optimised build
// (NDEBUG, what CI's release job and `redres run` use); an unoptimised one may round differently, so 1e-12 there.
TEST(VelocityLevel, RunsWithoutMotionLimitsAreUnchangedBitForBit) {
  struct Reference {
    const char* config;
    std::vector<double> final_theta;
  };
  const std::vector<Reference> references = {
      {"configs/paper_r_tvcmm.toml",
       {0x1.d3c39c5757276p-1, 0x1.63f145fd6ea07p-4, 0x1.c2b49cd03c64ap-3, 0x1.84a996c5a720cp-2, 0x1.fff084deeaadfp-3,
        0x1.268cef5e1d28fp-4}},
      {"configs/paper_r_obstacle.toml",
       {0x1.d3c5a50691e1cp-1, 0x1.63f145fd647ddp-4, 0x1.c282f85e76b2fp-3, 0x1.84d13a18a6007p-2, 0x1.ffabaabd9fe0bp-3,
        0x1.2707ef6bb7a98p-4}},
      {"configs/iiwa_pose_circle.toml",
       {0x1.3c3c49bb3d9a8p-11, 0x1.0c1502476d6a6p-1, -0x1.b7e2f2a5986aap-11, -0x1.921fa5f1f86bfp+0,
        0x1.fbef7984dd610p-12, 0x1.0c1546db50909p+0, -0x1.7f66eb6ea08e4p-12}},
  };
  for (const Reference& ref : references) {
    SCOPED_TRACE(ref.config);
    Scenario s = load_scenario(source_path(ref.config));
    EXPECT_FALSE(s.robot->has_acceleration_limits());
    EXPECT_EQ(s.on_infeasible, FailurePolicy::kRelax);  // the default, which changes nothing on a run that never fails
    const RunResult run = simulate(s);
    const Eigen::VectorXd theta = recorded_theta(*s.robot, run.trajectory, run.trajectory.size() - 1);
    ASSERT_EQ(theta.size(), static_cast<Eigen::Index>(ref.final_theta.size()));
    for (Eigen::Index j = 0; j < theta.size(); ++j) {
#ifdef NDEBUG
      EXPECT_EQ(theta(j), ref.final_theta[static_cast<std::size_t>(j)]) << "joint " << j + 1;
#else
      EXPECT_NEAR(theta(j), ref.final_theta[static_cast<std::size_t>(j)], 1e-12) << "joint " << j + 1;
#endif
    }
  }
}

// The per-step path of the new machinery allocates nothing: the acceleration and jerk constraints with relaxed steps
// (the 10x helix), braked steps (every solve failing), measured velocities, and the acceleration level.
TEST(MotionRealTime, StepsWithLimitsBrakingAndTheAccelerationLevelAllocateNothing) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  struct Case {
    const char* config;
    std::vector<std::string> overrides;
    SolverStatus expect;  // a status the case must see
  };
  const std::vector<Case> cases = {
      {"configs/panda_helix_fast.toml", {}, SolverStatus::kRelaxed},
      {"configs/panda_helix_fast.toml",
       {"solver.engine=\"projection\"", "solver.max_iterations=1", "solver.tolerance=1e-14",
        "solver.on_infeasible=\"brake\""},
       SolverStatus::kBraked},
      {"configs/panda_helix_acceleration.toml", {}, SolverStatus::kSolved},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.config);
    Scenario s = load_scenario(source_path(c.config), c.overrides);
    const auto ctrl = Controller::from_scenario(s);
    StepOutput out = ctrl->make_output();
    Eigen::VectorXd theta = s.theta0, velocity = Eigen::VectorXd::Zero(s.robot->dof());
    ctrl->step(theta, 0.0, out);
    long allocations = 0;
    int seen = 0;
    for (int k = 1; k < 1500; ++k) {
      {
        const testing::AllocationCounter counter;
        if (k % 2 == 0) {
          ctrl->step(theta, velocity, k * s.tau, out);
        } else {
          ctrl->step(theta, k * s.tau, out);
        }
        allocations += counter.count();
      }
      seen += out.info.status == c.expect ? 1 : 0;
      theta += s.tau * out.theta_dot;
      velocity = out.theta_dot;
    }
    EXPECT_GT(seen, 0) << "the case makes " << to_string(c.expect) << " steps";
    EXPECT_EQ(allocations, 0);
  }
}

}  // namespace
}  // namespace redres

// The braking law of a failed step (control/brake.hpp), on its own: a case worked by hand, and properties over random
// states: the braking command keeps every acceleration limit, no smaller scale does, the velocity limits hold where the
// previous velocity was within them, and jerk limits that can hold with the others do.

#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include "redres/control/brake.hpp"
#include "redres/control/failure_policy.hpp"

namespace redres {
namespace {

struct BrakeCase {
  Eigen::VectorXd b, a_lo, a_hi, v_lo, v_hi, j_lo, j_hi, prev, prev2;
  double tau = 0.01;
  BrakeInput input(bool jerk) const {
    BrakeInput in;
    in.velocity = &b;
    in.acceleration_lower = &a_lo;
    in.acceleration_upper = &a_hi;
    in.velocity_lower = &v_lo;
    in.velocity_upper = &v_hi;
    if (jerk) {
      in.jerk_lower = &j_lo;
      in.jerk_upper = &j_hi;
    }
    in.previous = &prev;
    in.previous2 = &prev2;
    in.tau = tau;
    return in;
  }
};

BrakeCase two_joints() {
  BrakeCase c;
  c.b = Eigen::Vector2d(1.0, -2.0);
  c.a_lo = Eigen::Vector2d::Constant(-10.0);
  c.a_hi = Eigen::Vector2d::Constant(10.0);
  c.v_lo = Eigen::Vector2d::Constant(-5.0);
  c.v_hi = Eigen::Vector2d::Constant(5.0);
  c.prev = c.b;
  c.prev2 = c.b;
  c.j_lo = Eigen::Vector2d::Constant(-1e3);
  c.j_hi = Eigen::Vector2d::Constant(1e3);
  return c;
}

TEST(BrakingLaw, TheSlowestJointToStopSetsTheScale) {
  // Joint 1 may lose 0.1 rad/s of its 1 (s >= 0.9), joint 2 0.1 of its 2 (s >= 0.95): joint 2 decides.
  const BrakeCase c = two_joints();
  const BrakeScale s = braking_scale(c.input(false));
  EXPECT_NEAR(s.scale, 0.95, 1e-15);
  EXPECT_EQ(s.deciding_joint, 1);
  EXPECT_FALSE(s.jerk_yields);
  // At rest (the previous acceleration zero), a jerk limit of 1e3 rad/s^3 allows 10 rad/s^2 in one step of 10 ms:
  // the acceleration limits still decide.
  const BrakeScale j = braking_scale(c.input(true));
  EXPECT_NEAR(j.scale, 0.95, 1e-15);
  EXPECT_FALSE(j.jerk_yields);
}

TEST(BrakingLaw, AJerkLimitSlowsTheTurnToBraking) {
  // Jerk limit 100 rad/s^3 from rest: the acceleration may reach -1 rad/s^2 in one step, so joint 2 (2 rad/s) keeps
  // s >= 1 - 0.01 / 2 = 0.995, joint 1 s >= 0.99: joint 2 decides.
  BrakeCase c = two_joints();
  c.j_lo.setConstant(-100.0);
  c.j_hi.setConstant(100.0);
  const BrakeScale s = braking_scale(c.input(true));
  EXPECT_NEAR(s.scale, 0.995, 1e-15);
  EXPECT_EQ(s.deciding_joint, 1);
  EXPECT_FALSE(s.jerk_yields);
}

TEST(BrakingLaw, AnArmThatWasAcceleratingDeceleratesAtOnce) {
  // Both joints were accelerating along their motion at 8 rad/s^2 (joint 1: 0.92 -> 1 rad/s; joint 2: -1.92 -> -2);
  // jerk limit 100 rad/s^3 turns that round by at most 1 rad/s^2 in a step of 10 ms, so keeping it would take s > 1
  // (the arm speeding up). The jerk limits yield; s is the acceleration limits' 0.95, as without jerk limits.
  BrakeCase c = two_joints();
  c.j_lo.setConstant(-100.0);
  c.j_hi.setConstant(100.0);
  c.prev2 = Eigen::Vector2d(0.92, -1.92);
  const BrakeScale s = braking_scale(c.input(true));
  EXPECT_TRUE(s.jerk_yields);
  EXPECT_NEAR(s.scale, 0.95, 1e-15);
  EXPECT_EQ(s.deciding_joint, 1);
  // Accelerating at 0.5 rad/s^2 only: the jerk limit reaches -0.5 rad/s^2 in one step, and holds (s < 1).
  c.prev2 = Eigen::Vector2d(1.0 - 0.005, -2.0 + 0.005);
  const BrakeScale gentle = braking_scale(c.input(true));
  EXPECT_FALSE(gentle.jerk_yields);
  EXPECT_NEAR(gentle.scale, 1.0 - 0.01 * 0.5 / 2.0, 1e-12);  // joint 2 (2 rad/s) may lose 0.005 rad/s
  EXPECT_LT(gentle.scale, 1.0);
}

// With jerk limits and any previous acceleration, braking never speeds the arm up, and keeps the acceleration limits.
RC_GTEST_PROP(BrakingLaw, WithJerkLimitsTheArmNeverSpeedsUp, ()) {
  const int n = *rc::gen::inRange(1, 8);
  BrakeCase c;
  c.tau = *rc::gen::element(0.001, 0.01);
  for (Eigen::VectorXd* v : {&c.b, &c.a_lo, &c.a_hi, &c.v_lo, &c.v_hi, &c.j_lo, &c.j_hi, &c.prev, &c.prev2}) {
    v->resize(n);
  }
  for (int j = 0; j < n; ++j) {
    c.b(j) = *rc::gen::inRange(-2000, 2001) / 1000.0;
    c.a_hi(j) = *rc::gen::inRange(1, 2001) / 100.0;
    c.a_lo(j) = -*rc::gen::inRange(1, 2001) / 100.0;
    c.v_hi(j) = 2.5;
    c.v_lo(j) = -2.5;
    c.j_hi(j) = *rc::gen::inRange(10, 5001);
    c.j_lo(j) = -*rc::gen::inRange(10, 5001);
    c.prev(j) = c.b(j);
    c.prev2(j) = c.b(j) - c.tau * *rc::gen::inRange(-2000, 2001) / 100.0;  // a_prev within +-20 rad/s^2
  }
  const BrakeScale s = braking_scale(c.input(true));
  RC_ASSERT(s.scale >= 0.0);
  RC_ASSERT(s.scale <= 1.0);
  for (int j = 0; j < n; ++j) {
    const double a = (s.scale - 1.0) * c.b(j) / c.tau;
    RC_ASSERT(a >= c.a_lo(j) - 1e-9 && a <= c.a_hi(j) + 1e-9);
    if (!s.jerk_yields) {
      const double a_prev = (c.prev(j) - c.prev2(j)) / c.tau;
      RC_ASSERT(a >= a_prev + c.tau * c.j_lo(j) - 1e-6 && a <= a_prev + c.tau * c.j_hi(j) + 1e-6);
    }
  }
}

TEST(BrakingLaw, JointsThatSetNothingAreLeftOut) {
  BrakeCase c = two_joints();
  c.b(0) = 0.0;                                          // at rest
  c.a_lo(1) = -std::numeric_limits<double>::infinity();  // a law outside its range
  const BrakeScale s = braking_scale(c.input(false));
  EXPECT_EQ(s.scale, 0.0);  // nothing holds the arm back: it stops
  EXPECT_EQ(s.deciding_joint, -1);
}

RC_GTEST_PROP(BrakingLaw, KeepsTheAccelerationLimitsAndIsTheSmallestScaleThatDoes, ()) {
  const int n = *rc::gen::inRange(1, 9);
  BrakeCase c;
  c.tau = *rc::gen::element(0.001, 0.01, 0.05);
  c.b.resize(n);
  c.a_lo.resize(n);
  c.a_hi.resize(n);
  c.v_lo.resize(n);
  c.v_hi.resize(n);
  for (int j = 0; j < n; ++j) {
    c.b(j) = *rc::gen::inRange(-3000, 3001) / 1000.0;
    c.a_hi(j) = *rc::gen::inRange(1, 2001) / 100.0;
    c.a_lo(j) = -*rc::gen::inRange(1, 2001) / 100.0;
    c.v_hi(j) = *rc::gen::inRange(1, 4001) / 1000.0;
    c.v_lo(j) = -*rc::gen::inRange(1, 4001) / 1000.0;
  }
  c.prev = c.b;
  c.prev2 = c.b;
  const BrakeScale s = braking_scale(c.input(false));
  RC_ASSERT(s.scale >= 0.0);
  RC_ASSERT(s.scale <= 1.0);
  const auto within = [&](double scale, int j) {
    const double a = (scale - 1.0) * c.b(j) / c.tau;
    return a >= c.a_lo(j) - 1e-9 && a <= c.a_hi(j) + 1e-9;
  };
  for (int j = 0; j < n; ++j) RC_ASSERT(within(s.scale, j));
  if (s.scale > 0.0) {
    // A smaller scale breaks the deciding joint's limit.
    RC_ASSERT(s.deciding_joint >= 0);
    RC_ASSERT(!within(s.scale - 1e-6, s.deciding_joint));
  }
  // A joint within its velocity limits before the step stays within them, where the acceleration limits allow.
  for (int j = 0; j < n; ++j) {
    const double v = s.scale * c.b(j);
    if (c.b(j) >= c.v_lo(j) && c.b(j) <= c.v_hi(j)) RC_ASSERT(v >= c.v_lo(j) - 1e-12 && v <= c.v_hi(j) + 1e-12);
  }
}

TEST(FailurePolicyNames, OneTableReadsAndWritesEveryName) {
  EXPECT_EQ(failure_policy_from_name("hold"), FailurePolicy::kHold);
  EXPECT_EQ(failure_policy_from_name("continue"), FailurePolicy::kHold);  // the older name
  EXPECT_EQ(failure_policy_from_name("stop"), FailurePolicy::kStop);
  EXPECT_EQ(failure_policy_from_name("relax"), FailurePolicy::kRelax);
  EXPECT_EQ(failure_policy_from_name("brake"), FailurePolicy::kBrake);
  for (const FailurePolicy p :
       {FailurePolicy::kHold, FailurePolicy::kStop, FailurePolicy::kRelax, FailurePolicy::kBrake}) {
    EXPECT_EQ(failure_policy_from_name(failure_policy_name(p)), p);
  }
  try {
    (void)failure_policy_from_name("halt");
    FAIL() << "'halt' was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("one of 'hold', 'stop', 'relax', 'continue', 'brake', got 'halt'"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace redres

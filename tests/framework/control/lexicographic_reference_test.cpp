// The test reference for task priorities (tests/support/lexicographic_reference.hpp) checked on its own before it
// checks anything: where no bound is active it agrees with the null-space cascade; a higher level keeps its optimum
// when a lower one conflicts with it; swapping the levels swaps which task is met; bounds and held inequality rows
// hold.

#include <random>

#include <gtest/gtest.h>

#include "lexicographic_reference.hpp"

namespace redres::testing {
namespace {

ReferenceProblem loose(int n) {
  ReferenceProblem p;
  p.lo = Eigen::VectorXd::Constant(n, -1e3);
  p.hi = Eigen::VectorXd::Constant(n, 1e3);
  p.A.resize(0, n);
  p.b.resize(0);
  return p;
}

TEST(LexicographicReference, AgreesWithTheNullSpaceCascadeWhereNoBoundIsActive) {
  std::mt19937 rng(29);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 7;
    ReferenceProblem p = loose(n);
    for (const int rows : {3, 2, 3}) {  // 8 rows on 7 joints: the last level cannot be met
      ReferenceLevel level;
      level.J = Eigen::MatrixXd::NullaryExpr(rows, n, [&] { return g(rng); });
      level.d = Eigen::VectorXd::NullaryExpr(rows, [&] { return g(rng); });
      level.G.resize(0, n);
      level.h.resize(0);
      p.levels.push_back(level);
    }
    const ReferenceSolution s = solve_lexicographic(p, Eigen::VectorXd::Zero(n));
    const Eigen::VectorXd ns = null_space_cascade(p.levels, n);
    // The minimum-norm choice is the null-space cascade's; SLSQP from 0 may end elsewhere in the last level's
    // optimal set only where that set is not a point: here it is (8 rows, 7 joints), so x must agree.
    EXPECT_LT((s.x - ns).norm(), 1e-7) << "trial " << trial;
    EXPECT_LT((p.levels[0].J * s.x - p.levels[0].d).norm(), 1e-7);
    EXPECT_LT((p.levels[1].J * s.x - p.levels[1].d).norm(), 1e-7);
  }
}

TEST(LexicographicReference, AHigherLevelKeepsItsOptimumAndSwappingSwapsTheOutcome) {
  // Two joints, two tasks that cannot both be met: x1 + x2 = 1 and x1 + x2 = 3 (the same row, two targets).
  ReferenceProblem p = loose(2);
  ReferenceLevel a{Eigen::RowVector2d(1.0, 1.0), Eigen::VectorXd::Constant(1, 1.0), Eigen::MatrixXd(0, 2),
                   Eigen::VectorXd(0)};
  ReferenceLevel b{Eigen::RowVector2d(1.0, 1.0), Eigen::VectorXd::Constant(1, 3.0), Eigen::MatrixXd(0, 2),
                   Eigen::VectorXd(0)};
  p.levels = {a, b};
  const ReferenceSolution ab = solve_lexicographic(p, Eigen::Vector2d::Zero());
  EXPECT_NEAR(ab.x.sum(), 1.0, 1e-9);
  p.levels = {b, a};
  const ReferenceSolution ba = solve_lexicographic(p, Eigen::Vector2d::Zero());
  EXPECT_NEAR(ba.x.sum(), 3.0, 1e-9);
}

TEST(LexicographicReference, BoundsAndAHeldInequalityHold) {
  // Level 0: x1 <= 0.2 (an inequality task, met); level 1: x = (1, 1) as near as it can be within x2 <= 0.5.
  ReferenceProblem p;
  p.lo = Eigen::Vector2d(-1.0, -1.0);
  p.hi = Eigen::Vector2d(1.0, 0.5);
  p.A.resize(0, 2);
  p.b.resize(0);
  ReferenceLevel ineq{Eigen::MatrixXd(0, 2), Eigen::VectorXd(0), Eigen::RowVector2d(1.0, 0.0),
                      Eigen::VectorXd::Constant(1, 0.2)};
  ReferenceLevel target{Eigen::Matrix2d::Identity(), Eigen::Vector2d(1.0, 1.0), Eigen::MatrixXd(0, 2),
                        Eigen::VectorXd(0)};
  p.levels = {ineq, target};
  const ReferenceSolution s = solve_lexicographic(p, Eigen::Vector2d::Zero());
  EXPECT_NEAR(s.x(0), 0.2, 1e-8);
  EXPECT_NEAR(s.x(1), 0.5, 1e-8);
}

}  // namespace
}  // namespace redres::testing

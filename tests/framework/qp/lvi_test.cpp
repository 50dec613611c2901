// The LVI engines: KKT conditions on random feasible QPs, agreement between engines (and with NLopt's SLSQP),
// optimality against random feasible points, warm starts, infeasibility reports, and allocation-free solves.

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <nlopt.h>
#include <rapidcheck/gtest.h>

#include "alloc_counter.hpp"
#include "qp_util.hpp"
#include "redres/control/engine_registry.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

using testing::kkt_residual;
using testing::qp_objective;
using testing::random_qp;

struct Solved {
  SolverResult result;
  std::unique_ptr<LviEngine> engine;
};

Solved solve_with(const std::string& engine, const QpProblem& qp, SolverSettings settings = {}) {
  Solved s;
  s.engine = make_engine(engine, settings);
  s.engine->setup(qp.n(), qp.m_eq(), qp.m_in(), s.result);
  s.engine->solve(qp, s.result);
  return s;
}

// A random feasible point: the known one plus a random null-space step of J, kept only if inside every bound.
bool random_feasible_point(std::mt19937& rng, const testing::RandomQp& rq, Eigen::VectorXd& x) {
  const QpProblem& qp = rq.qp;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd step(qp.n());
  for (int i = 0; i < qp.n(); ++i) step(i) = u(rng);
  if (qp.m_eq() > 0) {
    const Eigen::MatrixXd P =
        Eigen::MatrixXd::Identity(qp.n(), qp.n()) - qp.J.transpose() * (qp.J * qp.J.transpose()).ldlt().solve(qp.J);
    step = P * step;
  }
  for (double scale = 1.0; scale > 1e-4; scale *= 0.5) {
    x = rq.feasible + scale * step;
    const bool in_box = ((x - qp.lo).array() >= 0).all() && ((qp.hi - x).array() >= 0).all();
    const bool in_rows = qp.m_in() == 0 || ((qp.b - qp.A * x).array() >= 0).all();
    if (in_box && in_rows) return true;
  }
  return false;
}

RC_GTEST_PROP(LviProperty, EnginesSatisfyKktAndAgree, ()) {
  const int n = *rc::gen::inRange(2, 10);
  const int m_e = *rc::gen::inRange(0, std::min(4, n));
  const int m_i = *rc::gen::inRange(0, 3);
  const bool dense = *rc::gen::inRange(0, 4) == 0;
  std::mt19937 rng(*rc::gen::arbitrary<std::uint32_t>());
  const testing::RandomQp rq = random_qp(rng, n, m_e, m_i, dense);
  // Eq. 15's error bound |u - u*| <= c ||e(u)|| has a constant c that grows with the conditioning of M, so on
  // random QPs the engines are compared at a tighter tolerance than the paper's; the paper's 1e-6 is checked on
  // the paper's own QP family below (PaperFamilyEnginesAgreeAtThePapersTolerance).
  SolverSettings settings;
  settings.tolerance = 1e-8;
  settings.max_iterations = 1000000;

  const Solved proj = solve_with("projection", rq.qp, settings);
  const Solved newton = solve_with("newton", rq.qp, settings);
  const Solved nlopt = solve_with("nlopt", rq.qp, settings);
  for (const Solved* s : {&proj, &newton, &nlopt}) {
    RC_LOG() << s->result.info.engine << ": " << to_string(s->result.info.status) << ", " << s->result.info.iterations
             << " iterations, residual " << s->result.info.residual << " " << s->result.info.diagnosis << "\n";
  }
  RC_ASSERT(proj.result.info.status == SolverStatus::kSolved);
  RC_ASSERT(newton.result.info.status == SolverStatus::kSolved);
  RC_ASSERT(proj.result.info.residual <= settings.tolerance);
  // projection reports ||e|| of its final iterate and returns that iterate's x projected onto the box; the
  // residual at the returned point stays of the order of the tolerance.
  RC_ASSERT(lvi_residual(rq.qp, proj.result, settings.varpi) <= 10.0 * settings.tolerance);

  RC_ASSERT(kkt_residual(rq.qp, proj.result) <= 1e-7);
  const double kkt_newton = kkt_residual(rq.qp, newton.result);
  // newton itself solves every problem of the family (no fallback), exactly.
  RC_ASSERT(newton.result.info.engine == "newton");
  RC_ASSERT(kkt_newton <= 1e-10);
  RC_ASSERT(lvi_residual(rq.qp, newton.result, settings.varpi) <= 1e-10);
  RC_ASSERT((proj.result.x - newton.result.x).cwiseAbs().maxCoeff() <= 1e-5);
  // SLSQP is an independent method on the QP itself.
  RC_ASSERT((nlopt.result.x - newton.result.x).cwiseAbs().maxCoeff() <= 1e-5);

  // No feasible point does better.
  const double best = qp_objective(rq.qp, newton.result.x);
  for (int k = 0; k < 20; ++k) {
    Eigen::VectorXd x;
    if (random_feasible_point(rng, rq, x)) RC_ASSERT(best <= qp_objective(rq.qp, x) + 1e-9);
  }
}

// newton on the QPs collision constraints make: up to 16 inequality rows, often several active at once, and a
// dense W in half of the problems; W scaled by up to 1e4 and zeta by up to 1e3 (large multipliers), and a quarter
// of the bounds infinite on one side. newton itself (never
// the fallback) meets the KKT conditions to 1e-10 relative to the data's size, agrees with NLopt's SLSQP (an
// independent method on the QP itself), and no random feasible point does better. (projection is left out: on the
// nearly degenerate problems of this family it needs far more than 10^6 iterations.)
RC_GTEST_PROP(LviProperty, NewtonSolvesManyInequalityRowsExactly, ()) {
  const int n = *rc::gen::inRange(2, 10);
  const int m_e = *rc::gen::inRange(0, std::min(4, n));
  const int m_i = *rc::gen::element(1, 2, 4, 8, 16);
  const bool dense = *rc::gen::arbitrary<bool>();
  const double w_scale = *rc::gen::element(1.0, 1e2, 1e4);
  const double zeta_scale = *rc::gen::element(1.0, 1.0, 1e3);
  std::mt19937 rng(*rc::gen::arbitrary<std::uint32_t>());
  testing::RandomQp rq = random_qp(rng, n, m_e, m_i, dense);
  rq.qp.W *= w_scale;
  rq.qp.zeta *= zeta_scale;
  std::uniform_int_distribution<int> side(0, 7);
  for (int i = 0; i < n; ++i) {
    const int k = side(rng);
    if (k == 0) rq.qp.lo(i) = -kNoBound;
    if (k == 1) rq.qp.hi(i) = kNoBound;
  }
  const double size = 1.0 + std::max(w_scale, zeta_scale);
  SolverSettings settings;
  settings.tolerance = 1e-8;
  const Solved newton = solve_with("newton", rq.qp, settings);
  // SLSQP stops on its own tests, a little short of 1e-8 on problems with many rows, and early on badly scaled ones:
  // it solves the same QP with W and zeta divided by their scale (the same minimiser), checked at 1e-6.
  QpProblem normalised = rq.qp;
  normalised.W /= std::max(w_scale, zeta_scale);
  normalised.zeta /= std::max(w_scale, zeta_scale);
  const Solved nlopt = solve_with("nlopt", normalised, SolverSettings{.tolerance = 1e-6});
  for (const Solved* s : {&newton, &nlopt}) {
    RC_LOG() << s->result.info.engine << ": " << to_string(s->result.info.status) << ", " << s->result.info.iterations
             << " iterations, residual " << s->result.info.residual << " " << s->result.info.diagnosis << "\n";
  }
  RC_ASSERT(newton.result.info.status == SolverStatus::kSolved);
  RC_ASSERT(newton.result.info.engine == "newton");
  RC_ASSERT(kkt_residual(rq.qp, newton.result) <= 1e-10 * size);
  int active_rows = 0;
  for (int r = 0; r < m_i; ++r) active_rows += newton.result.z(r) > 0.0 ? 1 : 0;
  RC_CLASSIFY(active_rows >= 2, "two or more inequality rows active");
  RC_CLASSIFY(w_scale > 1.0 || zeta_scale > 1.0, "scaled W or zeta");
  // Where SLSQP itself stops short (about 1 problem in 10^4 here, all with zeta >> W), newton's KKT residual above
  // and the random feasible points below still check it.
  const bool cross_check = nlopt.result.info.status == SolverStatus::kSolved;
  RC_CLASSIFY(!cross_check, "SLSQP stopped short (no cross-check)");
  if (cross_check) {
    const double x_size = 1.0 + newton.result.x.lpNorm<Eigen::Infinity>();
    RC_ASSERT((nlopt.result.x - newton.result.x).cwiseAbs().maxCoeff() <= 1e-5 * x_size);
  }
  const double best = qp_objective(rq.qp, newton.result.x);
  for (int k = 0; k < 20; ++k) {
    Eigen::VectorXd x;
    if (random_feasible_point(rng, rq, x)) RC_ASSERT(best <= qp_objective(rq.qp, x) + 1e-9 * size);
  }
}

// Long chains (96 and 192 joints, 2 or 6 rows, diagonal W) with zeta large enough that a third to two thirds of the
// joints end on a bound: newton's reduced path walks many breakpoints in its line search, cold and warm (the next
// problem's zeta moved, so that tens of joints change side between solves). newton itself meets the KKT conditions
// to 1e-10 and agrees with projection (eq. 15, an independent iteration; SLSQP stops round-off limited at this size)
// at every solve.
TEST(Lvi, NewtonSolvesLongChainsWithManyBoundsActive) {
  for (const int n : {96, 192}) {
    for (const int m_e : {2, 6}) {
      SCOPED_TRACE("n = " + std::to_string(n) + ", m_e = " + std::to_string(m_e));
      std::mt19937 rng(static_cast<unsigned>(n + m_e));
      testing::RandomQp rq = random_qp(rng, n, m_e, 0, false);
      SolverSettings settings;
      settings.tolerance = 1e-8;
      const std::unique_ptr<LviEngine> engine = make_engine("newton", settings);
      SolverResult result;
      engine->setup(n, m_e, 0, result);
      std::normal_distribution<double> kick(0.0, 1.0);
      for (int solve = 0; solve < 6; ++solve) {
        for (int i = 0; i < n; ++i) rq.qp.zeta(i) = 3.0 * kick(rng);
        engine->solve(rq.qp, result);
        ASSERT_EQ(result.info.status, SolverStatus::kSolved) << result.info.diagnosis;
        EXPECT_EQ(result.info.engine, "newton");
        EXPECT_LE(kkt_residual(rq.qp, result), 1e-10);
        int on_bound = 0;
        for (int i = 0; i < n; ++i) on_bound += result.x(i) <= rq.qp.lo(i) || result.x(i) >= rq.qp.hi(i) ? 1 : 0;
        EXPECT_GE(on_bound, n / 3) << "the family is meant to have many bounds active";
        const Solved other =
            solve_with("projection", rq.qp, SolverSettings{.tolerance = 1e-10, .max_iterations = 1000000});
        ASSERT_EQ(other.result.info.status, SolverStatus::kSolved) << other.result.info.diagnosis;
        EXPECT_LE((other.result.x - result.x).cwiseAbs().maxCoeff(), 1e-7);
      }
    }
  }
}

// A bound's multiplier is not a dual of the LVI (Omega clips x, the multiplier is eliminated), so it may exceed varpi:
// a joint that no row involves, pushed against its bound by zeta = -3e6 while the rows' duals stay small, is solved
// by newton itself (a bound multiplier of 3e6 > varpi = 1e6).
TEST(Lvi, NewtonGeneralPathAllowsBoundMultipliersPastVarpi) {
  std::mt19937 rng(3);
  testing::RandomQp rq = random_qp(rng, 5, 2, 4, true);
  rq.qp.J.col(4).setZero();
  rq.qp.A.col(4).setZero();
  rq.qp.W.row(4).setZero();
  rq.qp.W.col(4).setZero();
  rq.qp.W(4, 4) = 1.0;
  rq.qp.zeta(4) = -3e6;
  rq.qp.d = rq.qp.J * rq.feasible;
  const Solved newton = solve_with("newton", rq.qp, SolverSettings{.tolerance = 1e-8});
  ASSERT_EQ(newton.result.info.status, SolverStatus::kSolved) << newton.result.info.diagnosis;
  EXPECT_EQ(newton.result.info.engine, "newton");
  EXPECT_EQ(newton.result.x(4), rq.qp.hi(4));
  EXPECT_LE(kkt_residual(rq.qp, newton.result), 1e-10 * 3e6);
  EXPECT_LT(newton.result.z.lpNorm<Eigen::Infinity>(), 1e3);
}

// The paper-like family (the paper's arm and scheme, 6 joints, 2 rows, random states and desired velocities), each
// problem solved cold: both engines agree on feasibility, newton meets the KKT conditions to 1e-10, and projection,
// run to a tight tolerance, converges to the same (unique: W > 0) solution. Properties of every problem, not bands
// tuned to the generator: the only counts checked are that the family exercised both active and inactive bounds.
TEST(Lvi, PaperFamilyEnginesConvergeToTheSameSolution) {
  std::mt19937 rng(2026);
  auto step = testing::make_paper_step();
  SolverSettings tight;
  tight.tolerance = 1e-11;
  tight.max_iterations = 200000;
  int active = 0, inactive = 0;
  for (int rep = 0; rep < 120; ++rep) {
    testing::paper_family_qp(rng, *step);
    const Solved proj = solve_with("projection", step->qp, tight);
    const Solved newton = solve_with("newton", step->qp);
    ASSERT_EQ(proj.result.info.status, newton.result.info.status) << rep << ": " << newton.result.info.diagnosis;
    if (newton.result.info.status != SolverStatus::kSolved) continue;
    ASSERT_EQ(newton.result.info.engine, "newton");
    EXPECT_LE(kkt_residual(step->qp, newton.result), 1e-10) << rep;
    EXPECT_LE((proj.result.x - newton.result.x).cwiseAbs().maxCoeff(), 1e-7) << rep;
    const Eigen::VectorXd& x = newton.result.x;
    const bool on_bound =
        ((x - step->qp.lo).array().abs() < 1e-12).any() || ((step->qp.hi - x).array().abs() < 1e-12).any();
    (on_bound ? active : inactive) += 1;
  }
  EXPECT_GT(active, 0) << "no problem had an active bound";
  EXPECT_GT(inactive, 0) << "every problem had an active bound";
}

TEST(Lvi, ProjectionDiagonalShortcutKeepsTheIterates) {
  std::mt19937 rng(7);
  testing::RandomQp rq = random_qp(rng, 6, 2, 0);
  const Solved fast = solve_with("projection", rq.qp);
  rq.qp.w_diagonal = false;  // forces the dense products
  const Solved dense = solve_with("projection", rq.qp);
  EXPECT_EQ(fast.result.info.iterations, dense.result.info.iterations);
  EXPECT_EQ(fast.result.x, dense.result.x);  // bitwise
  EXPECT_EQ(fast.result.y, dense.result.y);
}

TEST(Lvi, ProjectionReturnsTheBoxProjectionOfItsIterate) {
  std::mt19937 rng(11);
  for (int rep = 0; rep < 20; ++rep) {
    const testing::RandomQp rq = random_qp(rng, 6, 2, 0);
    const Solved s = solve_with("projection", rq.qp);
    ASSERT_EQ(s.result.info.status, SolverStatus::kSolved);
    EXPECT_TRUE(((s.result.x - rq.qp.lo).array() >= 0).all() && ((rq.qp.hi - s.result.x).array() >= 0).all());
  }
}

TEST(Lvi, PaperStepAllEnginesAgree) {
  auto step = testing::make_paper_step();
  step->build(paper_theta0(), 10.0, Eigen::Vector2d(0.004, -0.003), Eigen::Vector2d(1e-5, -2e-5));
  const Solved proj = solve_with("projection", step->qp);
  const Solved newton = solve_with("newton", step->qp);
  const Solved nlopt = solve_with("nlopt", step->qp);
  ASSERT_EQ(proj.result.info.status, SolverStatus::kSolved) << proj.result.info.diagnosis;
  ASSERT_EQ(newton.result.info.status, SolverStatus::kSolved) << newton.result.info.diagnosis;
  EXPECT_EQ(newton.result.info.engine, "newton");
  EXPECT_LE(kkt_residual(step->qp, newton.result), 1e-10);
  EXPECT_LE((proj.result.x - newton.result.x).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_LE((nlopt.result.x - newton.result.x).cwiseAbs().maxCoeff(), 1e-5);
  // The task rows hold: J x = r_d_dot + K (r_d - f).
  const Eigen::Vector2d d = Eigen::Vector2d(0.004, -0.003) + 8.0 * Eigen::Vector2d(1e-5, -2e-5);
  EXPECT_LE((step->kin->J * newton.result.x - d).norm(), 1e-12);
}

Eigen::VectorXd exact_x(const QpProblem& qp) { return solve_with("newton", qp).result.x; }

// A slowly varying family (the same arm moving along a smooth path) is solved faster warm than cold.
TEST(Lvi, WarmStartTakesFewerIterations) {
  for (const char* engine : {"projection", "newton"}) {
    auto step = testing::make_paper_step();
    auto warm = make_engine(engine, SolverSettings{});
    SolverSettings cold_settings;
    cold_settings.warm_start = false;
    auto cold = make_engine(engine, cold_settings);
    SolverResult rw, rc;
    warm->setup(6, 2, 0, rw);
    cold->setup(6, 2, 0, rc);
    long it_warm = 0, it_cold = 0;
    Eigen::VectorXd theta = paper_theta0();
    for (int k = 0; k < 200; ++k) {
      const double t = 0.01 * k;
      step->build(theta, 10.0 + t, Eigen::Vector2d(0.005 * std::cos(t), 0.005 * std::sin(t)), Eigen::Vector2d::Zero());
      warm->solve(step->qp, rw);
      cold->solve(step->qp, rc);
      ASSERT_EQ(rw.info.status, SolverStatus::kSolved) << engine << " step " << k;
      ASSERT_EQ(rc.info.status, SolverStatus::kSolved) << engine << " step " << k;
      EXPECT_LE((rw.x - exact_x(step->qp)).cwiseAbs().maxCoeff(), 1e-5) << engine << " step " << k;
      it_warm += rw.info.iterations;
      it_cold += rc.info.iterations;
      theta += 0.01 * rw.x;
    }
    EXPECT_LT(it_warm, it_cold) << engine;
    RecordProperty(std::string(engine) + "_warm_iterations", std::to_string(it_warm));
    RecordProperty(std::string(engine) + "_cold_iterations", std::to_string(it_cold));
  }
}

// lo_i > hi_i from two plugins: joint 3 pushed above its position limit makes joint_angle_margin's upper bound
// fall below joint_velocity_limits' lower bound.
TEST(LviInfeasible, BoundConflictNamesTheJointAndThePlugins) {
  auto step = testing::make_paper_step();
  Eigen::VectorXd theta = paper_theta0();
  theta(2) = 0.611 + 0.2;  // theta_3^+ = 0.611: kappa ((0.611 - 0.0349) - 0.811) = -0.94 < -0.36
  step->build(theta, 10.0, Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero());
  for (const char* engine : {"projection", "newton", "nlopt"}) {
    const Solved s = solve_with(engine, step->qp);
    EXPECT_EQ(s.result.info.status, SolverStatus::kInfeasible) << engine;
    const std::string& why = s.result.info.diagnosis;
    EXPECT_NE(why.find("joint 3 ('joint3')"), std::string::npos) << engine << ": " << why;
    EXPECT_NE(why.find("'joint_velocity_limits'"), std::string::npos) << engine << ": " << why;
    EXPECT_NE(why.find("'joint_angle_margin'"), std::string::npos) << engine << ": " << why;
    EXPECT_TRUE(s.result.x.allFinite()) << engine;
    // The residual of a conflict is how far apart the bounds are: a number, so that summaries stay numbers.
    EXPECT_EQ(s.result.info.residual, (step->qp.lo - step->qp.hi).maxCoeff()) << engine;
    EXPECT_GT(s.result.info.residual, 0.0) << engine;
  }
}

// The task asks for more end-effector speed than the push-rod limits allow.
TEST(LviInfeasible, UnmeetableEqualityRowsAreReportedWithTheBoundJoints) {
  auto step = testing::make_paper_step();
  step->build(paper_theta0(), 10.0, Eigen::Vector2d(3.0, -3.0), Eigen::Vector2d::Zero());
  for (const char* engine : {"projection", "newton", "nlopt"}) {
    SolverSettings settings;
    settings.max_iterations = 5000;
    const Solved s = solve_with(engine, step->qp, settings);
    EXPECT_EQ(s.result.info.status, SolverStatus::kInfeasible) << engine << ": " << s.result.info.diagnosis;
    const std::string& why = s.result.info.diagnosis;
    EXPECT_NE(why.find("cannot be met inside the bounds"), std::string::npos) << engine << ": " << why;
    EXPECT_NE(why.find("'task_tracking'"), std::string::npos) << engine << ": " << why;
    EXPECT_NE(why.find("at its"), std::string::npos) << engine << ": " << why;
    EXPECT_TRUE(s.result.x.allFinite()) << engine;
  }
}

TEST(LviInfeasible, WarmStartIsResetAfterAnInfeasibleStep) {
  auto step = testing::make_paper_step();
  auto engine = make_engine("projection");
  SolverResult r;
  engine->setup(6, 2, 0, r);
  step->build(paper_theta0(), 10.0, Eigen::Vector2d(3.0, -3.0), Eigen::Vector2d::Zero());
  engine->solve(step->qp, r);
  ASSERT_EQ(r.info.status, SolverStatus::kInfeasible);
  EXPECT_EQ(r.y.cwiseAbs().maxCoeff(), 0.0);  // duals were reset, not left near varpi
  step->build(paper_theta0(), 10.0, Eigen::Vector2d(0.004, 0.0), Eigen::Vector2d::Zero());
  engine->solve(step->qp, r);
  EXPECT_EQ(r.info.status, SolverStatus::kSolved);
  EXPECT_LT(r.info.iterations, 5000);
}

TEST(LviInput, WrongSizesAndNanThrow) {
  auto engine = make_engine("newton");
  SolverResult r;
  engine->setup(6, 2, 0, r);
  std::mt19937 rng(3);
  testing::RandomQp rq = random_qp(rng, 5, 2, 0);
  EXPECT_THROW(engine->solve(rq.qp, r), std::invalid_argument);
  rq = random_qp(rng, 6, 2, 0);
  rq.qp.zeta(4) = std::nan("");
  try {
    engine->solve(rq.qp, r);
    FAIL() << "NaN accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("zeta(4"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)make_engine("simplex"), std::invalid_argument);
}

TEST(LviRealTime, ProjectionAndNewtonSolvesAllocateNothing) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  auto step = testing::make_paper_step();
  for (const char* name : {"projection", "newton"}) {
    auto engine = make_engine(name);
    SolverResult r;
    engine->setup(6, 2, 0, r);
    Eigen::VectorXd theta = paper_theta0();
    step->build(theta, 10.0, Eigen::Vector2d(0.004, -0.002), Eigen::Vector2d::Zero());
    engine->solve(step->qp, r);  // warm-up
    long count = 0;
    {
      const testing::AllocationCounter counter;
      for (int k = 0; k < 20; ++k) {
        step->build(theta, 10.0 + 0.01 * k, Eigen::Vector2d(0.004, -0.002), Eigen::Vector2d::Zero());
        engine->solve(step->qp, r);
        theta += 0.01 * r.x;
      }
      count = counter.count();
    }
    EXPECT_EQ(r.info.status, SolverStatus::kSolved);
    EXPECT_EQ(count, 0) << name << " (scheme build + solve)";
  }
}

// The fit behind every `infeasible` and every failure's diagnosis (RowFitter) allocates nothing after setup, on QPs
// whose rows cannot be met (the rows pulled far outside the bounds) and on QPs whose can, with and without
// inequality rows; and it fits as best_row_fit does.
TEST(LviRealTime, TheRowFitAllocatesNothing) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  std::mt19937 rng(17);
  for (const int m_i : {0, 6}) {
    std::vector<testing::RandomQp> family;
    for (int k = 0; k < 8; ++k) {
      family.push_back(random_qp(rng, 7, 3, m_i, false));
      if (k % 2 == 0) family.back().qp.d *= 1e3;  // unmeetable inside the bounds
      if (m_i > 0 && k % 4 == 1) family.back().qp.b.array() -= 10.0;
    }
    RowFitter fitter;
    fitter.setup(7, 3, m_i);
    (void)fitter.fit(family.front().qp);  // warm-up
    long count = 0;
    double worst = 0.0;
    for (const auto& rq : family) {
      double miss = 0.0;
      {
        const testing::AllocationCounter counter;
        miss = fitter.fit(rq.qp).miss_norm();
        count += counter.count();
      }
      const RowFit reference = best_row_fit(rq.qp);
      worst = std::max(worst, std::abs(miss - reference.miss_norm()));
    }
    EXPECT_EQ(count, 0) << "m_i = " << m_i;
    EXPECT_EQ(worst, 0.0) << "the fitter and best_row_fit are one computation";
  }
}

// newton's general path, cold (so the method of multipliers runs, not only the exact step): 16 inequality rows and
// a dense W, solved by newton itself without allocating.
TEST(LviRealTime, NewtonGeneralPathAllocatesNothing) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  std::mt19937 rng(99);
  std::vector<testing::RandomQp> family;
  for (int k = 0; k < 20; ++k) family.push_back(random_qp(rng, 7, 3, 16, k % 2 == 0));
  auto engine = make_engine("newton", SolverSettings{.warm_start = false});
  SolverResult r;
  engine->setup(7, 3, 16, r);
  engine->solve(family[0].qp, r);  // warm-up
  long count = 0;
  int general_iterations = 0;
  {
    const testing::AllocationCounter counter;
    for (const testing::RandomQp& rq : family) {
      engine->solve(rq.qp, r);
      if (r.info.status != SolverStatus::kSolved || r.info.engine != "newton") break;
      general_iterations += r.info.iterations;
    }
    count = counter.count();
  }
  ASSERT_EQ(r.info.status, SolverStatus::kSolved) << r.info.diagnosis;
  ASSERT_EQ(r.info.engine, "newton");
  EXPECT_GT(general_iterations, 2 * static_cast<int>(family.size()));  // more than the exact step alone
  EXPECT_EQ(count, 0);
}

// NLopt's SLSQP mallocs its work array inside every nlopt_optimize() (it has no caller-provided workspace), so the
// `nlopt` engine cannot be allocation-free; everything redres adds around it must be. The count per solve is
// pinned to what a bare nlopt_optimize() of the same size allocates, measured here.
double bare_objective(unsigned n, const double* x, double* grad, void* /*data*/) {
  double f = 0.0;
  for (unsigned i = 0; i < n; ++i) {
    f += 0.5 * x[i] * x[i] + 0.1 * x[i];
    if (grad != nullptr) grad[i] = x[i] + 0.1;
  }
  return f;
}

void bare_rows(unsigned m, double* result, unsigned n, const double* x, double* grad, void* /*data*/) {
  for (unsigned r = 0; r < m; ++r) {
    result[r] = x[r] + x[r + 1] - 0.1;
    for (unsigned i = 0; grad != nullptr && i < n; ++i) grad[r * n + i] = (i == r || i == r + 1) ? 1.0 : 0.0;
  }
}

TEST(LviRealTime, NloptEngineAllocatesOnlyWhatNloptDoes) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  long per_optimize = 0;
  {
    nlopt_opt opt = nlopt_create(NLOPT_LD_SLSQP, 6);
    ASSERT_NE(opt, nullptr);
    const double tol[2] = {1e-13, 1e-13};
    const double lo[6] = {-1, -1, -1, -1, -1, -1}, hi[6] = {1, 1, 1, 1, 1, 1};
    nlopt_set_min_objective(opt, &bare_objective, nullptr);
    nlopt_add_equality_mconstraint(opt, 2, &bare_rows, nullptr, tol);
    nlopt_set_lower_bounds(opt, lo);
    nlopt_set_upper_bounds(opt, hi);
    nlopt_set_xtol_abs1(opt, 1e-14);
    double x[6] = {0, 0, 0, 0, 0, 0};
    double f = 0.0;
    {
      const testing::AllocationCounter counter;
      ASSERT_GT(nlopt_optimize(opt, x, &f), 0);
      per_optimize = counter.count();
    }
    nlopt_destroy(opt);
  }
  RecordProperty("nlopt_optimize_allocations", std::to_string(per_optimize));

  auto step = testing::make_paper_step();
  auto engine = make_engine("nlopt");
  SolverResult r;
  engine->setup(6, 2, 0, r);
  Eigen::VectorXd theta = paper_theta0();
  step->build(theta, 10.0, Eigen::Vector2d(0.004, -0.002), Eigen::Vector2d::Zero());
  engine->solve(step->qp, r);  // warm-up
  constexpr int kSolves = 20;
  long count = 0;
  {
    const testing::AllocationCounter counter;
    for (int k = 0; k < kSolves; ++k) {
      step->build(theta, 10.0 + 0.01 * k, Eigen::Vector2d(0.004, -0.002), Eigen::Vector2d::Zero());
      engine->solve(step->qp, r);
      theta += 0.01 * r.x;
    }
    count = counter.count();
  }
  EXPECT_EQ(r.info.status, SolverStatus::kSolved) << r.info.diagnosis;
  EXPECT_EQ(count, kSolves * per_optimize) << "allocations beyond NLopt's own " << per_optimize << " per solve";
}

}  // namespace
}  // namespace redres

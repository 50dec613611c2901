// The certificate behind `solved` (redres/qp/certificate.hpp): each of its three checks fails on an answer that
// breaks it, and names where; its limits scale with the data; every engine's `solved` answer passes it; and a QP
// whose W is dense but whose w_diagonal flag was left at its default is solved as the dense QP it is.

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include "qp_util.hpp"
#include "redres/control/engine_registry.hpp"

namespace redres {
namespace {

// min |x|^2 / 2 - x1  s.t.  x1 + x2 = 1 (row from 'task'),  x3 <= -0.5 (row from 'wall'),  0.25 <= x2,
// -2 <= x <= 2 (bounds from 'limits'). By hand: x3 = -0.5 on its row with z = 0.5 (x3 + z = 0); x1 + x2 = 1 with
// x2 >= 0.25 gives x2 = 0.25 at its bound, x1 = 0.75, y = x1 - 1 = -0.25, and x2's gradient g_2 = x2 - y = 0.5 >= 0
// pushes it onto its lower bound, which holds it.
QpProblem small_qp() {
  QpProblem qp;
  qp.resize(3, 1, 1);
  qp.W.setIdentity();
  qp.zeta << -1.0, 0.0, 0.0;
  qp.J << 1.0, 1.0, 0.0;
  qp.d << 1.0;
  qp.A << 0.0, 0.0, 1.0;
  qp.b << -0.5;
  qp.lo << -2.0, 0.25, -2.0;
  qp.hi.setConstant(2.0);
  qp.source_names = {"posture", "task", "wall", "limits"};
  qp.eq_source = {1};
  qp.in_source = {2};
  qp.lo_source = {3, 3, 3};
  qp.hi_source = {3, 3, 3};
  qp.variable_names = {"a", "b", "c"};
  return qp;
}

SolverResult exact_answer() {
  SolverResult r;
  r.x = Eigen::Vector3d(0.75, 0.25, -0.5);
  r.y = Eigen::VectorXd::Constant(1, -0.25);
  r.z = Eigen::VectorXd::Constant(1, 0.5);
  return r;
}

std::string text_of(const Certificate& c, const QpProblem& qp) {
  std::string s;
  s.reserve(kDiagnosisCapacity);
  TextSink t(s);
  describe(c, qp, t);
  return s;
}

TEST(Certificate, TheExactAnswerPassesAndEachBrokenConditionIsNamed) {
  const QpProblem qp = small_qp();
  const SolverResult exact = exact_answer();
  ASSERT_LE(testing::kkt_residual(qp, exact), 1e-15);  // the hand solution, checked independently
  const Certificate ok = certify(qp, exact, true, 1e-9, 0.0);
  EXPECT_EQ(ok.verdict(), SolverStatus::kSolved) << text_of(ok, qp);
  EXPECT_LE(std::max({ok.primal, ok.dual, ok.complementarity}), 1e-15);

  SolverResult r = exact;  // a row missed
  r.x(0) += 1e-4;
  Certificate c = certify(qp, r, true, 1e-9, 0.0);
  EXPECT_EQ(c.verdict(), SolverStatus::kInaccuratePrimal);
  EXPECT_NEAR(c.primal, 1e-4, 1e-12);
  EXPECT_NE(text_of(c, qp).find("equality row 0 (from 'task')"), std::string::npos) << text_of(c, qp);

  r = exact;  // a bound missed (the row still met)
  r.x(0) += 1e-4;
  r.x(1) -= 1e-4;
  c = certify(qp, r, true, 1e-9, 0.0);
  EXPECT_EQ(c.verdict(), SolverStatus::kInaccuratePrimal);
  EXPECT_NE(text_of(c, qp).find("joint 2 ('b')'s lower bound (from 'limits')"), std::string::npos) << text_of(c, qp);

  r = exact;  // not stationary: the equality row's multiplier off
  r.y(0) += 1e-3;
  c = certify(qp, r, true, 1e-9, 0.0);
  EXPECT_EQ(c.verdict(), SolverStatus::kInaccurateDual);
  EXPECT_NEAR(c.dual, 1e-3, 1e-12);
  EXPECT_NE(text_of(c, qp).find("at joint 1 ('a')"), std::string::npos) << text_of(c, qp);

  r = exact;  // stationary, but through a row that is not active: x3 = -0.6 held by z = 0.6 on x3 <= -0.5
  r.x(2) = -0.6;
  r.z(0) = 0.6;
  c = certify(qp, r, true, 1e-9, 0.0);
  EXPECT_EQ(c.verdict(), SolverStatus::kInaccurateComplementarity) << text_of(c, qp);
  EXPECT_NEAR(c.complementarity, 0.6, 1e-12);
  EXPECT_NE(text_of(c, qp).find("inequality row 0 (from 'wall') is not active"), std::string::npos);

  r = exact;
  r.x(1) = std::numeric_limits<double>::quiet_NaN();
  c = certify(qp, r, true, 1e-9, 0.0);
  EXPECT_EQ(c.verdict(), SolverStatus::kInaccuratePrimal);
  EXPECT_NE(text_of(c, qp).find("not finite"), std::string::npos);
}

TEST(Certificate, ABoundHoldsOnlyInItsOwnDirection) {
  // min x^2 / 2 - x on [-1, 0.5]: x* = 0.5 at the upper bound (g = x - 1 = -0.5 pushes up, the bound holds it).
  QpProblem qp;
  qp.resize(1, 0, 0);
  qp.W.setIdentity();
  qp.zeta << -1.0;
  qp.lo << -1.0;
  qp.hi << 0.5;
  SolverResult r;
  r.x = Eigen::VectorXd::Constant(1, 0.5);
  r.y.resize(0);
  r.z.resize(0);
  EXPECT_EQ(certify(qp, r, true, 1e-12, 0.0).verdict(), SolverStatus::kSolved);
  r.x(0) = -1.0;  // at the lower bound, but the gradient -2 pushes up: the lower bound cannot hold it there
  const Certificate c = certify(qp, r, true, 1e-12, 0.0);
  EXPECT_EQ(c.verdict(), SolverStatus::kInaccurateDual);
  EXPECT_NEAR(c.dual, 2.0, 1e-15);
}

TEST(Certificate, ItsLimitsScaleWithTheData) {
  QpProblem qp = small_qp();
  SolverResult r = exact_answer();
  // The objective 1e8 times larger: the same x, multipliers 1e8 times larger.
  qp.W *= 1e8;
  qp.zeta *= 1e8;
  r.y *= 1e8;
  r.z *= 1e8;
  r.y(0) += 0.05;  // a dual residual of 0.05 on gradients of size 1e8
  EXPECT_EQ(certify(qp, r, true, 1e-9, 0.0).verdict(), SolverStatus::kInaccurateDual);
  const Certificate c = certify(qp, r, true, 1e-9, 1e-9);
  EXPECT_EQ(c.verdict(), SolverStatus::kSolved) << text_of(c, qp);
  EXPECT_NEAR(c.dual_limit, 1e-9 + 1e-9 * 1e8, 1e-6);
}

// Every engine's `solved` is certified, and the figures in the step's info are the certificate's: on random QPs
// (diagonal and dense W, equality and inequality rows, bounds often active) at the default settings.
RC_GTEST_PROP(CertificateProperty, EverySolvedAnswerIsCertified, ()) {
  const int n = *rc::gen::inRange(2, 10);
  const int m_e = *rc::gen::inRange(0, std::min(4, n));
  const int m_i = *rc::gen::inRange(0, 3);
  const bool dense = *rc::gen::inRange(0, 2) == 0;
  std::mt19937 rng(*rc::gen::arbitrary<std::uint32_t>());
  const testing::RandomQp rq = testing::random_qp(rng, n, m_e, m_i, dense);
  for (const char* name : {"newton", "projection", "nlopt"}) {
    SolverSettings settings;
    settings.max_iterations = 200000;
    auto engine = make_engine(name, settings);
    SolverResult r;
    engine->setup(n, m_e, m_i, r);
    engine->solve(rq.qp, r);
    RC_LOG() << name << ": " << to_string(r.info.status) << " " << r.info.diagnosis << "\n";
    if (r.info.status == SolverStatus::kSolved) {
      // (A failed solve's duals are reset after its figures are taken.)
      const Certificate c = certify(rq.qp, r, !dense, settings.tolerance, settings.relative_tolerance);
      RC_ASSERT(c.verdict() == SolverStatus::kSolved);
      RC_ASSERT(r.info.primal_residual == c.primal);
      RC_ASSERT(r.info.dual_residual == c.dual);
      RC_ASSERT(r.info.complementarity == c.complementarity);
    }
    // newton is exact on this family: it is always solved (and so certified).
    if (std::string(name) == "newton") RC_ASSERT(r.info.status == SolverStatus::kSolved);
  }
}

// A C++ program that fills a dense W by hand and leaves w_diagonal at its default (true) gets the dense QP's
// answer from every engine, not the diagonal part's: the engines verify the flag against W.
TEST(Certificate, ADenseWWithTheFlagLeftAtItsDefaultIsSolvedAsTheDenseQp) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    testing::RandomQp rq = testing::random_qp(rng, 6, 2, 0, true);
    rq.qp.lo.setConstant(-1e3);  // bounds far away: the optimum is the KKT system's solution
    rq.qp.hi.setConstant(1e3);
    rq.qp.w_diagonal = true;  // QpProblem's default, which a program that fills W by hand leaves
    ASSERT_GT((rq.qp.W - Eigen::MatrixXd(rq.qp.W.diagonal().asDiagonal())).cwiseAbs().maxCoeff(), 1e-3);
    // [W -J'; J 0] [x; y] = [-zeta; d], solved by Eigen's LU: the independent answer.
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(8, 8);
    K.topLeftCorner(6, 6) = rq.qp.W;
    K.topRightCorner(6, 2) = -rq.qp.J.transpose();
    K.bottomLeftCorner(2, 6) = rq.qp.J;
    Eigen::VectorXd rhs(8);
    rhs << -rq.qp.zeta, rq.qp.d;
    const Eigen::VectorXd expected = K.fullPivLu().solve(rhs).head(6);
    for (const char* name : {"newton", "projection", "nlopt"}) {
      SolverSettings settings;
      const bool slsqp = std::string(name) == "nlopt";
      settings.tolerance = slsqp ? 1e-6 : 1e-9;  // SLSQP stops short of 1e-8 on some of these
      settings.max_iterations = 1000000;
      auto engine = make_engine(name, settings);
      SolverResult r;
      engine->setup(6, 2, 0, r);
      engine->solve(rq.qp, r);
      ASSERT_EQ(r.info.status, SolverStatus::kSolved) << name << ": " << r.info.diagnosis;
      EXPECT_LE((r.x - expected).cwiseAbs().maxCoeff(), slsqp ? 1e-5 : 1e-7) << name << ", trial " << trial;
    }
  }
}

}  // namespace
}  // namespace redres

namespace redres {
namespace {

// The paper's case (diagonal W, two rows, six joints) is measured by its own kernel; the dense path (W's zeros add
// nothing) is the general one. Both add the same terms in the same order, so their figures agree bit for bit, on
// answers inside, on and outside the bounds, and both refuse a non-finite answer.
RC_GTEST_PROP(CertificateProperty, ThePaperCaseKernelMeasuresAsTheGeneralPath, ()) {
  std::mt19937 rng(*rc::gen::arbitrary<unsigned>());
  testing::RandomQp rq = testing::random_qp(rng, 6, 2, 0, false);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SolverResult answer;
  answer.x.resize(6);
  answer.y.resize(2);
  answer.z.resize(0);
  for (int i = 0; i < 6; ++i) {
    const int where = *rc::gen::inRange(0, 4);  // strictly inside, at lo, at hi, outside
    const double lo = rq.qp.lo(i), hi = rq.qp.hi(i);
    answer.x(i) = where == 0 ? lo + (hi - lo) * (0.5 + 0.4 * u(rng)) : where == 1 ? lo : where == 2 ? hi : hi + 0.1;
  }
  answer.y << u(rng), u(rng);
  const double relative = *rc::gen::element(0.0, 1e-9, 1e-3);
  const Certificate fast = certify(rq.qp, answer, true, 1e-9, relative);
  const Certificate general = certify(rq.qp, answer, false, 1e-9, relative);
  RC_ASSERT(fast.primal == general.primal);
  RC_ASSERT(fast.dual == general.dual);
  RC_ASSERT(fast.primal_limit == general.primal_limit);
  RC_ASSERT(fast.dual_limit == general.dual_limit);
  RC_ASSERT(fast.verdict() == general.verdict());
  answer.y(*rc::gen::inRange(0, 2)) =
      *rc::gen::element(std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity());
  RC_ASSERT(certify(rq.qp, answer, true, 1e-9, relative).verdict() == SolverStatus::kInaccuratePrimal);
  RC_ASSERT(certify(rq.qp, answer, false, 1e-9, relative).verdict() == SolverStatus::kInaccuratePrimal);
}

}  // namespace
}  // namespace redres

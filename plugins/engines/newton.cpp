/// `newton`: an exact, fast engine for the same LVI (docs/lvi.md). For diagonal W > 0 with equality rows and
/// bounds, eq. 14 reduces to the m_e dual unknowns y:
///   x(y) = P_[lo,hi](W^-1 (J' y - zeta)),   F(y) = J x(y) - d = 0,
/// where F is minus the gradient of the concave dual function
///   phi(y) = min_{lo <= x <= hi} x'Wx/2 + zeta'x - y'(J x - d).
/// Semismooth Newton: G = J D W^-1 J' (D selects the joints strictly inside their bounds), G delta = -F, with an
/// exact line search on phi (phi is concave and piecewise quadratic along delta, so its maximiser is found by
/// walking the breakpoints where a joint reaches a bound). Where the free joints do not span the rows (a
/// degenerate solution), G is regularised by |F| I (Levenberg-Marquardt), which vanishes at the solution. Once
/// the free set is right the step is exact, so warm-started steps take one or two iterations. At x(y), e_x(u) = 0
/// by construction and e_y(u) = F(y) while |y| < varpi, so ||e(u)||_2 = ||F(y)||_2 is the paper's stopping test;
/// the engine reports `solved` only once ||F|| <= min(tolerance, 1e-12 (1 + |d|_inf)), i.e. after the exact step,
/// so its KKT residual is tiny.
///
/// Infeasible rows make phi unbounded: the line search then finds phi increasing linearly for ever (a proof of
/// infeasibility), or y leaves [-varpi, varpi]; either way the solve is reported `infeasible`.
///
/// General path: with live inequality rows or a non-diagonal W (still symmetric positive definite), semismooth
/// Newton on the natural map of the whole LVI, u = [x; y; z], exact once its active set is right (one step warm),
/// globalised by the method of multipliers with an exact semismooth Newton inner solve (see general_solve()).
///
/// Fallback: where neither path settles (on the reduced path a step without ascent or 100 iterations; on the
/// general one multipliers past varpi, i.e. an infeasible step, or 50 outer iterations), the step is solved by
/// `projection` (eq. 15) instead, and the info's `engine` says so.
/// No engine-specific TOML keys.
///
/// This file: setup, the choice of path, the reduced path's driver and the registration. newton_internal.hpp
/// declares the class and says which file holds each of its other parts.

#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <string>

#include "redres/control/engine_registry.hpp"
#include "redres/engines/newton.hpp"

#include "newton_internal.hpp"
#include "redres/common/hot.hpp"

namespace redres {
namespace newton_internal {

void Newton::do_setup(int n, int m_e, int m_i) {
  x_.setZero(n);
  box_x_.setZero(n);
  box_g_.setZero(n);
  box_at_.assign(static_cast<std::size_t>(n), 0);
  free_.assign(static_cast<std::size_t>(n), 0);
  v_.setZero(n);
  jtd_.setZero(n);
  x1_.setZero(n);
  v1_.setZero(n);
  F1_.setZero(m_e);
  inv_w_.setZero(n);
  w_diag_.setZero(n);
  dv_.setZero(n);
  events_.assign(2 * static_cast<std::size_t>(n), {0.0, 0.0});
  y_.setZero(m_e);
  F_.setZero(m_e);
  delta_.setZero(m_e);
  row_scale_.setZero(m_e);
  G_.setZero(m_e, m_e);
  L_.setZero(m_e, m_e);
  const int N = n + m_e + m_i;
  free_x_.assign(static_cast<std::size_t>(n), 0);
  free_w_.assign(static_cast<std::size_t>(m_e + m_i), 0);
  bt_.setZero(n, m_e + m_i);
  yt_.setZero(n, m_e + m_i);
  wff_.setZero(n, n);
  s_kkt_.setZero(m_e + m_i, m_e + m_i);
  w_.setZero(m_e + m_i);
  h_.setZero(n);
  u_.setZero(N);
  mu_.setZero(N);
  e_.setZero(N);
  rhs_.setZero(N);
  du_.setZero(N);
  lo_u_.setZero(N);
  hi_u_.setZero(N);
  trial_.setZero(N);
  const int R = m_e + m_i + n;
  Ct_.setZero(n, R);
  row_lo_.setZero(R);
  row_hi_.setZero(R);
  rho_.setZero(R);
  lambda_.setZero(R);
  s_.setZero(R);
  delta_r_.setZero(R);
  breaks_ab_.assign(2 * static_cast<std::size_t>(R), 0.0);
  xa_.setZero(n);
  ga_.setZero(n);
  dxa_.setZero(n);
  wx_.setZero(n);
  wdx_.setZero(n);
  // Sized by a factorisation (LLT(n) leaves its status uninitialised, and copying that is undefined).
  ha_.setIdentity(n, n);
  llt_.compute(ha_);
  setup_fallback(n, m_e, m_i);
}

bool Newton::slack_rows_only(const QpProblem& qp) {
  for (int r = 0; r < qp.m_in(); ++r) {
    if (!(qp.b(r) >= 0.0)) return false;
  }
  const double* a = qp.A.data();
  const Eigen::Index size = qp.A.size();
  for (Eigen::Index k = 0; k < size; ++k) {
    if (a[k] != 0.0) return false;
  }
  return true;
}

REDRES_HOT void Newton::do_solve(const QpProblem& qp, SolverResult& result) {
  // Inequality rows that are all zero with b >= 0 (the slack rows collision constraints leave for pairs out of
  // range) hold for every x with z = 0, so they do not stop the exact path.
  bool applicable = w_diagonal() && slack_rows_only(qp);
  if (applicable) {
    // W rarely changes between steps (W = I in the paper): reuse 1 / W_ii when it has not.
    const int n = qp.n();
    const double* __restrict W = qp.W.data();
    double* __restrict w_diag = w_diag_.data();
    double* __restrict inv_w = inv_w_.data();
    for (int i = 0; i < n; ++i) {
      const double w = W[static_cast<std::ptrdiff_t>(i) * (n + 1)];
      applicable &= w > 0.0;
      if (w != w_diag[i]) {
        w_diag[i] = w;
        inv_w[i] = 1.0 / w;
      }
    }
  }
  if (!applicable) {
    if (general_solve(qp, result)) return;
    // Bounds and equality rows (inequality rows slack or none), where the general path did not settle: the primal
    // active-set method.
    if (slack_rows_only(qp) && box_solve(qp, result)) return;
    result.info.diagnosis = "newton's general path did not settle";
    run_fallback(qp, result, 0, std::numeric_limits<double>::infinity(), u_.head(qp.n()));
    return;
  }
  // Planar position tasks (2 rows) get loops of fixed length; the arithmetic is the same.
  if (qp.m_eq() == 2) {
    run<2>(qp, result);
  } else {
    run<0>(qp, result);
  }
}

template <int kRows>
REDRES_HOT void Newton::run(const QpProblem& qp, SolverResult& result) {
  const bool warm_start = warm();
  if (!warm_start) y_.setZero();
  int k = 0;
  double f2 = 0.0;
  Reduced outcome = reduced_iterate<kRows>(qp, k, f2);
  if (outcome == Reduced::kStalled && warm_start) {
    // The last step's duals can leave the iteration where it stalls short of the target (seen on a cascade's level
    // below a relaxed one, at 7.6e-12 against 1e-14): once more from y = 0, as a cold start goes, before the fallback.
    const int warm_iterations = k;
    y_.setZero();
    outcome = reduced_iterate<kRows>(qp, k, f2);
    k += warm_iterations;
  }
  switch (outcome) {
    case Reduced::kConverged: finish(result, SolverStatus::kSolved, k, f2); return;
    case Reduced::kInfeasible: finish(result, SolverStatus::kInfeasible, k, f2); return;
    case Reduced::kStalled:
      keep_diagnosis_capacity(result.info.diagnosis);
      result.info.diagnosis.clear();
      TextSink(result.info.diagnosis) << "newton did not converge in " << k << " iterations (residual " << std::sqrt(f2)
                                      << ")";
      run_fallback(qp, result, k, std::sqrt(f2), x_);
      return;
  }
}

REDRES_HOT void Newton::finish(SolverResult& result, SolverStatus status, int iterations, double f2) const {
  result.info.status = status;
  result.info.iterations = iterations;
  result.info.residual = std::sqrt(f2);
  result.x = x_;
  result.y = y_;
  result.z.setZero();
}

}  // namespace newton_internal

namespace {

const bool kNewtonRegistered = engine_registry().add<NewtonConfig>(
    "newton", "semismooth Newton on eq. 14 (exact; equality and inequality rows, bounds, any W > 0)",
    [](const NewtonConfig& /*config*/, const SolverSettings& s) -> std::unique_ptr<LviEngine> {
      return std::make_unique<newton_internal::Newton>(s);
    });

}  // namespace
}  // namespace redres

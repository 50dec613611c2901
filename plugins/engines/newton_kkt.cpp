/// `newton`'s general path (newton.cpp) on the whole LVI u = [x; y; z]: M and Omega, the natural map's residual,
/// the exact step through the dense KKT-like system (I - D + D M) du = -e, and the accuracy it is held to.

#include <algorithm>
#include <cmath>

#include "newton_internal.hpp"

namespace redres::newton_internal {

// The general path, for inequality rows and any symmetric positive definite W, on the whole LVI u = [x; y; z].
//  1. The exact step, on the natural map e(u) = u - P_Omega(u - (M u + g)): with D the components where
//     u - (M u + g) lies strictly inside Omega, (I - D + D M) du = -e moves a component on a bound to it and makes
//     a free one's row of M u + g vanish. e is piecewise linear, so once the active set is right this step lands
//     on the solution (exact_step_lands()). Warm starts usually land at once.
//  2. Where it does not land, the active set is found by the method of multipliers (augmented_lagrangian()):
//     every constraint, the bounds included, becomes a row c_r x in [l_r, h_r] with a multiplier lambda_r, and
//     each outer iteration minimises the augmented Lagrangian
//       L(x) = x'Wx/2 + zeta'x + sum_r rho_r/2 dist(c_r x + lambda_r / rho_r, [l_r, h_r])^2,
//     a strictly convex, continuously differentiable, piecewise quadratic function, by semismooth Newton with an
//     exact line search (its Hessian W + sum over rows outside their interval of rho_r c_r c_r' is positive
//     definite, and the minimiser along a direction is found by walking the breakpoints). That inner iteration
//     ends exactly, when a full Newton step keeps every row's side; then lambda_r <- rho_r (s_r - P(s_r)). The
//     method converges for every convex QP with a solution (no constraint qualification needed), and after each
//     outer iteration step 1 is tried from u = [x; -lambda_J; lambda_A], so the answer is exact.
// Returns false (and the caller falls back to projection) when the multipliers grow past varpi (no solution:
// the rows cannot be met inside the bounds) or the iteration caps are reached.
bool Newton::general_solve(const QpProblem& qp, SolverResult& result) {
  const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
  const double varpi = settings().varpi;
  // M's blocks that hold data are written here; the zero block [y; z] x [y; z] stays as setup left it.
  M_.topLeftCorner(n, n) = qp.W;
  M_.block(0, n, n, me) = -qp.J.transpose();
  M_.block(0, n + me, n, mi) = qp.A.transpose();
  M_.block(n, 0, me, n) = qp.J;
  M_.block(n + me, 0, mi, n) = -qp.A;
  lo_u_.head(n) = qp.lo;
  hi_u_.head(n) = qp.hi;
  lo_u_.segment(n, me).setConstant(-varpi);
  hi_u_.segment(n, me).setConstant(varpi);
  lo_u_.tail(mi).setZero();
  hi_u_.tail(mi).setConstant(varpi);
  int iterations = 0;
  if (warm()) {
    u_.head(n) = result.x;
    u_.segment(n, me) = result.y;
    u_.tail(mi) = result.z;
  } else {
    // Cold: the reduced path's solution for W's diagonal, without the inequality rows (exact when W is
    // diagonal and the rows are slack), as the start: it puts the duals of J x = d near their values.
    for (int i = 0; i < n; ++i) {
      w_diag_(i) = qp.W(i, i);
      inv_w_(i) = 1.0 / w_diag_(i);
    }
    y_.setZero();
    double f2 = 0.0;
    (void)reduced_iterate<0>(qp, iterations, f2);
    u_.setZero();
    u_.head(n) = x_;
    u_.segment(n, me) = y_;
  }
  set_norms(qp);
  const auto solved = [&](double e2) {
    result.x = u_.head(n).cwiseMax(qp.lo).cwiseMin(qp.hi);
    result.y = u_.segment(n, me);
    result.z = u_.tail(mi);
    result.info.status = SolverStatus::kSolved;
    result.info.iterations = iterations;
    result.info.residual = std::sqrt(e2);
    return true;
  };
  double e2 = natural_residual2(qp, u_);
  if (std::sqrt(e2) <= target_at(u_)) return solved(e2);
  ++iterations;
  if (exact_step_lands(qp, e2)) return solved(e2);
  return augmented_lagrangian(qp, iterations) && (e2 = natural_residual2(qp, u_), solved(e2));
}

// Infinity norms of W, J, J', A and A' for target_at(), once per solve (loops: no temporaries).
void Newton::set_norms(const QpProblem& qp) {
  const auto row_sums = [](const Eigen::MatrixXd& m, bool transposed) {
    double best = 0.0;
    const Eigen::Index outer = transposed ? m.cols() : m.rows(), inner = transposed ? m.rows() : m.cols();
    for (Eigen::Index i = 0; i < outer; ++i) {
      double sum = 0.0;
      for (Eigen::Index k = 0; k < inner; ++k) sum += std::abs(transposed ? m(k, i) : m(i, k));
      best = std::max(best, sum);
    }
    return best;
  };
  norm_w_ = row_sums(qp.W, false);
  norm_j_ = row_sums(qp.J, false);
  norm_jt_ = row_sums(qp.J, true);
  norm_a_ = row_sums(qp.A, false);
  norm_at_ = row_sums(qp.A, true);
  data_scale_ = std::max({qp.zeta.lpNorm<Eigen::Infinity>(), qp.m_eq() > 0 ? qp.d.lpNorm<Eigen::Infinity>() : 0.0,
                          qp.m_in() > 0 ? qp.b.lpNorm<Eigen::Infinity>() : 0.0});
}

// The general path's accuracy at w = [x; y; z]: min(tolerance, 1e-12 s) with s the size of the terms the
// residual adds up there, 1 + max(|zeta|, |d|, |b|, |W||x| + |J'||y| + |A'||z|, |J||x|, |A||x|) (infinity
// norms): rounding alone leaves about 1e-16 s, so a large W or large multipliers raise the bar accordingly.
double Newton::target_at(const Eigen::VectorXd& w) const {
  const Eigen::Index n = xa_.size(), me = y_.size();
  const Eigen::Index mi = w.size() - n - me;
  const double x = w.head(n).lpNorm<Eigen::Infinity>();
  const double y = me > 0 ? w.segment(n, me).lpNorm<Eigen::Infinity>() : 0.0;
  const double z = mi > 0 ? w.tail(mi).lpNorm<Eigen::Infinity>() : 0.0;
  const double terms = std::max({data_scale_, norm_w_ * x + norm_jt_ * y + norm_at_ * z, norm_j_ * x, norm_a_ * x});
  return std::min(settings().tolerance, 1e-12 * (1.0 + terms));
}

// Step 1 of general_solve() from u_ (natural_residual2(u_) just computed, so mu_ and e_ hold its values): on
// landing (||e|| <= target_at() there), moves u_ to u_ + du, leaves ||e||^2 in e2 and returns true.
bool Newton::exact_step_lands(const QpProblem& qp, double& e2) {
  const Eigen::Index N = u_.size();
  for (Eigen::Index i = 0; i < N; ++i) {
    const double v = u_(i) - mu_(i);
    if (v > lo_u_(i) && v < hi_u_(i)) {
      K_.row(i) = M_.row(i);
      rhs_(i) = -mu_(i);
    } else {
      K_.row(i).setZero();
      K_(i, i) = 1.0;
      rhs_(i) = -e_(i);
    }
  }
  lu_.compute(K_);
  if (!(std::abs(lu_.matrixLU().diagonal().prod()) > 0.0)) return false;  // singular: no step
  du_.noalias() = lu_.solve(rhs_);
  if (!du_.allFinite()) return false;
  trial_ = u_ + du_;
  const double landed = natural_residual2(qp, trial_);
  if (!(std::sqrt(landed) <= target_at(trial_))) return false;
  u_.swap(trial_);
  e2 = landed;
  return true;
}

// ||e(w)||^2 of the natural map at w; leaves M w + g in mu_ and e(w) in e_.
double Newton::natural_residual2(const QpProblem& qp, const Eigen::VectorXd& w) {
  const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
  mu_.noalias() = M_ * w;
  mu_.head(n) += qp.zeta;
  mu_.segment(n, me) -= qp.d;
  mu_.tail(mi) += qp.b;
  double e2 = 0.0;
  for (Eigen::Index i = 0; i < w.size(); ++i) {
    e_(i) = w(i) - box(w(i) - mu_(i), lo_u_(i), hi_u_(i));
    e2 += e_(i) * e_(i);
  }
  return e2;
}

}  // namespace redres::newton_internal

/// `newton`'s reduced path (newton.cpp): the semismooth Newton iteration on the m_e dual unknowns y, with x(y),
/// F(y) and G = J D W^-1 J' evaluated in one pass and the Newton system solved by a checked Cholesky.

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "newton_internal.hpp"
#include "redres/common/hot.hpp"

namespace redres::newton_internal {

// x(y), v(y), the free set, F(y) = J x(y) - d, G = J D W^-1 J' over the free joints (lower triangle, in G_) and
// full_scale_ = the largest diagonal entry of J W^-1 J' (all joints), in one pass over the joints; returns |F|^2.
template <int kRows>
REDRES_HOT double Newton::evaluate(const QpProblem& qp) {
  const int n = qp.n(), me = rows<kRows>(qp);
  const double* __restrict J = qp.J.data();
  const double* __restrict zeta = qp.zeta.data();
  const double* __restrict lo = qp.lo.data();
  const double* __restrict hi = qp.hi.data();
  const double* __restrict inv_w = inv_w_.data();
  const double* __restrict y = y_.data();
  double* __restrict v = v_.data();
  double* __restrict x = x_.data();
  char* __restrict free_mask = free_.data();
  double* __restrict F = F_.data();
  double* __restrict G = G_.data();
  if constexpr (kRows == 2) {
    // The same sums as the general loops below, kept in registers.
    const double y0 = y[0], y1 = y[1];
    double f0 = -qp.d(0), f1 = -qp.d(1), g00 = 0.0, g10 = 0.0, g11 = 0.0, s0 = 0.0, s1 = 0.0;
    for (int i = 0; i < n; ++i) {
      const double j0 = J[2 * i], j1 = J[2 * i + 1], iw = inv_w[i];
      const double vi = (j0 * y0 + j1 * y1 - zeta[i]) * iw;
      const double xi = box(vi, lo[i], hi[i]);
      const bool is_free = (vi > lo[i]) & (vi < hi[i]);
      v[i] = vi;
      x[i] = xi;
      free_mask[i] = static_cast<char>(is_free);
      f0 += j0 * xi;
      f1 += j1 * xi;
      // Clamped joints add zero; no branch on the free set.
      const double fw = is_free ? iw : 0.0;
      g00 += j0 * j0 * fw;
      g10 += j1 * j0 * fw;
      g11 += j1 * j1 * fw;
      s0 += j0 * j0 * iw;
      s1 += j1 * j1 * iw;
    }
    F[0] = f0;
    F[1] = f1;
    G[0] = g00;
    G[1] = g10;
    G[3] = g11;
    full_scale_ = std::max(s0, s1);
    return f0 * f0 + f1 * f1;
  }
  for (int r = 0; r < me; ++r) F[r] = -qp.d(r);
  G_.setZero();
  double* __restrict scale = row_scale_.data();
  for (int r = 0; r < me; ++r) scale[r] = 0.0;
  for (int i = 0; i < n; ++i) {
    const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
    const double iw = inv_w[i];
    double jty = 0.0;
    for (int r = 0; r < me; ++r) jty += Ji[r] * y[r];
    const double vi = (jty - zeta[i]) * iw;
    const double xi = box(vi, lo[i], hi[i]);
    const bool is_free = (vi > lo[i]) & (vi < hi[i]);
    v[i] = vi;
    x[i] = xi;
    free_mask[i] = static_cast<char>(is_free);
    const double fw = is_free ? iw : 0.0;
    for (int r = 0; r < me; ++r) {
      F[r] += Ji[r] * xi;
      scale[r] += Ji[r] * Ji[r] * iw;
    }
    for (int c = 0; c < me; ++c) {
      for (int r = c; r < me; ++r) G[r + c * me] += Ji[r] * Ji[c] * fw;
    }
  }
  full_scale_ = 0.0;
  double f2 = 0.0;
  for (int r = 0; r < me; ++r) {
    full_scale_ = std::max(full_scale_, scale[r]);
    f2 += F[r] * F[r];
  }
  return f2;
}

// Solves (G + (reg + prox) I) delta = -F, with G from evaluate(). Without `prox`, false if a pivot is not clearly
// positive (the free joints do not span the rows).
template <int kRows>
bool Newton::solve_newton_system(const QpProblem& qp, double prox) {
  const int me = rows<kRows>(qp);
  const double full_scale = full_scale_;
  const double reg = 1e-13 * (1.0 + full_scale) + prox * full_scale;
  const bool check = prox == 0.0;
  // A pivot lost to cancellation (below 1e-8 of its diagonal entry) means the free joints (nearly) do not span
  // the rows. The test is on pivot / scale, written without the division (scale > 0).
  const auto pivot_ok = [&](double pivot, double diag, double scale) {
    return (!check || pivot > (1e-8 * diag + 1e-10 * full_scale) * scale) && pivot > 0.0;
  };
  if constexpr (kRows == 2) {
    // Two rows: the same pivots as the Cholesky below (a, then the Schur complement det / a), solved in closed
    // form with one division instead of two square roots and four divisions.
    const double a = G_(0, 0) + reg, b = G_(1, 0), c = G_(1, 1) + reg;
    const double det = a * c - b * b;
    if (!pivot_ok(a, a, 1.0) || !pivot_ok(det, c, a)) return false;
    const double inv = 1.0 / det;
    delta_(0) = (-F_(0) * c + F_(1) * b) * inv;
    delta_(1) = (-F_(1) * a + F_(0) * b) * inv;
    return true;
  }
  // Cholesky L L' = G + reg I in L_ (lower triangle); G_ is kept for a regularised retry.
  for (int c = 0; c < me; ++c) {
    for (int r = c; r < me; ++r) L_(r, c) = G_(r, c) + (r == c ? reg : 0.0);
  }
  for (int c = 0; c < me; ++c) {
    const double diag_entry = L_(c, c);
    double diag = diag_entry;
    for (int k = 0; k < c; ++k) diag -= L_(c, k) * L_(c, k);
    if (!pivot_ok(diag, diag_entry, 1.0)) return false;
    const double l = std::sqrt(diag);
    L_(c, c) = l;
    for (int r = c + 1; r < me; ++r) {
      double t = L_(r, c);
      for (int k = 0; k < c; ++k) t -= L_(r, k) * L_(c, k);
      L_(r, c) = t / l;
    }
  }
  for (int r = 0; r < me; ++r) {  // L w = -F
    double t = -F_(r);
    for (int k = 0; k < r; ++k) t -= L_(r, k) * delta_(k);
    delta_(r) = t / L_(r, r);
  }
  for (int r = me - 1; r >= 0; --r) {  // L' delta = w
    double t = delta_(r);
    for (int k = r + 1; k < me; ++k) t -= L_(k, r) * delta_(k);
    delta_(r) = t / L_(r, r);
  }
  return true;
}

// The reduced path's iteration from y_ (inv_w_ holds 1 / W_ii): leaves x(y), y and |F|^2 in x_, y_ and f2, the
// iterations taken in k. kInfeasible: the dual is unbounded along a step, or y left [-varpi, varpi] (then
// clamped back); kStalled: no ascent, a Newton system that cannot be solved, or the iteration cap.
template <int kRows>
REDRES_HOT Newton::Reduced Newton::reduced_iterate(const QpProblem& qp, int& k, double& f2) {
  const int me = rows<kRows>(qp);
  double d_max = 0.0;
  for (int r = 0; r < me; ++r) d_max = std::max(d_max, std::abs(qp.d(r)));
  const double varpi = settings().varpi;
  const double target = std::min(settings().tolerance, 1e-12 * (1.0 + d_max));

  f2 = evaluate<kRows>(qp);
  for (k = 0;; ++k) {
    if (f2 <= target * target) return Reduced::kConverged;
    if (k >= kMaxNewtonIterations) return Reduced::kStalled;
    // Where the free joints do not span the rows (a degenerate solution, where some v_i sits on its bound),
    // G is singular: regularise it proximally with |F| (Levenberg-Marquardt), which vanishes at the solution.
    if (!solve_newton_system<kRows>(qp, 0.0) && !solve_newton_system<kRows>(qp, std::sqrt(f2))) {
      return Reduced::kStalled;
    }
    const double step = exact_step<kRows>(qp);
    if (std::isinf(step)) {
      // phi grows linearly for ever along delta: the dual is unbounded, so J x = d cannot be met.
      ++k;
      return Reduced::kInfeasible;
    }
    if (!(step > 0.0)) return Reduced::kStalled;  // no ascent: leave it to the fallback
    bool outside = false;
    for (int r = 0; r < me; ++r) {
      y_(r) += step * delta_(r);
      outside = outside || std::abs(y_(r)) > varpi;
    }
    if (full_step_ready_) {
      // Same free set as before the step: x, v and F at the new y were computed by exact_step.
      x_.swap(x1_);
      v_.swap(v1_);
      F_.swap(F1_);
      f2 = 0.0;
      for (int r = 0; r < me; ++r) f2 += F_(r) * F_(r);
    } else {
      f2 = evaluate<kRows>(qp);
    }
    if (outside) {
      // The duals left the LVI's box: J x = d cannot be met inside the bounds.
      y_ = y_.cwiseMax(-varpi).cwiseMin(varpi);
      ++k;
      return Reduced::kInfeasible;
    }
  }
}

template Newton::Reduced Newton::reduced_iterate<0>(const QpProblem& qp, int& k, double& f2);
template Newton::Reduced Newton::reduced_iterate<2>(const QpProblem& qp, int& k, double& f2);

}  // namespace redres::newton_internal

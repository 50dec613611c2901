/// `newton`'s general path (newton.cpp) on the whole LVI u = [x; y; z]: M and Omega, the natural map's residual,
/// the exact step (I - D + D M) du = -e through the Schur complement of its live rows, and the accuracy it is held
/// to.

#include <algorithm>
#include <cmath>
#include <limits>

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
  set_omega(qp);
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

// Omega of the LVI (eq. 14) into lo_u_, hi_u_: the bounds for x, +-varpi for y, [0, varpi] for z.
void Newton::set_omega(const QpProblem& qp) {
  const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
  const double varpi = settings().varpi;
  lo_u_.head(n) = qp.lo;
  hi_u_.head(n) = qp.hi;
  lo_u_.segment(n, me).setConstant(-varpi);
  hi_u_.segment(n, me).setConstant(varpi);
  lo_u_.tail(mi).setZero();
  hi_u_.tail(mi).setConstant(varpi);
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

namespace {

// The lower Cholesky factor of the m x m symmetric matrix at `a` (column-major, leading dimension lda; its lower
// triangle is read and overwritten) in place. False if a pivot is not clearly positive (below 1e-12 of its diagonal
// entry, or of `scale`): the matrix is singular to working accuracy.
bool cholesky_in_place(double* a, Eigen::Index lda, Eigen::Index m, double scale) {
  for (Eigen::Index c = 0; c < m; ++c) {
    double* col = a + c * lda;
    const double entry = col[c];
    double diag = entry;
    for (Eigen::Index k = 0; k < c; ++k) diag -= a[c + k * lda] * a[c + k * lda];
    if (!(diag > 1e-12 * std::max(std::abs(entry), scale))) return false;
    const double l = std::sqrt(diag);
    col[c] = l;
    for (Eigen::Index r = c + 1; r < m; ++r) {
      double t = col[r];
      for (Eigen::Index k = 0; k < c; ++k) t -= a[r + k * lda] * a[c + k * lda];
      col[r] = t / l;
    }
  }
  return true;
}

// Solves L L' v = v in place with the factor of cholesky_in_place().
void cholesky_solve(const double* a, Eigen::Index lda, Eigen::Index m, double* v) {
  for (Eigen::Index r = 0; r < m; ++r) {
    double t = v[r];
    for (Eigen::Index k = 0; k < r; ++k) t -= a[r + k * lda] * v[k];
    v[r] = t / a[r + r * lda];
  }
  for (Eigen::Index r = m - 1; r >= 0; --r) {
    double t = v[r];
    for (Eigen::Index k = r + 1; k < m; ++k) t -= a[k + r * lda] * v[k];
    v[r] = t / a[r + r * lda];
  }
}

}  // namespace

// Step 1 of general_solve() from u_ (natural_residual2(u_) just computed, so mu_ and e_ hold its values): on
// landing (||e|| <= target_at() there), moves u_ to u_ + du, leaves ||e||^2 in e2 and returns true.
//
// The step solves (I - D + D M) du = -e, where D selects the components of u - (M u + g) strictly inside Omega
// (free), without forming it: a clamped component moves to its bound (du_c = -e_c), and a free one's row of
// M du = -(M u + g) holds. With F the free joints and w the free duals (y, and z of the live inequality rows),
// that is the KKT system
//   W_FF dx_F - B' w = r_x,   B dx_F = r_w,     B = [J_F; -A_F] (the free duals' rows),
// whose right-hand sides carry the clamped components' moves. It is solved through the Schur complement in w:
// S = B W_FF^-1 B', S w = r_w - B W_FF^-1 r_x, dx_F = W_FF^-1 (r_x + B' w). Its size is that of the live rows, not
// of all of them: slack inequality rows (z = 0 on its bound) never enter it. Storage is sized at setup.
bool Newton::exact_step_lands(const QpProblem& qp, double& e2) {
  trial_e2_ = std::numeric_limits<double>::infinity();
  const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
  const Eigen::Index N = u_.size();
  // The clamped components' moves in du_ (zero at the free ones), the free joints and duals by index.
  int nf = 0, k = 0;
  for (Eigen::Index i = 0; i < N; ++i) {
    const double v = u_(i) - mu_(i);
    const bool is_free = v > lo_u_(i) && v < hi_u_(i);
    du_(i) = is_free ? 0.0 : -e_(i);
    if (!is_free) continue;
    if (i < n) {
      free_x_[static_cast<std::size_t>(nf++)] = static_cast<int>(i);
    } else {
      free_w_[static_cast<std::size_t>(k++)] = static_cast<int>(i - n);
    }
  }
  if (k > nf) return false;  // more live rows than free joints: B has no full row rank
  // rhs = -(M u + g) - M du_c, read at the free components.
  apply_m(qp, du_, rhs_);
  rhs_ = -mu_ - rhs_;
  const double* __restrict W = qp.W.data();
  const double* __restrict J = qp.J.data();
  const double* __restrict A = qp.A.data();
  // B' in bt_ (nf x k): column c is row free_w_[c] of [J; -A] at the free joints.
  for (int c = 0; c < k; ++c) {
    const int r = free_w_[static_cast<std::size_t>(c)];
    double* col = bt_.data() + static_cast<std::ptrdiff_t>(c) * bt_.rows();
    for (int f = 0; f < nf; ++f) {
      const std::ptrdiff_t j = free_x_[static_cast<std::size_t>(f)];
      col[f] = r < me ? J[r + j * me] : -A[(r - me) + j * mi];
    }
  }
  // Y = W_FF^-1 B' (in yt_) and h = W_FF^-1 r_x (in h_).
  for (int f = 0; f < nf; ++f) h_(f) = rhs_(free_x_[static_cast<std::size_t>(f)]);
  if (w_diagonal()) {
    for (int f = 0; f < nf; ++f) {
      const std::ptrdiff_t j = free_x_[static_cast<std::size_t>(f)];
      const double iw = 1.0 / W[j * (n + 1)];
      h_(f) *= iw;
      for (int c = 0; c < k; ++c) yt_(f, c) = bt_(f, c) * iw;
    }
  } else {
    for (int b = 0; b < nf; ++b) {
      for (int a = b; a < nf; ++a) {
        wff_(a, b) = W[free_x_[static_cast<std::size_t>(a)] +
                       static_cast<std::ptrdiff_t>(free_x_[static_cast<std::size_t>(b)]) * n];
      }
    }
    if (!cholesky_in_place(wff_.data(), wff_.rows(), nf, 0.0)) return false;
    cholesky_solve(wff_.data(), wff_.rows(), nf, h_.data());
    for (int c = 0; c < k; ++c) {
      for (int f = 0; f < nf; ++f) yt_(f, c) = bt_(f, c);
      cholesky_solve(wff_.data(), wff_.rows(), nf, yt_.data() + static_cast<std::ptrdiff_t>(c) * yt_.rows());
    }
  }
  // S = B Y (lower triangle) and its right-hand side r_w - B h.
  double scale = 0.0;
  for (int c = 0; c < k; ++c) {
    for (int r = c; r < k; ++r) {
      double t = 0.0;
      for (int f = 0; f < nf; ++f) t += bt_(f, r) * yt_(f, c);
      s_kkt_(r, c) = t;
    }
    scale = std::max(scale, s_kkt_(c, c));
    double t = rhs_(n + free_w_[static_cast<std::size_t>(c)]);
    for (int f = 0; f < nf; ++f) t -= bt_(f, c) * h_(f);
    w_(c) = t;
  }
  if (!cholesky_in_place(s_kkt_.data(), s_kkt_.rows(), k, scale)) return false;  // the live rows are dependent
  cholesky_solve(s_kkt_.data(), s_kkt_.rows(), k, w_.data());
  for (int f = 0; f < nf; ++f) {
    double t = h_(f);
    for (int c = 0; c < k; ++c) t += yt_(f, c) * w_(c);
    du_(free_x_[static_cast<std::size_t>(f)]) = t;
  }
  for (int c = 0; c < k; ++c) du_(n + free_w_[static_cast<std::size_t>(c)]) = w_(c);
  if (!du_.allFinite()) return false;
  trial_ = u_ + du_;
  const double landed = natural_residual2(qp, trial_);
  trial_e2_ = landed;
  if (!(std::sqrt(landed) <= target_at(trial_))) return false;
  u_.swap(trial_);
  e2 = landed;
  return true;
}

// The primal active-set method for min x'Wx/2 + zeta'x subject to J x = d and lo <= x <= hi (W symmetric positive
// definite, no inequality rows that bind). From a feasible point (the rows' best fit inside the bounds, which meets
// them), Newton's step to the minimiser on the current face (the joints at a bound held there, J p = 0 through the
// Schur complement J_F W_FF^-1 J_F'), cut at the first bound it meets, which joins the face; at a face's minimiser,
// the bound whose multiplier (W x + zeta - J'y at that joint) has the wrong sign is released. Each face's minimiser
// is lower than the last, so no face recurs, and the method ends at the optimum in finitely many steps. On a W with
// eigenvalues near zero the face's step is long, and the cut keeps it inside the box, where the exact step of the
// natural map overshoots.
bool Newton::box_solve(const QpProblem& qp, SolverResult& result) {
  const int n = qp.n(), me = qp.m_eq();
  const double* __restrict W = qp.W.data();
  const double* __restrict J = qp.J.data();
  if (me > 0) {
    const RowFit& fit = row_fit(qp);
    if (!(fit.equality_miss <= 1e-12 * (1.0 + qp.d.lpNorm<Eigen::Infinity>()))) return false;
    box_x_ = fit.x;
  } else {
    for (int i = 0; i < n; ++i) box_x_(i) = warm() && result.x.size() == n ? result.x(i) : 0.0;
  }
  for (int i = 0; i < n; ++i) {
    box_x_(i) = box(box_x_(i), qp.lo(i), qp.hi(i));
    box_at_[static_cast<std::size_t>(i)] = box_x_(i) == qp.lo(i) ? -1 : box_x_(i) == qp.hi(i) ? 1 : 0;
  }
  w_.head(me).setZero();  // the rows' multipliers y of the last face
  bool at_minimiser = false;
  for (int iteration = 0; iteration < 20 * n + 50; ++iteration) {
    box_g_.noalias() = qp.W * box_x_;
    box_g_ += qp.zeta;
    if (at_minimiser) {
      // The bounds' multipliers r = g - J'y: at lo r must not be negative, at hi not positive.
      int release = -1;
      double worst = 1e-15 * (1.0 + box_g_.lpNorm<Eigen::Infinity>());
      for (int i = 0; i < n; ++i) {
        const signed char at = box_at_[static_cast<std::size_t>(i)];
        if (at == 0 || qp.lo(i) == qp.hi(i)) continue;
        double r = box_g_(i);
        for (int c = 0; c < me; ++c) r -= J[c + static_cast<std::ptrdiff_t>(i) * me] * w_(c);
        const double wrong = at < 0 ? -r : r;
        if (wrong > worst) {
          worst = wrong;
          release = i;
        }
      }
      if (release < 0) {
        result.x = box_x_;
        result.y = w_.head(me);
        result.z.setZero();
        result.info.status = SolverStatus::kSolved;
        result.info.iterations = iteration;
        result.info.residual = 0.0;
        return true;
      }
      box_at_[static_cast<std::size_t>(release)] = 0;
    }
    // Newton's step on the free joints: p_F = W_FF^-1 (J_F' y - g_F) with J_F p_F = d - J x (0 but for rounding),
    // i.e. S y = J_F W_FF^-1 g_F + d - J x.
    int nf = 0;
    for (int i = 0; i < n; ++i) {
      if (box_at_[static_cast<std::size_t>(i)] == 0) free_x_[static_cast<std::size_t>(nf++)] = i;
    }
    if (me > nf) return false;  // the rows fix the free joints: J_F has no full row rank
    for (int b = 0; b < nf; ++b) {
      const std::ptrdiff_t jb = free_x_[static_cast<std::size_t>(b)];
      h_(b) = box_g_(jb);
      for (int c = 0; c < me; ++c) yt_(b, c) = J[c + jb * me];
      for (int a = b; a < nf; ++a) wff_(a, b) = W[free_x_[static_cast<std::size_t>(a)] + jb * n];
    }
    if (!cholesky_in_place(wff_.data(), wff_.rows(), nf, 0.0)) return false;
    cholesky_solve(wff_.data(), wff_.rows(), nf, h_.data());  // W_FF^-1 g_F
    double scale = 0.0;
    for (int c = 0; c < me; ++c) {
      double t = 0.0;
      for (int f = 0; f < nf; ++f) t += yt_(f, c) * h_(f);
      double miss = qp.d(c);  // and d - J x: the step also takes back what rounding moved the rows by
      for (int i = 0; i < n; ++i) miss -= J[c + static_cast<std::ptrdiff_t>(i) * me] * box_x_(i);
      w_(c) = t + miss;  // J_F W_FF^-1 g_F + (d - J x)
      cholesky_solve(wff_.data(), wff_.rows(), nf, yt_.data() + static_cast<std::ptrdiff_t>(c) * yt_.rows());
    }
    for (int c = 0; c < me; ++c) {
      for (int r = c; r < me; ++r) {
        double t = 0.0;
        for (int f = 0; f < nf; ++f)
          t += J[r + static_cast<std::ptrdiff_t>(free_x_[static_cast<std::size_t>(f)]) * me] * yt_(f, c);
        s_kkt_(r, c) = t;
      }
      scale = std::max(scale, s_kkt_(c, c));
    }
    if (me > 0) {
      if (!cholesky_in_place(s_kkt_.data(), s_kkt_.rows(), me, scale)) return false;
      cholesky_solve(s_kkt_.data(), s_kkt_.rows(), me, w_.data());
    }
    for (int f = 0; f < nf; ++f) {
      double t = -h_(f);
      for (int c = 0; c < me; ++c) t += yt_(f, c) * w_(c);
      h_(f) = t;  // p_F
    }
    double alpha = 1.0;
    int blocking = -1;
    bool up = false;  // the blocking joint meets its upper bound
    for (int f = 0; f < nf; ++f) {
      const int i = free_x_[static_cast<std::size_t>(f)];
      const double p = h_(f);
      const double reach = p > 0.0 ? (qp.hi(i) - box_x_(i)) / p : p < 0.0 ? (qp.lo(i) - box_x_(i)) / p : alpha;
      if (reach < alpha) {
        alpha = std::max(reach, 0.0);
        blocking = i;
        up = p > 0.0;
      }
    }
    if (!std::isfinite(alpha) || !h_.head(nf).allFinite()) return false;
    for (int f = 0; f < nf; ++f) {
      const int i = free_x_[static_cast<std::size_t>(f)];
      box_x_(i) = box(box_x_(i) + alpha * h_(f), qp.lo(i), qp.hi(i));
    }
    if (blocking >= 0) {
      box_x_(blocking) = up ? qp.hi(blocking) : qp.lo(blocking);
      box_at_[static_cast<std::size_t>(blocking)] = up ? 1 : -1;
    }
    at_minimiser = blocking < 0;
  }
  return false;
}

// Semismooth Newton on the natural map from u_, undamped but kept only while it lowers ||e||: where the active set of
// u_ is nearly right (an answer another engine stopped short with), the exact step lands within a few steps.
bool Newton::polish(const QpProblem& qp, double& e2) {
  for (int k = 0; k < kMaxPolishSteps; ++k) {
    if (exact_step_lands(qp, e2)) return true;
    if (!(trial_e2_ < e2)) return false;  // no step, or no progress
    u_.swap(trial_);                      // mu_ and e_ are the trial's (natural_residual2 ran last on it)
    e2 = trial_e2_;
  }
  return false;
}

// out = M w: [W x - J' y + A' z; J x; -A x] for w = [x; y; z] (no temporaries).
void Newton::apply_m(const QpProblem& qp, const Eigen::VectorXd& w, Eigen::VectorXd& out) const {
  const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
  out.head(n).noalias() = qp.W * w.head(n);
  out.head(n).noalias() -= qp.J.transpose() * w.segment(n, me);
  out.head(n).noalias() += qp.A.transpose() * w.tail(mi);
  out.segment(n, me).noalias() = qp.J * w.head(n);
  out.tail(mi).noalias() = qp.A * w.head(n);
  out.tail(mi) = -out.tail(mi);
}

// ||e(w)||^2 of the natural map at w; leaves M w + g in mu_ and e(w) in e_.
double Newton::natural_residual2(const QpProblem& qp, const Eigen::VectorXd& w) {
  const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
  apply_m(qp, w, mu_);
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

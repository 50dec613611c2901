/// The bounded least-squares fit of a QP's constraint rows inside its bounds (best_row_fit, redres/qp/row_fit.hpp).

#include "redres/qp/row_fit.hpp"

#include <algorithm>
#include <cstddef>
#include <vector>

#include "redres/common/error.hpp"

namespace redres {

void RowFitter::setup(int n, int m_e, int m_i) {
  REDRES_REQUIRE(n > 0 && m_e >= 0 && m_i >= 0, "RowFitter::setup", "n > 0, m_e >= 0, m_i >= 0");
  n_ = n;
  m_e_ = m_e;
  m_i_ = m_i;
  const int rows = std::max(1, m_e + m_i);
  fit_.x.setZero(n);
  fit_.misses.setZero(m_e);
  fit_.excesses.setZero(m_i);
  c_.setZero(rows, n);
  cf_.setZero(rows, n);
  e_.setZero(rows);
  r_.setZero(rows);
  res_.setZero(rows);
  c_work_.setZero(rows);
  z_.setZero(n);
  permuted_.setZero(n);
  g_.setZero(n);
  target_.setZero(n);
  best_.setZero(n);
  trial_.setZero(n);
  eq_.setZero(m_e);
  in_.setZero(m_i);
  viol_.setZero(m_i);
  grad_.setZero(n);
  next_.setZero(n);
  stacked_.setZero(rows, n);
  cod_ = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(rows, n);
  cod_.compute(cf_);  // sizes its internal storage once
  svd_ = Eigen::JacobiSVD<Eigen::MatrixXd>(rows, n);
  svd_.compute(stacked_);
  svd_j_ = Eigen::JacobiSVD<Eigen::MatrixXd>(m_e, n);
  if (m_e > 0) svd_j_.compute(Eigen::MatrixXd::Zero(m_e, n));
  state_.assign(static_cast<std::size_t>(n), 0);
  releases_.assign(static_cast<std::size_t>(n), 0);
  active_.assign(static_cast<std::size_t>(m_i), 0);
}

// z_ = the minimum-norm least-squares solution of cf_ z = r_, from cod_ = cf_ P = Q [T 0; 0 0] Z: c = Q' r, T y =
// c(1:rank), z = P Z' [y; 0]. Each of Q's and Z's reflections is applied by hand, into storage sized at setup (what
// the decomposition's own solve() does, but its temporaries allocate).
void RowFitter::min_norm_solve() {
  const Eigen::Index rank = cod_.rank(), rows = cf_.rows(), cols = cf_.cols();
  if (rank == 0) {
    z_.setZero();
    return;
  }
  const Eigen::MatrixXd& qtz = cod_.matrixQTZ();
  // c = Q' r = H_{rank-1} ... H_0 r, with H_k = I - h_k v_k v_k', v_k = [0 (k); 1; qtz(k+1:, k)].
  c_work_ = r_;
  for (Eigen::Index k = 0; k < rank; ++k) {
    double s = c_work_(k);
    for (Eigen::Index i = k + 1; i < rows; ++i) s += qtz(i, k) * c_work_(i);
    s *= cod_.hCoeffs()(k);
    c_work_(k) -= s;
    for (Eigen::Index i = k + 1; i < rows; ++i) c_work_(i) -= s * qtz(i, k);
  }
  // y = T^-1 c(1:rank), then [y; 0].
  permuted_.setZero();
  permuted_.head(rank) = c_work_.head(rank);
  qtz.topLeftCorner(rank, rank).triangularView<Eigen::Upper>().solveInPlace(permuted_.head(rank));
  // Z' [y; 0] = G_{rank-1} ... G_0 [y; 0] (Z = G_0 ... G_{rank-1}, each reflection symmetric), G_k = I - t_k w_k w_k'
  // acting on coordinate k and coordinates rank .. cols-1, with w_k = [1; qtz(k, rank:)].
  if (rank < cols) {
    for (Eigen::Index k = 0; k < rank; ++k) {
      double s = permuted_(k);
      for (Eigen::Index j = rank; j < cols; ++j) s += qtz(k, j) * permuted_(j);
      s *= cod_.zCoeffs()(k);
      permuted_(k) -= s;
      for (Eigen::Index j = rank; j < cols; ++j) permuted_(j) -= s * qtz(k, j);
    }
  }
  // z = P [..]: entry i of the permuted solution belongs to column P(i).
  const auto& p = cod_.colsPermutation().indices();
  for (Eigen::Index i = 0; i < cols; ++i) z_(p(i)) = permuted_(i);
}

// min 1/2 |C x - e|^2 over lo <= x <= hi (bounds may be infinite), from a feasible x, with C and e the first `rows`
// rows of c_ and e_ (the rest zero): an active-set method in the manner of Stark and Parker's BVLS. Each pass solves
// the least-squares problem over the free variables (minimum norm, so that rank-deficient rows are fine), walks
// from x towards that solution until a bound stops it, and once the free variables' solution lies inside the box
// frees the bound variable whose gradient most wants it inside. Every pass decreases the objective; it ends at a
// KKT point, or at the pass cap (a feasible x either way).
void RowFitter::bounded_least_squares(const QpProblem& qp, int rows, Eigen::VectorXd& x) {
  const int n = n_;
  const Eigen::VectorXd& lo = qp.lo;
  const Eigen::VectorXd& hi = qp.hi;
  enum : char { kFree, kAtLower, kAtUpper };
  for (int i = 0; i < n; ++i) {
    char st = kFree;
    if (x(i) <= lo(i)) st = kAtLower;
    if (x(i) >= hi(i)) st = kAtUpper;
    state_[static_cast<std::size_t>(i)] = st;
    releases_[static_cast<std::size_t>(i)] = 0;  // a variable freed again and again is degenerate
  }
  const auto used = c_.topRows(rows);
  const double scale = std::max(1.0, used.cwiseAbs().maxCoeff() * (e_.head(rows).cwiseAbs().maxCoeff() + 1.0));
  for (int pass = 0; pass < 20 * n + 100; ++pass) {
    bool any_free = false;
    for (int i = 0; i < n; ++i) any_free = any_free || state_[static_cast<std::size_t>(i)] == kFree;
    if (any_free) {
      r_ = e_;
      for (int i = 0; i < n; ++i) {
        if (state_[static_cast<std::size_t>(i)] != kFree) {
          r_ -= c_.col(i) * x(i);
          cf_.col(i).setZero();
        } else {
          cf_.col(i) = c_.col(i);
        }
      }
      cod_.compute(cf_);
      min_norm_solve();
      double alpha = 1.0;
      int blocking = -1;  // the variable whose bound stops the step
      bool blocked_low = false;
      for (int i = 0; i < n; ++i) {
        if (state_[static_cast<std::size_t>(i)] != kFree) continue;
        const double to = z_(i), from = x(i);
        double a = 1.0;
        if (to < lo(i)) a = (lo(i) - from) / (to - from);
        if (to > hi(i)) a = (hi(i) - from) / (to - from);
        if (a < alpha) {
          alpha = std::max(0.0, a);
          blocking = i;
          blocked_low = to < lo(i);
        }
      }
      for (int i = 0; i < n; ++i) {
        if (state_[static_cast<std::size_t>(i)] != kFree) continue;
        x(i) = std::clamp(x(i) + alpha * (z_(i) - x(i)), lo(i), hi(i));
      }
      if (blocking >= 0) {
        x(blocking) = blocked_low ? lo(blocking) : hi(blocking);
        state_[static_cast<std::size_t>(blocking)] = blocked_low ? kAtLower : kAtUpper;
        continue;
      }
    }
    // The free variables are optimal: free the bound variable that most wants to move inside, if any does.
    res_.noalias() = c_ * x;
    res_ -= e_;
    g_.noalias() = c_.transpose() * res_;
    int release = -1;
    double worst = 1e-13 * scale;
    for (int i = 0; i < n; ++i) {
      const char st = state_[static_cast<std::size_t>(i)];
      const double want = st == kAtLower ? -g_(i) : st == kAtUpper ? g_(i) : 0.0;
      if (want > worst && releases_[static_cast<std::size_t>(i)] < 3) {
        worst = want;
        release = i;
      }
    }
    if (release < 0) return;
    state_[static_cast<std::size_t>(release)] = kFree;
    ++releases_[static_cast<std::size_t>(release)];
  }
}

// |J x - d|^2 + |(A x - b)+|^2.
double RowFitter::value(const QpProblem& qp, const Eigen::VectorXd& x) {
  eq_.noalias() = qp.J * x;
  eq_ -= qp.d;
  double v = eq_.squaredNorm();
  if (m_i_ > 0) {
    in_.noalias() = qp.A * x;
    in_ -= qp.b;
    v += in_.cwiseMax(0.0).squaredNorm();
  }
  return v;
}

const RowFit& RowFitter::fit(const QpProblem& qp) {
  REDRES_REQUIRE(qp.n() == n_ && qp.m_eq() == m_e_ && qp.m_in() == m_i_, "RowFitter::fit",
                 "the QP has the sizes given to setup()");
  const int n = n_, me = m_e_, mi = m_i_;
  fit_.x = Eigen::VectorXd::Zero(n).cwiseMax(qp.lo).cwiseMin(qp.hi);
  // The inequality rows that x violates are taken as rows to meet with equality, x is fitted again by bounded least
  // squares, and the best point on the segment from the old x to the new one is kept: a semismooth Newton method
  // on |J x - d|^2 + |(A x - b)+|^2 with a line search, exact for equality rows alone (one pass). Projected
  // gradient steps then polish the fit with inequality rows.
  double best_value = value(qp, fit_.x);
  for (int outer = 0; outer < (mi > 0 ? 4 * mi + 20 : 1); ++outer) {
    int active = 0;
    for (int r = 0; r < mi; ++r) {
      if (qp.A.row(r).dot(fit_.x) > qp.b(r)) active_[static_cast<std::size_t>(active++)] = r;
    }
    const int rows = me + active;
    if (rows == 0) break;
    c_.setZero();
    e_.setZero();
    c_.topRows(me) = qp.J;
    e_.head(me) = qp.d;
    for (int k = 0; k < active; ++k) {
      c_.row(me + k) = qp.A.row(active_[static_cast<std::size_t>(k)]);
      e_(me + k) = qp.b(active_[static_cast<std::size_t>(k)]);
    }
    target_ = fit_.x;
    bounded_least_squares(qp, rows, target_);
    // The segment's best point among a few (the objective is convex and piecewise quadratic along it).
    best_ = fit_.x;
    double best_here = best_value;
    for (const double a : {1.0, 0.5, 0.25, 0.125, 0.0625}) {
      // (Clamped: a convex combination of two points in the box can leave it by a rounding.)
      trial_ = (fit_.x + a * (target_ - fit_.x)).cwiseMax(qp.lo).cwiseMin(qp.hi);
      const double v = value(qp, trial_);
      if (v < best_here) {
        best_here = v;
        best_ = trial_;
      }
    }
    const bool improved = best_here < best_value * (1.0 - 1e-12);
    fit_.x = best_;
    best_value = best_here;
    if (!improved) break;
  }
  if (mi > 0) {
    // Step 1 / L with L the largest eigenvalue of [J; A]'[J; A], which bounds the gradient's Lipschitz constant.
    stacked_.topRows(me) = qp.J;
    stacked_.middleRows(me, mi) = qp.A;
    svd_.compute(stacked_);
    const double lipschitz = std::max(svd_.singularValues()(0), 1e-150);
    Eigen::VectorXd& x = trial_;
    x = fit_.x;
    for (int k = 0; k < 20000; ++k) {
      in_.noalias() = qp.A * x;
      viol_ = (in_ - qp.b).cwiseMax(0.0);
      eq_.noalias() = qp.J * x;
      eq_ -= qp.d;
      grad_.noalias() = qp.J.transpose() * eq_;
      grad_.noalias() += qp.A.transpose() * viol_;
      next_ = (x - grad_ / (lipschitz * lipschitz)).cwiseMax(qp.lo).cwiseMin(qp.hi);
      const double moved = (next_ - x).cwiseAbs().maxCoeff();
      x = next_;
      if (moved <= 1e-16 * (1.0 + x.cwiseAbs().maxCoeff())) break;
    }
    if (value(qp, x) < best_value) fit_.x = x;
  }
  fit_.misses.noalias() = qp.J * fit_.x;
  fit_.misses -= qp.d;
  fit_.equality_miss = me > 0 ? fit_.misses.cwiseAbs().maxCoeff() : 0.0;
  fit_.excesses.noalias() = qp.A * fit_.x;
  fit_.excesses -= qp.b;
  fit_.excesses = fit_.excesses.cwiseMax(0.0);
  fit_.inequality_excess = mi > 0 ? fit_.excesses.maxCoeff() : 0.0;
  return fit_;
}

const Eigen::VectorXd& RowFitter::equality_singular_values(const QpProblem& qp) {
  REDRES_REQUIRE(qp.n() == n_ && qp.m_eq() == m_e_ && m_e_ > 0, "RowFitter::equality_singular_values",
                 "the QP has the sizes given to setup() and equality rows");
  svd_j_.compute(qp.J);
  return svd_j_.singularValues();
}

RowFit best_row_fit(const QpProblem& qp) {
  RowFitter fitter;
  fitter.setup(qp.n(), qp.m_eq(), qp.m_in());
  return fitter.fit(qp);
}

}  // namespace redres

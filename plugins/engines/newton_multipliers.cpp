/// `newton`'s general path, step 2 (newton_kkt.cpp): the method of multipliers, each augmented Lagrangian
/// minimised by semismooth Newton with an exact line search.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "newton_internal.hpp"

namespace redres::newton_internal {

// s_r - P_[l_r, h_r](s_r): how far s_r lies outside its interval (signed).
double Newton::excess(int r, double s) const { return s - box(s, row_lo_(r), row_hi_(r)); }

// Step 2 of general_solve(): the method of multipliers from u_, trying step 1 after each outer iteration.
// Rows r: J (m_e, l = h = d), A (m_i, l = -inf, h = b), then the bounds (n, the identity).
bool Newton::augmented_lagrangian(const QpProblem& qp, int& iterations) {
  const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in(), R = me + mi + n;
  Ct_.leftCols(me) = qp.J.transpose();
  Ct_.middleCols(me, mi) = qp.A.transpose();
  Ct_.rightCols(n).setIdentity();
  row_lo_.head(me) = qp.d;
  row_hi_.head(me) = qp.d;
  row_lo_.segment(me, mi).setConstant(-std::numeric_limits<double>::infinity());
  row_hi_.segment(me, mi) = qp.b;
  row_lo_.tail(n) = qp.lo;
  row_hi_.tail(n) = qp.hi;
  // rho_r = rho / |c_r|^2, rho a large multiple of W's scale: the outer iteration contracts the multipliers'
  // error by about 1 / (1 + rho sigma), while the inner Hessian W + rho C'C stays well conditioned (see the cap
  // below).
  const double rho = 1e4 * qp.W.diagonal().cwiseAbs().maxCoeff();
  for (int r = 0; r < R; ++r) {
    const double c2 = Ct_.col(r).squaredNorm();
    rho_(r) = c2 > 0.0 ? rho / c2 : 0.0;
  }
  rho_scale_ = 1.0;
  // Multipliers from u_: lambda_J = -y, lambda_A = z, and the bounds' from stationarity, on a finite side only.
  xa_ = u_.head(n);
  lambda_.head(me) = -u_.segment(n, me);
  lambda_.segment(me, mi) = u_.tail(mi);
  ga_.noalias() = qp.W * xa_;
  ga_ += qp.zeta;
  ga_.noalias() -= qp.J.transpose() * u_.segment(n, me);
  ga_.noalias() += qp.A.transpose() * u_.tail(mi);
  for (int i = 0; i < n; ++i) {
    const double l = -ga_(i);
    lambda_(me + mi + i) = (l > 0.0 && std::isfinite(qp.hi(i))) || (l < 0.0 && std::isfinite(qp.lo(i))) ? l : 0.0;
  }
  const double varpi = settings().varpi;
  double last_violation = std::numeric_limits<double>::infinity();
  for (int outer = 0; outer < kMaxOuterIterations; ++outer) {
    if (!minimise_augmented_lagrangian(qp, iterations)) return false;
    // lambda_r <- rho_r (s_r - P(s_r)) at the minimiser.
    double violation = 0.0;
    for (int r = 0; r < R; ++r) {
      const double cx = Ct_.col(r).dot(xa_);
      violation = std::max(violation, std::abs(excess(r, cx)));
      lambda_(r) = rho_(r) * excess(r, cx + (rho_(r) > 0.0 ? lambda_(r) / rho_(r) : 0.0));
      // Runaway duals of the rows (y, z; the LVI bounds them by varpi): the rows cannot be met. The bounds'
      // multipliers are not duals of the LVI (Omega clips x instead) and may be as large as the data make them.
      if (r < me + mi && !(std::abs(lambda_(r)) <= varpi)) return false;
    }
    u_.head(n) = xa_;
    u_.segment(n, me) = -lambda_.head(me);
    u_.tail(mi) = lambda_.segment(me, mi);
    const double target = target_at(u_);
    // Where the violation does not shrink fast (large multipliers at a nearly degenerate solution, which the
    // update approaches by rho * violation per iteration), raise the penalties tenfold, up to 1e6 times (the inner
    // Hessian's conditioning grows with them), and only while the violation is above the accuracy sought.
    if (violation > 0.25 * last_violation && violation > target && rho_scale_ < 1e6) {
      rho_ *= 10.0;
      rho_scale_ *= 10.0;
    }
    last_violation = violation;
    double e2 = natural_residual2(qp, u_);
    if (std::sqrt(e2) <= target) return true;
    ++iterations;
    if (exact_step_lands(qp, e2)) return true;
  }
  return false;
}

// Minimises the augmented Lagrangian over x from xa_ (semismooth Newton, exact line search); true when a full
// step kept every row on its side, i.e. xa_ is the exact minimiser.
bool Newton::minimise_augmented_lagrangian(const QpProblem& qp, int& iterations) {
  const int R = static_cast<int>(rho_.size());
  for (int inner = 0; inner < kMaxInnerIterations; ++inner, ++iterations) {
    // Gradient W x + zeta + sum_r c_r rho_r excess_r and Hessian W + sum_{r outside} rho_r c_r c_r'.
    ga_.noalias() = qp.W * xa_;
    ga_ += qp.zeta;
    ha_ = qp.W;
    for (int r = 0; r < R; ++r) {
      const double s = Ct_.col(r).dot(xa_) + (rho_(r) > 0.0 ? lambda_(r) / rho_(r) : 0.0);
      s_(r) = s;
      const double ex = excess(r, s);
      if (ex != 0.0) {
        ga_.noalias() += (rho_(r) * ex) * Ct_.col(r);
        ha_.selfadjointView<Eigen::Lower>().rankUpdate(Ct_.col(r), rho_(r));  // LLT reads the lower triangle
      }
    }
    llt_.compute(ha_);
    if (llt_.info() != Eigen::Success) return false;
    dxa_.noalias() = llt_.solve(ga_);
    dxa_ = -dxa_;
    if (!dxa_.allFinite()) return false;
    // phi'(t) along x + t dx: a0 + t q + sum_r rho_r delta_r excess_r(s_r + t delta_r), increasing and
    // piecewise linear, with breakpoints where some s_r + t delta_r crosses l_r or h_r.
    wx_.noalias() = qp.W * xa_;
    wdx_.noalias() = qp.W * dxa_;
    const double a0 = dxa_.dot(wx_) + dxa_.dot(qp.zeta);
    const double q = dxa_.dot(wdx_);
    bool same_side = true;
    int count = 0;
    for (int r = 0; r < R; ++r) {
      const double delta = Ct_.col(r).dot(dxa_);
      delta_r_(r) = delta;
      const double s0 = s_(r), s1 = s0 + delta;
      const int side0 = static_cast<int>(s0 > row_hi_(r)) - static_cast<int>(s0 < row_lo_(r));
      const int side1 = static_cast<int>(s1 > row_hi_(r)) - static_cast<int>(s1 < row_lo_(r));
      same_side &= side0 == side1;
      if (delta != 0.0 && rho_(r) > 0.0) {
        for (const double bound : {row_lo_(r), row_hi_(r)}) {
          const double t = (bound - s0) / delta;
          if (std::isfinite(t) && t > 0.0) breaks_ab_[static_cast<std::size_t>(count++)] = t;
        }
      }
    }
    const auto slope = [&](double t) {
      double v = a0 + t * q;
      for (int r = 0; r < R; ++r) {
        if (delta_r_(r) != 0.0) v += rho_(r) * delta_r_(r) * excess(r, s_(r) + t * delta_r_(r));
      }
      return v;
    };
    if (same_side) {
      // The quadratic model is exact on [0, 1]: the full step reaches the minimiser.
      xa_ += dxa_;
      ++iterations;
      return true;
    }
    std::sort(breaks_ab_.begin(), breaks_ab_.begin() + count);
    double t0 = 0.0, g0 = slope(0.0), t = 0.0;
    for (int k = 0;; ++k) {
      // Past the last breakpoint phi' is linear for ever, with a positive slope (>= q > 0).
      const double t1 = k < count ? breaks_ab_[static_cast<std::size_t>(k)] : t0 + std::max(1.0, t0);
      if (t1 <= t0) continue;
      const double g1 = slope(t1);
      if (g1 >= 0.0) {
        t = g1 > g0 ? t0 + (t1 - t0) * (-g0) / (g1 - g0) : t1;
        break;
      }
      if (k >= count) {
        t = t1 + (t1 - t0) * (-g1) / (g1 - g0);
        break;
      }
      t0 = t1;
      g0 = g1;
    }
    if (!(t > 0.0) || !std::isfinite(t)) return false;
    xa_ += t * dxa_;
  }
  return false;
}

}  // namespace redres::newton_internal

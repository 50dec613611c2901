/// The bounded least-squares fit of a QP's constraint rows inside its bounds (best_row_fit, redres/qp/row_fit.hpp).

#include "redres/qp/row_fit.hpp"

#include <algorithm>
#include <cstddef>
#include <vector>

#include <Eigen/QR>
#include <Eigen/SVD>

namespace redres {

namespace {

// min 1/2 |C x - e|^2 over lo <= x <= hi (bounds may be infinite), from a feasible x: an active-set method in the
// manner of Stark and Parker's BVLS. Each pass solves the least-squares problem over the free variables (minimum
// norm, so that rank-deficient rows are fine), walks from x towards that solution until a bound stops it, and
// once the free variables' solution lies inside the box frees the bound variable whose gradient most wants it
// inside. Every pass decreases the objective; it ends at a KKT point, or at the pass cap (a feasible x either way).
void bounded_least_squares(const Eigen::MatrixXd& C, const Eigen::VectorXd& e, const Eigen::VectorXd& lo,
                           const Eigen::VectorXd& hi, Eigen::VectorXd& x) {
  const int n = static_cast<int>(C.cols());
  enum : char { kFree, kAtLower, kAtUpper };
  std::vector<char> state(static_cast<std::size_t>(n), kFree);
  for (int i = 0; i < n; ++i) {
    if (x(i) <= lo(i)) state[static_cast<std::size_t>(i)] = kAtLower;
    if (x(i) >= hi(i)) state[static_cast<std::size_t>(i)] = kAtUpper;
  }
  const double scale = std::max(1.0, C.cwiseAbs().maxCoeff() * (e.cwiseAbs().maxCoeff() + 1.0));
  std::vector<int> free;
  std::vector<int> releases(static_cast<std::size_t>(n), 0);  // a variable freed again and again is degenerate
  for (int pass = 0; pass < 20 * n + 100; ++pass) {
    free.clear();
    for (int i = 0; i < n; ++i) {
      if (state[static_cast<std::size_t>(i)] == kFree) free.push_back(i);
    }
    if (!free.empty()) {
      Eigen::VectorXd r = e;
      Eigen::MatrixXd CF(C.rows(), static_cast<Eigen::Index>(free.size()));
      for (int i = 0; i < n; ++i) {
        if (state[static_cast<std::size_t>(i)] != kFree) r -= C.col(i) * x(i);
      }
      for (std::size_t j = 0; j < free.size(); ++j) CF.col(static_cast<Eigen::Index>(j)) = C.col(free[j]);
      const Eigen::VectorXd z = CF.completeOrthogonalDecomposition().solve(r);
      double alpha = 1.0;
      int blocking = -1;  // the variable whose bound stops the step
      bool blocked_low = false;
      for (std::size_t j = 0; j < free.size(); ++j) {
        const int i = free[j];
        const double to = z(static_cast<Eigen::Index>(j)), from = x(i);
        double a = 1.0;
        if (to < lo(i)) a = (lo(i) - from) / (to - from);
        if (to > hi(i)) a = (hi(i) - from) / (to - from);
        if (a < alpha) {
          alpha = std::max(0.0, a);
          blocking = i;
          blocked_low = to < lo(i);
        }
      }
      for (std::size_t j = 0; j < free.size(); ++j) {
        const int i = free[j];
        x(i) = std::clamp(x(i) + alpha * (z(static_cast<Eigen::Index>(j)) - x(i)), lo(i), hi(i));
      }
      if (blocking >= 0) {
        x(blocking) = blocked_low ? lo(blocking) : hi(blocking);
        state[static_cast<std::size_t>(blocking)] = blocked_low ? kAtLower : kAtUpper;
        continue;
      }
    }
    // The free variables are optimal: free the bound variable that most wants to move inside, if any does.
    const Eigen::VectorXd g = C.transpose() * (C * x - e);
    int release = -1;
    double worst = 1e-13 * scale;
    for (int i = 0; i < n; ++i) {
      const char st = state[static_cast<std::size_t>(i)];
      const double want = st == kAtLower ? -g(i) : st == kAtUpper ? g(i) : 0.0;
      if (want > worst && releases[static_cast<std::size_t>(i)] < 3) {
        worst = want;
        release = i;
      }
    }
    if (release < 0) return;
    state[static_cast<std::size_t>(release)] = kFree;
    ++releases[static_cast<std::size_t>(release)];
  }
}

}  // namespace

RowFit best_row_fit(const QpProblem& qp) {
  const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
  RowFit fit;
  fit.x = Eigen::VectorXd::Zero(n).cwiseMax(qp.lo).cwiseMin(qp.hi);
  const auto measure = [&qp](const Eigen::VectorXd& x, double& eq, double& in) {
    eq = qp.m_eq() > 0 ? (qp.J * x - qp.d).cwiseAbs().maxCoeff() : 0.0;
    in = qp.m_in() > 0 ? std::max(0.0, (qp.A * x - qp.b).maxCoeff()) : 0.0;
  };
  // The inequality rows that x violates are taken as rows to meet with equality, x is fitted again by bounded least
  // squares, and the best point on the segment from the old x to the new one is kept: a semismooth Newton method
  // on |J x - d|^2 + |(A x - b)+|^2 with a line search, exact for equality rows alone (one pass). Projected
  // gradient steps then polish the fit with inequality rows.
  const auto value = [&qp, mi](const Eigen::VectorXd& x) {
    return (qp.J * x - qp.d).squaredNorm() + (mi > 0 ? (qp.A * x - qp.b).cwiseMax(0.0).squaredNorm() : 0.0);
  };
  double best_value = value(fit.x);
  for (int outer = 0; outer < (mi > 0 ? 4 * mi + 20 : 1); ++outer) {
    std::vector<int> active;
    for (int r = 0; r < mi; ++r) {
      if (qp.A.row(r).dot(fit.x) > qp.b(r)) active.push_back(r);
    }
    const int rows = me + static_cast<int>(active.size());
    if (rows == 0) break;
    Eigen::MatrixXd C(rows, n);
    Eigen::VectorXd e(rows);
    C.topRows(me) = qp.J;
    e.head(me) = qp.d;
    for (std::size_t k = 0; k < active.size(); ++k) {
      C.row(me + static_cast<Eigen::Index>(k)) = qp.A.row(active[k]);
      e(me + static_cast<Eigen::Index>(k)) = qp.b(active[k]);
    }
    Eigen::VectorXd target = fit.x;
    bounded_least_squares(C, e, qp.lo, qp.hi, target);
    // The segment's best point among a few (the objective is convex and piecewise quadratic along it).
    Eigen::VectorXd best = fit.x;
    double best_here = best_value;
    for (const double a : {1.0, 0.5, 0.25, 0.125, 0.0625}) {
      const Eigen::VectorXd x = fit.x + a * (target - fit.x);
      const double v = value(x);
      if (v < best_here) {
        best_here = v;
        best = x;
      }
    }
    const bool improved = best_here < best_value * (1.0 - 1e-12);
    fit.x = best;
    best_value = best_here;
    if (!improved) break;
  }
  if (mi > 0) {
    // Step 1 / L with L the largest eigenvalue of [J; A]'[J; A], which bounds the gradient's Lipschitz constant.
    Eigen::MatrixXd stacked(me + mi, n);
    stacked << qp.J, qp.A;
    const double lipschitz = std::max(Eigen::JacobiSVD<Eigen::MatrixXd>(stacked).singularValues()(0), 1e-150);
    Eigen::VectorXd x = fit.x;
    for (int k = 0; k < 20000; ++k) {
      const Eigen::VectorXd viol = (qp.A * x - qp.b).cwiseMax(0.0);
      const Eigen::VectorXd grad = qp.J.transpose() * (qp.J * x - qp.d) + qp.A.transpose() * viol;
      const Eigen::VectorXd next = (x - grad / (lipschitz * lipschitz)).cwiseMax(qp.lo).cwiseMin(qp.hi);
      const double moved = (next - x).cwiseAbs().maxCoeff();
      x = next;
      if (moved <= 1e-16 * (1.0 + x.cwiseAbs().maxCoeff())) break;
    }
    if (value(x) < best_value) fit.x = x;
  }
  measure(fit.x, fit.equality_miss, fit.inequality_excess);
  return fit;
}

}  // namespace redres

/// `newton`: an exact, fast engine for the same LVI (DESIGN section 2). For diagonal W > 0 with equality rows and
/// bounds, eq. 14 reduces to the m_e dual unknowns y:
///   x(y) = P_[lo,hi](W^-1 (J' y - zeta)),   F(y) = J x(y) - d = 0,
/// where F is minus the gradient of the concave dual function
///   phi(y) = min_{lo <= x <= hi} x'Wx/2 + zeta'x - y'(J x - d).
/// Semismooth Newton: G = J D W^-1 J' (D selects the joints strictly inside their bounds), G delta = -F, with an
/// exact line search on phi (phi is concave and piecewise quadratic along delta, so its maximiser is found by
/// walking the breakpoints where a joint reaches a bound). Where the free joints do not span the rows (a
/// degenerate solution), G is regularised by |F| I (Levenberg-Marquardt), which vanishes at the solution. Once
/// the free set is right the step is exact, so warm-started steps take one or two iterations. At x(y), e_x(u) = 0 by construction and e_y(u) = F(y) while |y| < varpi, so
/// ||e(u)||_2 = ||F(y)||_2 is the paper's stopping test; the engine reports `solved` only once
/// ||F|| <= min(tolerance, 1e-12 (1 + |d|_inf)), i.e. after the exact step, so its KKT residual is tiny.
///
/// Infeasible rows make phi unbounded: the line search then finds phi increasing linearly for ever (a proof of
/// infeasibility), or y leaves [-varpi, varpi]; either way the solve is reported `infeasible`.
///
/// Fallback: for non-diagonal W, W_ii <= 0, inequality rows, a step without ascent or 100 iterations without
/// convergence, the step is solved by `projection` (eq. 15) instead, and the info's `engine` says so.
/// No engine-specific TOML keys.

#include <algorithm>
#include <cmath>
#include <limits>

#include "redres/lvi.hpp"

namespace redres {
namespace {

constexpr int kMaxNewtonIterations = 100;

class Newton final : public LviEngine {
 public:
  explicit Newton(const SolverSettings& s) { set_settings(s); }
  const char* name() const override { return "newton"; }

 private:
  void do_setup(int n, int m_e, int m_i) override {
    x_.setZero(n);
    free_.assign(static_cast<std::size_t>(n), 0);
    v_.setZero(n);
    jtd_.setZero(n);
    dv_.setZero(n);
    breaks_.assign(2 * static_cast<std::size_t>(n), 0.0);
    y_.setZero(m_e);
    F_.setZero(m_e);
    delta_.setZero(m_e);
    diag_.setZero(m_e);
    G_.setZero(m_e, m_e);
    fallback_ = make_engine("projection", settings());
    fallback_result_.x.resize(0);
    fallback_->setup(n, m_e, m_i, fallback_result_);
  }

  // x(y), the free set and F(y); returns phi(y).
  static double evaluate(const QpProblem& qp, const Eigen::VectorXd& y, Eigen::VectorXd& v, Eigen::VectorXd& x,
                         std::vector<char>& free, Eigen::VectorXd& F) {
    const int n = qp.n(), me = qp.m_eq();
    const double* J = qp.J.data();
    double phi = 0.0;
    for (int r = 0; r < me; ++r) F(r) = -qp.d(r);
    for (int i = 0; i < n; ++i) {
      const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
      double jty = 0.0;
      for (int r = 0; r < me; ++r) jty += Ji[r] * y(r);
      const double w = qp.W(i, i);
      const double vi = (jty - qp.zeta(i)) / w;
      const double xi = std::clamp(vi, qp.lo(i), qp.hi(i));
      v(i) = vi;
      x(i) = xi;
      free[static_cast<std::size_t>(i)] = (vi > qp.lo(i) && vi < qp.hi(i)) ? 1 : 0;
      for (int r = 0; r < me; ++r) F(r) += Ji[r] * xi;
      phi += 0.5 * w * xi * xi + qp.zeta(i) * xi;
    }
    for (int r = 0; r < me; ++r) phi -= y(r) * F(r);
    return phi;
  }

  // Solves (G + (reg + prox) I) delta = -F by Cholesky, in place in G_, with G = J D W^-1 J' over the free
  // joints. Without `prox`, false if a pivot is not clearly positive (the free joints do not span the rows).
  bool solve_newton_system(const QpProblem& qp, double prox) {
    const int n = qp.n(), me = qp.m_eq();
    const double* J = qp.J.data();
    G_.setZero();
    double full_scale = 0.0;
    for (int i = 0; i < n; ++i) {
      const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
      for (int r = 0; r < me; ++r) full_scale = std::max(full_scale, Ji[r] * Ji[r] / qp.W(i, i));
    }
    for (int i = 0; i < n; ++i) {
      if (!free_[static_cast<std::size_t>(i)]) continue;
      const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
      const double inv_w = 1.0 / qp.W(i, i);
      for (int c = 0; c < me; ++c) {
        for (int r = c; r < me; ++r) G_(r, c) += Ji[r] * Ji[c] * inv_w;
      }
    }
    const double reg = 1e-13 * (1.0 + full_scale) + prox * full_scale;
    const bool check = prox == 0.0;
    for (int r = 0; r < me; ++r) {
      G_(r, r) += reg;
      diag_(r) = G_(r, r);
    }
    // Cholesky G = L L' (lower triangle of G_).
    for (int c = 0; c < me; ++c) {
      double diag = G_(c, c);
      for (int k = 0; k < c; ++k) diag -= G_(c, k) * G_(c, k);
      // A pivot lost to cancellation means the free joints (nearly) do not span the rows.
      if (check && !(diag > 1e-8 * diag_(c) + 1e-10 * full_scale)) return false;
      if (!(diag > 0.0)) return false;
      const double l = std::sqrt(diag);
      G_(c, c) = l;
      for (int r = c + 1; r < me; ++r) {
        double s = G_(r, c);
        for (int k = 0; k < c; ++k) s -= G_(r, k) * G_(c, k);
        G_(r, c) = s / l;
      }
    }
    for (int r = 0; r < me; ++r) {  // L w = -F
      double s = -F_(r);
      for (int k = 0; k < r; ++k) s -= G_(r, k) * delta_(k);
      delta_(r) = s / G_(r, r);
    }
    for (int r = me - 1; r >= 0; --r) {  // L' delta = w
      double s = delta_(r);
      for (int k = r + 1; k < me; ++k) s -= G_(k, r) * delta_(k);
      delta_(r) = s / G_(r, r);
    }
    return true;
  }

  // phi'(s) along y + s delta: -delta . F(y + s delta) = sum_i -(J' delta)_i x_i(s) + delta . d, with
  // x_i(s) = P(v_i + s dv_i); piecewise linear and nonincreasing in s.
  double slope_at(const QpProblem& qp, double s) const {
    double out = delta_.dot(qp.d);
    for (int i = 0; i < qp.n(); ++i) {
      out -= jtd_(i) * std::clamp(v_(i) + s * dv_(i), qp.lo(i), qp.hi(i));
    }
    return out;
  }

  // The exact maximiser of the concave, piecewise quadratic phi along delta (phi' is piecewise linear between the
  // breakpoints where some v_i crosses a bound). Returns +inf when phi' stays positive for ever: the dual is then
  // unbounded, which proves that J x = d cannot be met inside the bounds.
  double exact_step(const QpProblem& qp) {
    const int n = qp.n(), me = qp.m_eq();
    const double* J = qp.J.data();
    int count = 0;
    for (int i = 0; i < n; ++i) {
      const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
      double jtd = 0.0;
      for (int r = 0; r < me; ++r) jtd += Ji[r] * delta_(r);
      jtd_(i) = jtd;
      dv_(i) = jtd / qp.W(i, i);
      if (dv_(i) != 0.0) {
        for (const double bound : {qp.lo(i), qp.hi(i)}) {
          const double s = (bound - v_(i)) / dv_(i);
          if (std::isfinite(s) && s > 0.0) breaks_[static_cast<std::size_t>(count++)] = s;
        }
      }
    }
    std::sort(breaks_.begin(), breaks_.begin() + count);
    double s0 = 0.0;
    double g0 = slope_at(qp, 0.0);
    if (!(g0 > 0.0)) return 0.0;
    for (int k = 0; k <= count; ++k) {
      // Beyond the last breakpoint phi' is linear for ever; probe it one unit further.
      const double s1 = k < count ? breaks_[static_cast<std::size_t>(k)] : s0 + std::max(1.0, s0);
      if (s1 <= s0) continue;
      const double g1 = slope_at(qp, s1);
      if (g1 <= 0.0) return s0 + (s1 - s0) * g0 / (g0 - g1);  // root of the linear piece
      if (k == count && !(g1 < g0 * (1.0 - 1e-12))) return std::numeric_limits<double>::infinity();
      if (k == count) return s1 + (s1 - s0) * g1 / (g0 - g1);
      s0 = s1;
      g0 = g1;
    }
    return s0;
  }

  void run_fallback(const QpProblem& qp, SolverResult& result) {
    fallback_->solve(qp, fallback_result_);
    result.x = fallback_result_.x;
    result.y = fallback_result_.y;
    result.z = fallback_result_.z;
    const std::string diagnosis = std::move(result.info.diagnosis);
    result.info = fallback_result_.info;  // names "projection" as the engine that ran
    if (result.info.diagnosis.empty()) result.info.diagnosis = diagnosis;
    y_ = result.y;
  }

  void do_solve(const QpProblem& qp, SolverResult& result) override {
    SolverInfo& info = result.info;
    const int n = qp.n(), me = qp.m_eq();
    bool applicable = qp.w_diagonal && qp.m_in() == 0;
    for (int i = 0; i < n && applicable; ++i) applicable = qp.W(i, i) > 0.0;
    if (!applicable) {
      run_fallback(qp, result);
      return;
    }
    if (!warm()) y_.setZero();
    const double varpi = settings().varpi;
    const double target = std::min(settings().tolerance, 1e-12 * (1.0 + (me > 0 ? qp.d.cwiseAbs().maxCoeff() : 0.0)));

    evaluate(qp, y_, v_, x_, free_, F_);
    int k = 0;
    bool converged = false;
    for (;; ++k) {
      const double fnorm = F_.norm();
      if (fnorm <= target) {
        converged = true;
        break;
      }
      if (k >= kMaxNewtonIterations) break;
      // Where the free joints do not span the rows (at a degenerate solution some v_i sits exactly on its
      // bound), the generalised Jacobian also takes the clamped joints nearest to their bounds, nearest first,
      // until the rows are spanned. If phi grows linearly for ever along the step, the rows cannot be met.
      // Where the free joints do not span the rows (a degenerate solution, where some v_i sits on its bound),
      // G is singular: regularise it proximally with |F| (Levenberg-Marquardt), which vanishes at the solution.
      if (!solve_newton_system(qp, 0.0) && !solve_newton_system(qp, F_.norm())) break;
      const double step = exact_step(qp);

      if (!std::isfinite(step) || !(step > 0.0)) {
        if (std::isinf(step)) {
          info.iterations = k + 1;
          info.residual = F_.norm();
          info.status = SolverStatus::kInfeasible;
          result.x = x_;
          result.y = y_;
          result.z.setZero();
          return;
        }
        break;  // no ascent: leave it to the fallback
      }
      y_ += step * delta_;
      evaluate(qp, y_, v_, x_, free_, F_);
      if (y_.cwiseAbs().maxCoeff() > varpi) {
        // The duals left the LVI's box: J x = d cannot be met inside the bounds.
        info.iterations = k + 1;
        info.residual = F_.norm();
        info.status = SolverStatus::kInfeasible;
        y_ = y_.cwiseMax(-varpi).cwiseMin(varpi);
        result.x = x_;
        result.y = y_;
        result.z.setZero();
        return;
      }
    }
    if (!converged) {
      info.diagnosis = "newton did not converge in " + std::to_string(k) + " iterations (residual " +
                       std::to_string(F_.norm()) + "); fell back to projection";
      run_fallback(qp, result);
      return;
    }
    info.iterations = k;
    info.residual = F_.norm();
    info.status = SolverStatus::kSolved;
    result.x = x_;
    result.y = y_;
    result.z.setZero();
  }

  Eigen::VectorXd v_, x_, y_, F_, delta_, diag_, jtd_, dv_;
  std::vector<char> free_;
  std::vector<double> breaks_;
  Eigen::MatrixXd G_;
  std::unique_ptr<LviEngine> fallback_;
  SolverResult fallback_result_;
};

const bool kRegistered = engine_registry().add({
    "newton",
    "semismooth Newton on the reduced eq. 14 (exact; diagonal W, equality rows and bounds; else projection)",
    {},
    [](const TableReader& /*r*/, const SolverSettings& s) -> std::unique_ptr<LviEngine> {
      return std::make_unique<Newton>(s);
    },
});

}  // namespace
}  // namespace redres

/// `newton`: an exact, fast engine for the same LVI (DESIGN section 2). For diagonal W > 0 with equality rows and
/// bounds, eq. 14 reduces to the m_e dual unknowns y:
///   x(y) = P_[lo,hi](W^-1 (J' y - zeta)),   F(y) = J x(y) - d = 0,
/// where F is minus the gradient of the concave dual function
///   phi(y) = min_{lo <= x <= hi} x'Wx/2 + zeta'x - y'(J x - d).
/// Semismooth Newton: G = J D W^-1 J' (D selects the joints strictly inside their bounds), G delta = -F, with a
/// backtracking (Armijo) line search on phi. Once the free set is right the step is exact, so warm-started steps
/// take one or two iterations. At x(y), e_x(u) = 0 by construction and e_y(u) = F(y) while |y| < varpi, so
/// ||e(u)||_2 = ||F(y)||_2 is the paper's stopping test; the engine reports `solved` only once
/// ||F|| <= min(tolerance, 1e-12 (1 + |d|_inf)), i.e. after the exact step, so its KKT residual is tiny.
///
/// Infeasible rows make phi unbounded: y then leaves [-varpi, varpi] and the solve is reported `infeasible`.
///
/// Fallback: for non-diagonal W, W_ii <= 0, inequality rows, a failed line search or 100 iterations without
/// convergence, the step is solved by `projection` (eq. 15) instead, and the info's `engine` says so.
/// No engine-specific TOML keys.

#include <algorithm>
#include <cmath>

#include "redres/lvi.hpp"

namespace redres {
namespace {

constexpr int kMaxNewtonIterations = 100;
constexpr int kMaxHalvings = 40;

class Newton final : public LviEngine {
 public:
  explicit Newton(const SolverSettings& s) { set_settings(s); }
  const char* name() const override { return "newton"; }

 private:
  void do_setup(int n, int m_e, int m_i) override {
    x_.setZero(n);
    x_trial_.setZero(n);
    free_.assign(static_cast<std::size_t>(n), 0);
    free_trial_.assign(static_cast<std::size_t>(n), 0);
    y_.setZero(m_e);
    y_trial_.setZero(m_e);
    F_.setZero(m_e);
    F_trial_.setZero(m_e);
    delta_.setZero(m_e);
    G_.setZero(m_e, m_e);
    fallback_ = make_engine("projection", settings());
    fallback_result_.x.resize(0);
    fallback_->setup(n, m_e, m_i, fallback_result_);
  }

  // x(y), the free set and F(y); returns phi(y).
  static double evaluate(const QpProblem& qp, const Eigen::VectorXd& y, Eigen::VectorXd& x, std::vector<char>& free,
                         Eigen::VectorXd& F) {
    const int n = qp.n(), me = qp.m_eq();
    const double* J = qp.J.data();
    double phi = 0.0;
    for (int r = 0; r < me; ++r) F(r) = -qp.d(r);
    for (int i = 0; i < n; ++i) {
      const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
      double jty = 0.0;
      for (int r = 0; r < me; ++r) jty += Ji[r] * y(r);
      const double w = qp.W(i, i);
      const double v = (jty - qp.zeta(i)) / w;
      const double xi = std::clamp(v, qp.lo(i), qp.hi(i));
      x(i) = xi;
      free[static_cast<std::size_t>(i)] = (v > qp.lo(i) && v < qp.hi(i)) ? 1 : 0;
      for (int r = 0; r < me; ++r) F(r) += Ji[r] * xi;
      phi += 0.5 * w * xi * xi + qp.zeta(i) * xi;
    }
    for (int r = 0; r < me; ++r) phi -= y(r) * F(r);
    return phi;
  }

  // Solves (G + reg I) delta = -F by Cholesky, in place in G_. False if G is not positive definite.
  bool solve_newton_system(const QpProblem& qp) {
    const int n = qp.n(), me = qp.m_eq();
    const double* J = qp.J.data();
    G_.setZero();
    for (int i = 0; i < n; ++i) {
      if (!free_[static_cast<std::size_t>(i)]) continue;
      const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
      const double inv_w = 1.0 / qp.W(i, i);
      for (int c = 0; c < me; ++c) {
        for (int r = c; r < me; ++r) G_(r, c) += Ji[r] * Ji[c] * inv_w;
      }
    }
    double scale = 0.0;
    for (int r = 0; r < me; ++r) scale = std::max(scale, G_(r, r));
    const double reg = 1e-13 * (1.0 + scale);
    for (int r = 0; r < me; ++r) G_(r, r) += reg;
    // Cholesky G = L L' (lower triangle of G_).
    for (int c = 0; c < me; ++c) {
      double diag = G_(c, c);
      for (int k = 0; k < c; ++k) diag -= G_(c, k) * G_(c, k);
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

    double phi = evaluate(qp, y_, x_, free_, F_);
    int k = 0;
    bool converged = false;
    for (;; ++k) {
      const double fnorm = F_.norm();
      if (fnorm <= target) {
        converged = true;
        break;
      }
      if (k >= kMaxNewtonIterations) break;
      if (!solve_newton_system(qp)) break;
      const double slope = -F_.dot(delta_);  // grad phi . delta > 0
      double s = 1.0;
      bool accepted = false;
      for (int h = 0; h < kMaxHalvings; ++h, s *= 0.5) {
        y_trial_ = y_ + s * delta_;
        const double phi_trial = evaluate(qp, y_trial_, x_trial_, free_trial_, F_trial_);
        if (phi_trial >= phi + 1e-4 * s * slope - 1e-14 * std::abs(phi) || y_trial_.cwiseAbs().maxCoeff() > varpi) {
          accepted = true;
          y_.swap(y_trial_);
          x_.swap(x_trial_);
          free_.swap(free_trial_);
          F_.swap(F_trial_);
          phi = phi_trial;
          break;
        }
      }
      if (!accepted) break;
      if (y_.cwiseAbs().maxCoeff() > varpi) {
        // phi is unbounded along delta: J x = d cannot be met inside the bounds.
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

  Eigen::VectorXd x_, x_trial_, y_, y_trial_, F_, F_trial_, delta_;
  std::vector<char> free_, free_trial_;
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

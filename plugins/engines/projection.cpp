/// `projection`: the paper's LVI-based numerical algorithm, eq. 15:
///   u^{k+1} = u^k - (||e(u^k)||^2 / ||phi(u^k)||^2) phi(u^k),  phi = (M' + I) e,
/// stopped when ||e(u^k)||_2 <= tolerance. It converges globally and linearly.
///
/// Choices (DESIGN section 2):
/// - The iterate u^k is not kept inside Omega, so its x may leave [lo, hi] by about the tolerance. The returned x
///   is the projection of the final iterate onto [lo, hi] (the bounds then hold exactly); the reported residual is
///   ||e|| of the iterate itself, i.e. the paper's stopping test. The engine keeps the unprojected iterate for the
///   warm start, so the sequence of iterates is exactly the paper's.
/// - Diagonal W is exploited in W x and W' e; the products are the same floating-point sums as the dense ones
///   (the skipped terms are exact zeros), so the iterates do not change.
/// - Warm start: u^0 is the previous solve's final iterate (after an infeasible or failed solve it is reset to 0).
///
/// No engine-specific TOML keys.

#include <algorithm>
#include <cmath>

#include "redres/lvi.hpp"

namespace redres {
namespace {

class Projection final : public LviEngine {
 public:
  explicit Projection(const SolverSettings& s) { set_settings(s); }
  const char* name() const override { return "projection"; }

 private:
  void do_setup(int n, int m_e, int m_i) override {
    for (Eigen::VectorXd* v : {&ux_, &rx_, &ex_, &px_}) v->setZero(n);
    for (Eigen::VectorXd* v : {&uy_, &ry_, &ey_, &py_}) v->setZero(m_e);
    for (Eigen::VectorXd* v : {&uz_, &rz_, &ez_, &pz_}) v->setZero(m_i);
  }

  void do_solve(const QpProblem& qp, SolverResult& result) override {
    const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
    const double varpi = settings().varpi;
    const double tol2 = settings().tolerance * settings().tolerance;
    if (!warm()) {
      ux_.setZero();
      uy_.setZero();
      uz_.setZero();
    }
    const double* W = qp.W.data();
    const double* J = qp.J.data();
    const double* A = qp.A.data();
    const bool diag = qp.w_diagonal;
    double* x = ux_.data();
    double* y = uy_.data();
    double* z = uz_.data();
    double *rx = rx_.data(), *ry = ry_.data(), *rz = rz_.data();
    double *ex = ex_.data(), *ey = ey_.data(), *ez = ez_.data();
    double *px = px_.data(), *py = py_.data(), *pz = pz_.data();

    SolverInfo& info = result.info;
    int k = 0;
    double e2 = 0.0;
    bool broke_down = false;
    for (;; ++k) {
      // r = M u + g.
      for (int r = 0; r < me; ++r) ry[r] = -qp.d(r);
      for (int r = 0; r < mi; ++r) rz[r] = qp.b(r);
      for (int i = 0; i < n; ++i) {
        const double* Wi = W + static_cast<std::ptrdiff_t>(i) * n;  // column i (W symmetric)
        double wx = 0.0;
        if (diag) {
          wx = Wi[i] * x[i];
        } else {
          for (int j = 0; j < n; ++j) wx += Wi[j] * x[j];
        }
        const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
        const double* Ai = A + static_cast<std::ptrdiff_t>(i) * mi;
        double jty = 0.0, atz = 0.0;
        for (int r = 0; r < me; ++r) {
          jty += Ji[r] * y[r];
          ry[r] += Ji[r] * x[i];
        }
        for (int r = 0; r < mi; ++r) {
          atz += Ai[r] * z[r];
          rz[r] -= Ai[r] * x[i];
        }
        rx[i] = wx - jty + atz + qp.zeta(i);
      }
      // e = u - P_Omega(u - r).
      e2 = 0.0;
      for (int i = 0; i < n; ++i) {
        ex[i] = x[i] - std::clamp(x[i] - rx[i], qp.lo(i), qp.hi(i));
        e2 += ex[i] * ex[i];
      }
      for (int r = 0; r < me; ++r) {
        ey[r] = y[r] - std::clamp(y[r] - ry[r], -varpi, varpi);
        e2 += ey[r] * ey[r];
      }
      for (int r = 0; r < mi; ++r) {
        ez[r] = z[r] - std::clamp(z[r] - rz[r], 0.0, varpi);
        e2 += ez[r] * ez[r];
      }
      if (e2 <= tol2 || k >= settings().max_iterations) break;
      // phi = (M' + I) e, M' = [W' J' -A'; -J 0 0; A 0 0].
      for (int r = 0; r < me; ++r) py[r] = ey[r];
      for (int r = 0; r < mi; ++r) pz[r] = ez[r];
      double p2 = 0.0;
      for (int i = 0; i < n; ++i) {
        const double* Wi = W + static_cast<std::ptrdiff_t>(i) * n;
        double we = 0.0;
        if (diag) {
          we = Wi[i] * ex[i];
        } else {
          for (int j = 0; j < n; ++j) we += Wi[j] * ex[j];
        }
        const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
        const double* Ai = A + static_cast<std::ptrdiff_t>(i) * mi;
        double jte = 0.0, ate = 0.0;
        for (int r = 0; r < me; ++r) {
          jte += Ji[r] * ey[r];
          py[r] -= Ji[r] * ex[i];
        }
        for (int r = 0; r < mi; ++r) {
          ate += Ai[r] * ez[r];
          pz[r] += Ai[r] * ex[i];
        }
        px[i] = we + jte - ate + ex[i];
        p2 += px[i] * px[i];
      }
      for (int r = 0; r < me; ++r) p2 += py[r] * py[r];
      for (int r = 0; r < mi; ++r) p2 += pz[r] * pz[r];
      if (!(p2 > 0.0) || !std::isfinite(p2)) {
        broke_down = true;
        info.diagnosis = "eq. 15 broke down: ||phi|| = 0 with ||e|| = " + std::to_string(std::sqrt(e2));
        break;
      }
      const double step = e2 / p2;
      for (int i = 0; i < n; ++i) x[i] -= step * px[i];
      for (int r = 0; r < me; ++r) y[r] -= step * py[r];
      for (int r = 0; r < mi; ++r) z[r] -= step * pz[r];
    }
    info.iterations = k;
    info.residual = std::sqrt(e2);
    info.status = broke_down ? SolverStatus::kNumericalError
                             : (e2 <= tol2 ? SolverStatus::kSolved : SolverStatus::kMaxIterations);
    result.x = ux_.cwiseMax(qp.lo).cwiseMin(qp.hi);
    result.y = uy_;
    result.z = uz_;
  }

  Eigen::VectorXd ux_, uy_, uz_, rx_, ry_, rz_, ex_, ey_, ez_, px_, py_, pz_;
};

const bool kRegistered = engine_registry().add({
    "projection",
    "the paper's eq. 15 (linear convergence; the reference for fidelity)",
    {},
    [](const TableReader& /*r*/, const SolverSettings& s) -> std::unique_ptr<LviEngine> {
      return std::make_unique<Projection>(s);
    },
});

}  // namespace
}  // namespace redres

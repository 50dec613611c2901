/// `nlopt`: NLopt's SLSQP applied to the QP itself (not to the LVI), as an independent cross-check of the LVI
/// engines. The duals, which SLSQP does not return, are estimated by least squares on the stationarity condition
/// over the joints strictly inside their bounds (and the active inequality rows, z >= 0), so that the residual
/// ||e(u)|| can be reported like the other engines'. `iterations` counts objective evaluations.
///
/// Allocation: the wrapper's buffers are sized at setup, but NLopt's SLSQP allocates its own work arrays inside
/// every nlopt_optimize() call, and the dual estimate uses a QR factorisation; this engine is a cross-check, not
/// for the real-time path. No engine-specific TOML keys.

#include <cmath>

#include <nlopt.h>

#include <Eigen/QR>

#include "redres/lvi.hpp"

namespace redres {
namespace {

class NloptSlsqp final : public LviEngine {
 public:
  explicit NloptSlsqp(const SolverSettings& s) { set_settings(s); }
  NloptSlsqp(const NloptSlsqp&) = delete;
  NloptSlsqp& operator=(const NloptSlsqp&) = delete;
  ~NloptSlsqp() override {
    if (opt_ != nullptr) nlopt_destroy(opt_);
  }
  const char* name() const override { return "nlopt"; }

 private:
  void do_setup(int n, int m_e, int m_i) override {
    if (opt_ != nullptr) nlopt_destroy(opt_);
    opt_ = nlopt_create(NLOPT_LD_SLSQP, static_cast<unsigned>(n));
    if (opt_ == nullptr) throw std::runtime_error("nlopt: nlopt_create(SLSQP) failed");
    nlopt_set_min_objective(opt_, &NloptSlsqp::objective, this);
    tol_eq_.assign(static_cast<std::size_t>(m_e), 1e-13);
    tol_in_.assign(static_cast<std::size_t>(m_i), 1e-13);
    if (m_e > 0) {
      nlopt_add_equality_mconstraint(opt_, static_cast<unsigned>(m_e), &NloptSlsqp::equality, this, tol_eq_.data());
    }
    if (m_i > 0) {
      nlopt_add_inequality_mconstraint(opt_, static_cast<unsigned>(m_i), &NloptSlsqp::inequality, this,
                                       tol_in_.data());
    }
    nlopt_set_xtol_abs1(opt_, 1e-14);
    nlopt_set_ftol_abs(opt_, 1e-16);
    x_.setZero(n);
    have_x_ = false;
  }

  static double objective(unsigned /*n*/, const double* x, double* grad, void* data) {
    auto* self = static_cast<NloptSlsqp*>(data);
    const QpProblem& qp = *self->qp_;
    ++self->evaluations_;
    const Eigen::Map<const Eigen::VectorXd> xv(x, qp.n());
    double f = qp.zeta.dot(xv);
    for (int i = 0; i < qp.n(); ++i) {
      const double wx = qp.W.col(i).dot(xv);  // W symmetric
      f += 0.5 * xv(i) * wx;
      if (grad != nullptr) grad[i] = wx + qp.zeta(i);
    }
    return f;
  }

  static void equality(unsigned m, double* result, unsigned n, const double* x, double* grad, void* data) {
    const QpProblem& qp = *static_cast<NloptSlsqp*>(data)->qp_;
    rows(qp.J, qp.d, m, result, n, x, grad);
  }

  static void inequality(unsigned m, double* result, unsigned n, const double* x, double* grad, void* data) {
    const QpProblem& qp = *static_cast<NloptSlsqp*>(data)->qp_;
    rows(qp.A, qp.b, m, result, n, x, grad);
  }

  // result = M x - v, grad (row-major m x n) = M.
  static void rows(const Eigen::MatrixXd& M, const Eigen::VectorXd& v, unsigned m, double* result, unsigned n,
                   const double* x, double* grad) {
    const Eigen::Map<const Eigen::VectorXd> xv(x, n);
    for (unsigned r = 0; r < m; ++r) {
      result[r] = M.row(r).dot(xv) - v(r);
      if (grad != nullptr) {
        for (unsigned i = 0; i < n; ++i) grad[r * n + i] = M(r, i);
      }
    }
  }

  void do_solve(const QpProblem& qp, SolverResult& result) override {
    qp_ = &qp;
    evaluations_ = 0;
    const int n = qp.n();
    nlopt_set_lower_bounds(opt_, qp.lo.data());
    nlopt_set_upper_bounds(opt_, qp.hi.data());
    nlopt_set_maxeval(opt_, settings().max_iterations);
    // Start from the previous answer, or from the box point nearest 0, either way inside the bounds.
    if (!(warm() && have_x_)) x_.setZero();
    x_ = x_.cwiseMax(qp.lo).cwiseMin(qp.hi);
    double f = 0.0;
    const nlopt_result code = nlopt_optimize(opt_, x_.data(), &f);
    result.x = x_.cwiseMax(qp.lo).cwiseMin(qp.hi);
    estimate_duals(qp, result);
    SolverInfo& info = result.info;
    info.iterations = evaluations_;
    info.residual = lvi_residual(qp, result, settings().varpi);
    const double feas =
        std::max(qp.m_eq() > 0 ? (qp.J * result.x - qp.d).cwiseAbs().maxCoeff() : 0.0,
                 qp.m_in() > 0 ? (qp.A * result.x - qp.b).maxCoeff() : 0.0);
    if (code == NLOPT_MAXEVAL_REACHED) {
      info.status = SolverStatus::kMaxIterations;
    } else if (code > 0 && feas <= settings().tolerance && info.residual <= settings().tolerance) {
      info.status = SolverStatus::kSolved;
    } else if (code > 0 || code == NLOPT_ROUNDOFF_LIMITED) {
      info.status = SolverStatus::kMaxIterations;  // stopped short of the tolerance; diagnosed by the caller
    } else {
      info.status = SolverStatus::kNumericalError;
      info.diagnosis = "nlopt SLSQP failed with code " + std::to_string(static_cast<int>(code)) + " (" +
                       nlopt_result_to_string(code) + ")";
    }
    have_x_ = info.status == SolverStatus::kSolved;
    (void)n;
  }

  // Least-squares duals from (W x + zeta - J' y + A' z)_F = 0 over the free joints F, with z on the active rows.
  static void estimate_duals(const QpProblem& qp, SolverResult& result) {
    const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
    std::vector<int> free, active;
    for (int i = 0; i < n; ++i) {
      if (result.x(i) > qp.lo(i) + 1e-10 && result.x(i) < qp.hi(i) - 1e-10) free.push_back(i);
    }
    for (int r = 0; r < mi; ++r) {
      if (qp.A.row(r).dot(result.x) >= qp.b(r) - 1e-9) active.push_back(r);
    }
    result.y.setZero();
    result.z.setZero();
    const int cols = me + static_cast<int>(active.size());
    if (free.empty() || cols == 0) return;
    Eigen::MatrixXd B(static_cast<Eigen::Index>(free.size()), cols);
    Eigen::VectorXd rhs(static_cast<Eigen::Index>(free.size()));
    const Eigen::VectorXd g = qp.W * result.x + qp.zeta;
    for (std::size_t k = 0; k < free.size(); ++k) {
      const int i = free[k];
      const auto row = static_cast<Eigen::Index>(k);
      for (int r = 0; r < me; ++r) B(row, r) = qp.J(r, i);
      for (std::size_t a = 0; a < active.size(); ++a) B(row, me + static_cast<Eigen::Index>(a)) = -qp.A(active[a], i);
      rhs(row) = g(i);
    }
    const Eigen::VectorXd sol = B.colPivHouseholderQr().solve(rhs);
    result.y = sol.head(me);
    for (std::size_t a = 0; a < active.size(); ++a) {
      result.z(active[a]) = std::max(0.0, sol(me + static_cast<Eigen::Index>(a)));
    }
  }

  nlopt_opt opt_ = nullptr;
  const QpProblem* qp_ = nullptr;
  int evaluations_ = 0;
  std::vector<double> tol_eq_, tol_in_;
  Eigen::VectorXd x_;
  bool have_x_ = false;
};

const bool kRegistered = engine_registry().add({
    "nlopt",
    "NLopt SLSQP on the QP (independent cross-check; allocates inside NLopt)",
    {},
    [](const TableReader& /*r*/, const SolverSettings& s) -> std::unique_ptr<LviEngine> {
      return std::make_unique<NloptSlsqp>(s);
    },
});

}  // namespace
}  // namespace redres

/// `nlopt`: NLopt's SLSQP applied to the QP itself (not to the LVI), as an independent cross-check of the LVI
/// engines. The duals, which SLSQP does not return, are estimated by least squares on the stationarity condition
/// over the joints strictly inside their bounds (and the active inequality rows, z >= 0), so that the residual
/// ||e(u)|| can be reported like the other engines'. `iterations` counts objective evaluations.
///
/// Allocation: everything redres does per solve uses buffers sized at setup (the dual estimate's QR included), but
/// NLopt's SLSQP allocates its own work array inside every nlopt_optimize() call (one malloc, freed before it
/// returns; NLopt has no caller-provided workspace). A test pins the count to NLopt's own. This engine is a
/// cross-check, not for the real-time path. No engine-specific TOML keys.

#include <cmath>

#include <nlopt.h>

#include <Eigen/QR>

#include "redres/control/engine_registry.hpp"
#include "redres/engines/nlopt.hpp"

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
  std::string_view name() const override { return "nlopt"; }

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
      nlopt_add_inequality_mconstraint(opt_, static_cast<unsigned>(m_i), &NloptSlsqp::inequality, this, tol_in_.data());
    }
    nlopt_set_xtol_abs1(opt_, 1e-14);
    nlopt_set_ftol_abs(opt_, 1e-16);
    x_.setZero(n);
    have_x_ = false;
    const int k = m_e + m_i;
    B_.setZero(n, k);
    rhs_.setZero(n);
    sol_.setZero(k);
    active_.assign(static_cast<std::size_t>(m_i), 0);
    qr_ = Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(n, k);
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
    double feas = 0.0;
    for (int r = 0; r < qp.m_eq(); ++r) feas = std::max(feas, std::abs(qp.J.row(r).dot(result.x) - qp.d(r)));
    for (int r = 0; r < qp.m_in(); ++r) feas = std::max(feas, qp.A.row(r).dot(result.x) - qp.b(r));
    if (code == NLOPT_MAXEVAL_REACHED) {
      info.status = SolverStatus::kMaxIterations;
    } else if ((code > 0 || code == NLOPT_ROUNDOFF_LIMITED) && feas <= settings().tolerance &&
               info.residual <= settings().tolerance) {
      // Roundoff-limited: SLSQP could not improve further in floating point; its answer counts when it meets the
      // tolerance like any other.
      info.status = SolverStatus::kSolved;
    } else if (code > 0 || code == NLOPT_ROUNDOFF_LIMITED) {
      // SLSQP met one of its own stopping tests (or rounding stopped it) short of the tolerance: not the iteration
      // cap, which is NLOPT_MAXEVAL_REACHED above.
      info.status = SolverStatus::kNumericalError;
      keep_diagnosis_capacity(info.diagnosis);
      info.diagnosis.clear();
      TextSink(info.diagnosis) << "SLSQP ended with " << nlopt_result_to_string(code) << " short of the tolerance";
    } else {
      info.status = SolverStatus::kNumericalError;
      keep_diagnosis_capacity(info.diagnosis);
      info.diagnosis.clear();
      TextSink(info.diagnosis) << "nlopt SLSQP failed with code " << static_cast<int>(code) << " ("
                               << nlopt_result_to_string(code) << ")";
    }
    have_x_ = info.status == SolverStatus::kSolved;
    (void)n;
  }

  // Least-squares duals from (W x + zeta - J' y + A' z)_F = 0 over the free joints F, with z on the active rows.
  // The matrix keeps its setup size: rows of clamped joints and columns of inactive rows are zero, which leaves the
  // least-squares solution unchanged (column-pivoting QR gives the zero columns a zero coefficient).
  void estimate_duals(const QpProblem& qp, SolverResult& result) {
    const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
    result.y.setZero();
    result.z.setZero();
    if (me + mi == 0) return;
    bool any_free = false;
    for (int r = 0; r < mi; ++r) active_[static_cast<std::size_t>(r)] = qp.A.row(r).dot(result.x) >= qp.b(r) - 1e-9;
    for (int i = 0; i < n; ++i) {
      const bool is_free = result.x(i) > qp.lo(i) + 1e-10 && result.x(i) < qp.hi(i) - 1e-10;
      any_free |= is_free;
      const double keep = is_free ? 1.0 : 0.0;
      for (int r = 0; r < me; ++r) B_(i, r) = keep * qp.J(r, i);
      for (int r = 0; r < mi; ++r) B_(i, me + r) = active_[static_cast<std::size_t>(r)] ? -keep * qp.A(r, i) : 0.0;
      rhs_(i) = keep * (qp.W.row(i).dot(result.x) + qp.zeta(i));
    }
    if (!any_free) return;
    // sol = R^-1 Q' rhs on the numerical rank, in place (QR::solve() would allocate a temporary).
    qr_.compute(B_);
    const Eigen::Index rank = qr_.rank();
    // Q' rhs = H_{p-1} ... H_0 rhs with H_k = I - tau_k v_k v_k', v_k = [1; essential part stored below R's diagonal].
    const Eigen::MatrixXd& qr = qr_.matrixQR();
    for (Eigen::Index k = 0; k < qr_.nonzeroPivots(); ++k) {
      const Eigen::Index tail = n - k - 1;
      const double vtr = rhs_(k) + qr.col(k).tail(tail).dot(rhs_.tail(tail));
      const double scale = qr_.hCoeffs()(k) * vtr;
      rhs_(k) -= scale;
      rhs_.tail(tail) -= scale * qr.col(k).tail(tail);
    }
    qr.topLeftCorner(rank, rank).triangularView<Eigen::Upper>().solveInPlace(rhs_.head(rank));
    sol_.setZero();
    for (Eigen::Index k = 0; k < rank; ++k) sol_(qr_.colsPermutation().indices()(k)) = rhs_(k);
    result.y = sol_.head(me);
    for (int r = 0; r < mi; ++r) {
      if (active_[static_cast<std::size_t>(r)]) result.z(r) = std::max(0.0, sol_(me + r));
    }
  }

  nlopt_opt opt_ = nullptr;
  const QpProblem* qp_ = nullptr;
  int evaluations_ = 0;
  std::vector<double> tol_eq_, tol_in_;
  Eigen::VectorXd x_;
  bool have_x_ = false;
  Eigen::MatrixXd B_;  // dual estimate: n x (m_e + m_i)
  Eigen::VectorXd rhs_, sol_;
  std::vector<char> active_;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr_;
};

const bool kNloptRegistered = engine_registry().add<NloptConfig>(
    "nlopt", "NLopt SLSQP on the QP (independent cross-check; NLopt allocates its work array per solve)",
    [](const NloptConfig& /*config*/, const SolverSettings& s) -> std::unique_ptr<LviEngine> {
      return std::make_unique<NloptSlsqp>(s);
    });

}  // namespace
}  // namespace redres

/// `newton`'s fallback (newton.cpp). A step that neither path settles is first checked: rows that cannot be met
/// inside the bounds (LviEngine::rows_unmeetable) make it infeasible at once, since no engine would meet them.
/// Otherwise `projection` gets at most kFallbackIterations iterations: a step it solves names it as the engine that
/// ran; a step it does not solve stays newton's, and its diagnosis says once what both did.

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "newton_internal.hpp"
#include "redres/control/engine_registry.hpp"

namespace redres::newton_internal {

void Newton::setup_fallback(int n, int m_e, int m_i) {
  SolverSettings s = settings();
  s.max_iterations = std::min(s.max_iterations, kFallbackIterations);
  fallback_ = make_engine("projection", s);
  fallback_->set_diagnoses(false);  // newton diagnoses the step once, naming both
  fallback_result_.x.resize(0);
  fallback_->setup(n, m_e, m_i, fallback_result_);
}

void Newton::run_fallback(const QpProblem& qp, SolverResult& result, int newton_iterations, double newton_residual,
                          const Eigen::Ref<const Eigen::VectorXd>& x) {
  result.info.iterations = newton_iterations;
  result.info.residual = newton_residual;
  result.x = x;
  result.z.setZero();
  result.y.setZero();
  // The general path keeps no residual of its own: the LVI residual of the answer handed back.
  if (!std::isfinite(newton_residual))
    newton_residual = result.info.residual = lvi_residual(qp, result, settings().varpi);
  if (rows_unmeetable(qp)) {
    // The rows cannot be met: projection's iterations would be spent for nothing. diagnose_failure names the rows.
    result.info.status = SolverStatus::kInfeasible;
    return;
  }
  fallback_->solve_valid(qp, fallback_result_);
  const SolverInfo& fb = fallback_result_.info;
  if (fb.status == SolverStatus::kSolved) {
    result.x = fallback_result_.x;
    result.y = fallback_result_.y;
    result.z = fallback_result_.z;
    result.info.status = SolverStatus::kSolved;
    result.info.iterations = newton_iterations + fb.iterations;
    result.info.residual = fb.residual;
    result.info.engine = fb.engine;  // names "projection" as the engine that solved the step
    result.info.diagnosis.clear();
    y_ = result.y;
    return;
  }
  // Projection stopped short (its iteration cap, or an answer the certificate refused): its answer, on a W whose
  // smallest eigenvalues leave it far from the optimum in x, usually has the right active set, and the exact step
  // from it lands (polish()).
  const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
  set_omega(qp);
  set_norms(qp);
  u_.head(n) = fallback_result_.x;  // its duals were cleared with its failure: the first exact step restores them
  u_.segment(n, me) = fallback_result_.y;
  u_.tail(mi) = fallback_result_.z;
  double e2 = natural_residual2(qp, u_);
  if (std::sqrt(e2) <= target_at(u_) || polish(qp, e2)) {
    result.x = u_.head(n).cwiseMax(qp.lo).cwiseMin(qp.hi);
    result.y = u_.segment(n, me);
    result.z = u_.tail(mi);
    result.info.status = SolverStatus::kSolved;
    result.info.iterations = newton_iterations + fb.iterations;
    result.info.residual = std::sqrt(e2);
    result.info.diagnosis.clear();
    y_ = result.y;
    return;
  }
  // Neither solved it: the step stays newton's, with the better of the two answers.
  if (fb.residual < newton_residual) {
    result.x = fallback_result_.x;
    result.info.residual = fb.residual;
  }
  result.info.status = fb.status;
  result.info.iterations = newton_iterations + fb.iterations;
  keep_diagnosis_capacity(result.info.diagnosis);
  TextSink(result.info.diagnosis) << "; projection, its fallback, then stopped after " << fb.iterations
                                  << " iterations with residual " << fb.residual;
}

}  // namespace redres::newton_internal

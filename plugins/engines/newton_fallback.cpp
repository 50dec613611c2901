/// `newton`'s fallback (newton.cpp): a step that neither path settles is solved by `projection`, which the info
/// then names as the engine that ran.

#include "newton_internal.hpp"

namespace redres::newton_internal {

void Newton::run_fallback(const QpProblem& qp, SolverResult& result) {
  fallback_->solve(qp, fallback_result_);
  result.x = fallback_result_.x;
  result.y = fallback_result_.y;
  result.z = fallback_result_.z;
  // Field by field, so that result.info.diagnosis keeps the capacity reserved at setup (no allocation).
  const SolverInfo& fb = fallback_result_.info;
  result.info.status = fb.status;
  result.info.iterations = fb.iterations;
  result.info.residual = fb.residual;
  result.info.engine = fb.engine;  // names "projection" as the engine that ran
  if (!fb.diagnosis.empty()) result.info.diagnosis = fb.diagnosis;
  y_ = result.y;
}

}  // namespace redres::newton_internal

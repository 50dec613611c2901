#include "redres/control/failure_policy.hpp"

#include <stdexcept>
#include <string>

#include "redres/config/config.hpp"
#include "redres/control/engine_registry.hpp"

namespace redres {

FailurePolicy failure_policy_from_name(std::string_view name) {
  for (const auto& [policy, n] : enum_names(FailurePolicy{})) {
    if (n == name) return policy;
  }
  throw std::invalid_argument("expected a failure policy, one of " + config_io::enum_choices<FailurePolicy>() +
                              ", got '" + std::string(name) + "'");
}

std::string_view failure_policy_name(FailurePolicy policy) { return config_io::enum_name(policy); }

void ElasticFallback::setup(const QpProblem& qp, const LviEngine& like) {
  engine_ = make_engine(std::string(like.name()), like.settings());
  elastic_.setup(qp);
  engine_->setup(qp.n(), 0, qp.m_in(), result_);
  miss_.resize(qp.m_eq());
}

const SolverResult& ElasticFallback::solve(const QpProblem& qp, double rho) {
  elastic_.build(qp, rho);
  engine_->solve_valid(elastic_.problem(), result_);
  row_miss_ = 0.0;
  if (result_.info.status == SolverStatus::kSolved && qp.m_eq() > 0) {
    miss_.noalias() = qp.J * result_.x;  // sized at setup(): no temporary
    miss_ -= qp.d;
    row_miss_ = miss_.cwiseAbs().maxCoeff();
  }
  return result_;
}

}  // namespace redres

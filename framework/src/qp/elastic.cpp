#include "redres/qp/elastic.hpp"

namespace redres {

void ElasticQp::setup(const QpProblem& qp) {
  elastic_.resize(qp.n(), 0, qp.m_in());
  elastic_.source_names = qp.source_names;
  elastic_.variable_names = qp.variable_names;
  elastic_.in_row_description = qp.in_row_description;  // once: a copy of a std::function may allocate
}

void ElasticQp::build(const QpProblem& qp, double rho) {
  REDRES_REQUIRE(qp.n() == elastic_.n() && qp.m_in() == elastic_.m_in(), "ElasticQp::build",
                 "qp has the sizes given to setup()");
  elastic_.W = qp.W;
  elastic_.W.noalias() += rho * qp.J.transpose() * qp.J;
  elastic_.w_diagonal = qp.m_eq() == 0 && qp.w_diagonal;
  elastic_.zeta = qp.zeta;
  elastic_.zeta.noalias() -= rho * qp.J.transpose() * qp.d;
  elastic_.A = qp.A;
  elastic_.b = qp.b;
  elastic_.lo = qp.lo;
  elastic_.hi = qp.hi;
  elastic_.lo_source = qp.lo_source;
  elastic_.hi_source = qp.hi_source;
  elastic_.in_source = qp.in_source;
}

}  // namespace redres

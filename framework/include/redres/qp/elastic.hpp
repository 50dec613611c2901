#pragma once
/// @file
/// The elastic QP of a QP whose equality rows cannot be met (the `relax` policy): the same objective plus
/// (rho / 2) |J x - d|^2, without the equality rows, and with every bound and inequality row kept, so that the
/// answer yields on the rows inside every limit:
///   minimise x'(W + rho J'J)x/2 + (zeta - rho J'd)'x   subject to   A x <= b,   lo <= x <= hi.

#include "redres/qp/qp.hpp"

namespace redres {

/// An elastic QP, made from a QP of fixed sizes.
class ElasticQp {
 public:
  /// Sizes it for `qp` (n, no equality rows, m_i inequality rows) and copies the names (allocates).
  void setup(const QpProblem& qp);
  /// Makes it from `qp` with weight rho > 0 (allocation-free; `qp` has the sizes given to setup()).
  void build(const QpProblem& qp, double rho);
  /// The elastic QP.
  [[nodiscard]] const QpProblem& problem() const noexcept { return elastic_; }

 private:
  QpProblem elastic_;
};

}  // namespace redres

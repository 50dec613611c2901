#pragma once
/// @file
/// The best fit of a QP's constraint rows inside its bounds (bounded least squares): the test behind the engines'
/// `infeasible` and the failure diagnosis (LviEngine).

#include <Eigen/Core>

#include "redres/qp/qp.hpp"

namespace redres {

/// The best the constraint rows can be met inside the bounds: an x in [lo, hi] that minimises
/// |J x - d|^2 + |(A x - b)+|^2, found by an active-set bounded least-squares method (exact, up to rounding, for
/// equality rows alone; for inequality rows an active-set iteration polished by projected gradient steps). The
/// engines' `infeasible` is this test's verdict: the rows miss by more than 10 tolerances at x.
struct RowFit {
  Eigen::VectorXd x;               //!< the fit (n), inside the bounds
  double equality_miss = 0.0;      //!< max_r |J_r x - d_r|
  double inequality_excess = 0.0;  //!< max(0, max_r A_r x - b_r)
};
/// See RowFit. Allocates; meant for diagnoses and tests, not the per-step path.
[[nodiscard]] RowFit best_row_fit(const QpProblem& qp);

}  // namespace redres

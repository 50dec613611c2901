#pragma once
/// @file
/// The certificate behind `solved`: the answer (x, y, z) checked against the QP in the QP's own units, each check
/// against absolute + relative x the size of the data it compares (in the manner of OSQP and ProxQP). Every engine's
/// answer is checked (LviEngine::solve); docs/engines.md says what it guarantees.
///
/// With g = W x + zeta - J'y + A'z (the stationarity residual before the bounds' forces):
/// - primal: the largest of |J x - d|, (A x - b)+, (lo - x)+ and (x - hi)+, against
///   absolute + relative * max(|J x|, |d|, |A x|) (infinity norms);
/// - dual: per joint, g_i where neither bound is active; where x_i is within the primal limit of lo_i only the
///   part of g_i that pushes below it (g_i < 0) counts, at hi_i only g_i > 0, at both nothing; and a negative z_r as
///   z_r |A_r|; against absolute + relative * max(|W x|, |zeta|, |J'y|, |A'z|);
/// - complementarity: the force z_r |A_r| of an inequality row that is not active (b_r - A_r x above the primal
///   limit), against the dual limit.

#include "redres/qp/qp.hpp"
#include "redres/qp/solver_status.hpp"

namespace redres {

struct SolverResult;

/// What the certificate measured, and where. Infinity norms.
struct Certificate {
  double primal = 0.0;           //!< the rows' and bounds' largest miss (the rows' units)
  double dual = 0.0;             //!< the largest stationarity residual (the objective's gradient units)
  double complementarity = 0.0;  //!< the largest force of an inequality row that is not active
  double primal_limit = 0.0;     //!< absolute + relative * the rows' scale
  double dual_limit = 0.0;       //!< absolute + relative * the gradient's scale (complementarity's limit too)
  /// Where the primal miss is: an equality row, an inequality row, a joint's lower or upper bound.
  enum class Where { kNone, kEqualityRow, kInequalityRow, kLowerBound, kUpperBound };
  Where primal_where = Where::kNone;
  int primal_at = -1;           //!< that row's or joint's index
  int dual_at = -1;             //!< the joint (0..n-1), or n + r for inequality row r's negative multiplier
  int complementarity_at = -1;  //!< the inequality row

  /// kSolved when all three hold; otherwise the first that does not (primal, dual, complementarity).
  [[nodiscard]] SolverStatus verdict() const noexcept {
    if (!(primal <= primal_limit)) return SolverStatus::kInaccuratePrimal;
    if (!(dual <= dual_limit)) return SolverStatus::kInaccurateDual;
    if (!(complementarity <= dual_limit)) return SolverStatus::kInaccurateComplementarity;
    return SolverStatus::kSolved;
  }
};

/// Checks `answer` against `qp`. `w_diagonal`: W has nothing off its diagonal (the caller verified it). Allocates
/// nothing.
[[nodiscard]] Certificate certify(const QpProblem& qp, const SolverResult& answer, bool w_diagonal, double absolute,
                                  double relative);

/// Writes which check fails and where, e.g. "dual residual 3.1e-04 > limit 1.0e-06 at joint 3 ('j3')".
void describe(const Certificate& c, const QpProblem& qp, TextSink& out);

/// Whether W has no non-zero entry off its diagonal.
[[nodiscard]] bool off_diagonal_zero(const Eigen::MatrixXd& W) noexcept;

}  // namespace redres

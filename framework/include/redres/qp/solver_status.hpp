#pragma once
/// @file
/// The outcome of one solve (what the LVI engines report and the Context carries of the previous step).

namespace redres {

/// Outcome of one solve.
enum class SolverStatus {
  kSolved,            //!< the engine stopped and its answer passed the certificate (redres/qp/certificate.hpp)
  kMaxIterations,     //!< the iteration cap was reached first
  kInfeasible,        //!< bounds conflict, or J x = d cannot be met inside the bounds
  kNumericalError,    //!< the iteration broke down (e.g. a zero step); see the diagnosis
  kNotRun,            //!< no solve has run yet (recorded codes 0-3 keep their meaning)
  kInvalidProblem,    //!< the step's QP could not be built: a plugin or a velocity-limit law gave a non-finite value
                      //!< there (Controller; the diagnosis names which); nothing was solved
  kRelaxed,           //!< the QP failed, and the elastic QP with the equality rows relaxed into a weighted penalty
                      //!< was solved instead (Controller::set_relaxation); the diagnosis says why and by how much
                      //!< the rows are missed
  kBraked,            //!< the QP (and the elastic QP, where it was tried) failed, and the step decelerated every joint
                      //!< along the previous command within its acceleration (and jerk) limits instead of stopping at
                      //!< once (Controller::set_braking; docs/motion.md); a failed step, but the arm moves
  kInaccuratePrimal,  //!< the engine stopped, but its answer misses a row or a bound by more than the certificate
                      //!< allows (redres/qp/certificate.hpp); the diagnosis says which
  kInaccurateDual,    //!< the answer is not stationary: the objective's gradient is not balanced by the rows and the
                      //!< active bounds within the certificate's limit
  kInaccurateComplementarity,  //!< a row that is not active carries a multiplier above the certificate's limit
};

/// Whether a step with this status has a usable theta_dot: solved, or solved with the rows relaxed.
[[nodiscard]] constexpr bool usable(SolverStatus status) noexcept {
  return status == SolverStatus::kSolved || status == SolverStatus::kRelaxed;
}

/// Whether a step with this status moves the arm: usable(), or braked (its theta_dot is the braking command).
[[nodiscard]] constexpr bool moves(SolverStatus status) noexcept {
  return usable(status) || status == SolverStatus::kBraked;
}

/// "solved", "max_iterations", "infeasible", "numerical_error", "not_run", "invalid_problem", "relaxed", "braked",
/// "inaccurate_primal", "inaccurate_dual", "inaccurate_complementarity".
[[nodiscard]] const char* to_string(SolverStatus status);

}  // namespace redres

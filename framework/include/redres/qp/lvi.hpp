#pragma once
/// @file
/// LVI engines: solve the step's QP through its linear variational inequality (eqs. 13-15, docs/lvi.md).
///
/// With u = [x; y; z] (x = theta_dot, y duals of J x = d, z duals of A x <= b),
///   M = [W -J' A'; J 0 0; -A 0 0],  g = [zeta; -d; b],
///   Omega = {u : [lo; -varpi; 0] <= u <= [hi; varpi; varpi]},
/// u* solves P_Omega(u - (M u + g)) - u = 0 (eq. 14); the stopping test is ||e(u)||_2 <= tolerance with
/// e(u) = u - P_Omega(u - (M u + g)).
///
/// Engines (selected by `engine` in the scenario's [solver] table):
/// - `projection`: the paper's eq. 15, u <- u - (||e||^2 / ||phi||^2) phi with phi = (M' + I) e;
/// - `newton`: semismooth Newton on eq. 14 (exact and fast, with inequality rows and dense W too; see newton.cpp);
/// - `nlopt`: NLopt's SLSQP on the QP itself, an independent cross-check.
///
/// Outcomes are statuses, never exceptions: a bound conflict lo_i > hi_i, or equality rows that cannot be met
/// inside the bounds, is `infeasible` with a diagnosis naming the joint, the bound and the plugins.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "redres/config/config.hpp"
#include "redres/config/toml_reader.hpp"
#include "redres/qp/certificate.hpp"
#include "redres/qp/qp.hpp"
#include "redres/qp/row_fit.hpp"  // RowFit, best_row_fit: the test behind `infeasible`
#include "redres/qp/solver_status.hpp"

namespace redres {

/// Settings shared by every engine (the scenario's [solver] table).
struct SolverSettings {
  double tolerance = 1e-6;  //!< stopping test ||e(u)||_2 <= tolerance (the paper's 1e-6), and the certificate's
                            //!< absolute limit (redres/qp/certificate.hpp)
  double relative_tolerance = 1e-9;  //!< the certificate's relative limit, times the size of the data it compares
  double varpi = 1e6;                //!< bound on the duals standing for infinity (the paper's 1e6)
  int max_iterations = 20000;        //!< iteration cap per solve
  bool warm_start = true;            //!< start from the previous solve's u

  static const Schema<SolverSettings>& schema();
};

// SolverStatus, usable() and to_string(SolverStatus): redres/qp/solver_status.hpp.

/// What a solve reports besides its answer.
struct SolverInfo {
  SolverStatus status = SolverStatus::kNotRun;  //!< outcome
  int iterations = 0;                           //!< iterations of the engine that ran
  double residual = 0.0;                        //!< ||e(u)||_2 at the returned u; for a bound conflict, the
                                                //!< largest lo_i - hi_i (finite, so that summaries stay numbers)
  std::string_view engine;                      //!< the engine that actually ran (a fallback names itself);
                                                //!< compares by value; refers to the engine's static name
  std::string diagnosis;                        //!< empty when solved; otherwise which joint, bound, plugin
  double primal_residual = 0.0;                 //!< the certificate's figures for the returned answer (infinity
  double dual_residual = 0.0;                   //!< norms; redres/qp/certificate.hpp); 0 when no answer was
  double complementarity = 0.0;                 //!< checked (a bound conflict, a QP not built)
};

/// The answer: x = theta_dot and the duals. Sized once by LviEngine::setup.
struct SolverResult {
  Eigen::VectorXd x;  //!< joint velocities (n), inside [lo, hi]
  Eigen::VectorXd y;  //!< duals of J x = d (m_e)
  Eigen::VectorXd z;  //!< duals of A x <= b (m_i), >= 0
  SolverInfo info;    //!< status, iterations, residual
};

/// An LVI engine. setup() sizes everything; solve() then allocates nothing (except the diagnosis text of a
/// failed solve). Exception: `nlopt`, where NLopt's SLSQP mallocs its own work array in every nlopt_optimize().
class LviEngine {
 public:
  LviEngine() = default;
  LviEngine(const LviEngine&) = delete;
  LviEngine& operator=(const LviEngine&) = delete;
  virtual ~LviEngine() = default;

  /// Sizes the engine and `result` for n variables, m_e equality and m_i inequality rows.
  void setup(int n, int m_e, int m_i, SolverResult& result);
  /// Solves `qp` into `result`. Checks sizes and values (throws std::invalid_argument on misuse), reports a
  /// bound conflict as infeasible, runs the engine, and diagnoses a failure. After an infeasible or failed solve
  /// the warm start is reset, so that runaway duals do not slow the next steps down.
  void solve(const QpProblem& qp, SolverResult& result);
  /// solve() for a QP whose values are known to be valid: every entry of W, zeta, J, d, A and b finite, no bound
  /// NaN (what QpProblem::validate() checks), and w_diagonal true only if W has nothing off its diagonal (what
  /// QpBuilder and clear() keep; solve() checks it against W). Scheme::build() gives such a QP: it checks every
  /// entry the plugins wrote, and the entries no plugin writes keep clear()'s zeros. The Controller solves with it,
  /// so that no entry is scanned twice per step. Sizes are still checked.
  void solve_valid(const QpProblem& qp, SolverResult& result);
  /// Forgets the warm start.
  void reset() {
    warm_ = false;
    last_infeasible_ = false;
  }
  /// Engine name ("projection", ...): the registry type, a static string.
  [[nodiscard]] virtual std::string_view name() const = 0;
  /// The settings.
  [[nodiscard]] const SolverSettings& settings() const noexcept { return settings_; }
  /// Replaces the settings; std::invalid_argument naming the key when they break SolverSettings' schema.
  void set_settings(const SolverSettings& s);
  /// Whether a failed solve is diagnosed (the default). An engine that runs another as its fallback turns the
  /// other's off: it diagnoses the step once itself, naming both.
  void set_diagnoses(bool on) noexcept { diagnoses_ = on; }
  /// Whether a failure's diagnosis ends with the equality rows' rank and conditioning (a singular value decomposition
  /// of J; the default). A cascade's level that is solved again in least squares when it fails turns it off: the
  /// text is read only if that fails too, and then describe_singular_rows() adds it.
  void set_singular_values(bool on) noexcept { singular_values_ = on; }
  /// Writes the equality rows' rank and conditioning where they are singular or nearly so (nothing otherwise), as a
  /// failure's diagnosis ends.
  void describe_singular_rows(const QpProblem& qp, TextSink& out);
  /// Whether the rows of `qp` cannot be met inside its bounds at the settings' tolerance: the best fit of the rows
  /// inside the bounds (best_row_fit) misses them by more than the tolerance in 2-norm (the equality rows' misses
  /// and the inequality rows' excesses), as the LVI residual measures them. The one decision behind every
  /// `infeasible` status. For failed solves only; the fit allocates nothing (a RowFitter sized by setup()).
  [[nodiscard]] bool rows_unmeetable(const QpProblem& qp);
  /// The best fit of qp's rows inside its bounds (RowFitter; allocation-free), valid until the next fit: a point of
  /// the feasible set when the rows can be met.
  [[nodiscard]] const RowFit& row_fit(const QpProblem& qp) { return fitter_.fit(qp); }

 protected:
  /// Whether `result` holds a previous solution to start from.
  [[nodiscard]] bool warm() const noexcept { return warm_ && settings_.warm_start; }
  /// Whether the QP being solved has nothing off W's diagonal: QpProblem::w_diagonal, verified against W by
  /// solve() (a QP filled by hand may leave the flag as it was). Engines read this, never the flag.
  [[nodiscard]] bool w_diagonal() const noexcept { return w_diagonal_; }
  /// The certificate of `result` against `qp` at the settings' limits (an engine may check an iterate before it
  /// stops; solve() checks every answer).
  [[nodiscard]] Certificate certify(const QpProblem& qp, const SolverResult& result) const {
    return redres::certify(qp, result, w_diagonal_, settings_.tolerance, settings_.relative_tolerance);
  }

 private:
  virtual void do_setup(int n, int m_e, int m_i) = 0;
  /// Runs the engine. `result` holds the previous u when warm(). Must set status, iterations and residual (solve()
  /// names the engine before; a fallback that runs another engine names that one).
  virtual void do_solve(const QpProblem& qp, SolverResult& result) = 0;
  void check_sizes(const QpProblem& qp, const SolverResult& result) const;
  void run(const QpProblem& qp, SolverResult& result);  // solve() after its checks
  // The status and the diagnosis of a failed solve, from one decision (the row fit); runs only after a failure.
  void diagnose_failure(const QpProblem& qp, bool capped, SolverInfo& info);
  // The same with the rows' best fit at hand (fitter_.fit(qp)'s).
  void diagnose_failure(const QpProblem& qp, bool capped, SolverInfo& info, const RowFit& fit);

  SolverSettings settings_;
  bool warm_ = false;
  bool last_infeasible_ = false;  // the last solve ended `infeasible`: the next first checks the rows' fit
  bool w_diagonal_ = true;
  bool diagnoses_ = true;
  bool singular_values_ = true;
  int n_ = 0, m_e_ = 0, m_i_ = 0;
  RowFitter fitter_;  // the best fit of the rows inside the bounds, for failed solves
  std::string note_;  // a failed solve's own note, while the diagnosis is written around it (reserved at setup)
};

/// ||e(u)||_2 of the LVI (eq. 14) at u = [x; y; z].
[[nodiscard]] double lvi_residual(const QpProblem& qp, const SolverResult& u, double varpi);

}  // namespace redres

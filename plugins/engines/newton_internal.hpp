#pragma once
/// @file
/// The `newton` engine's class (newton.cpp describes the method), shared by the sources that define its parts.
/// Private to plugins/engines/: a program makes the engine through engine_registry() only, and its public header is
/// redres/engines/newton.hpp.
///
/// | file | part |
/// |---|---|
/// | newton.cpp | setup, the choice of path, the reduced path's driver, the registration |
/// | newton_reduced.cpp | the reduced path's iteration: x(y), F(y), G and the Newton system |
/// | newton_line_search.cpp | the reduced path's exact line search |
/// | newton_kkt.cpp | the general path: M, Omega, the natural map and its exact step |
/// | newton_multipliers.cpp | the general path's method of multipliers |
/// | newton_fallback.cpp | the fallback to projection |

#include <algorithm>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "redres/engines/newton.hpp"

namespace redres::newton_internal {

/// The most iterations `projection` spends on a step newton did not settle and whose rows can be met: a failed step
/// costs at most this on top of newton's own (some 3 ms on a 7-joint arm), not the 20,000 of max_iterations.
inline constexpr int kFallbackIterations = 2000;

// P_[lo, hi](v) for lo <= hi, as min(max(v, lo), hi): the same value as std::clamp, without branches.
inline double box(double v, double lo, double hi) { return std::min(std::max(v, lo), hi); }

constexpr int kMaxNewtonIterations = 100;
constexpr int kMaxOuterIterations = 50;   // the general path's method of multipliers
constexpr int kMaxInnerIterations = 100;  // Newton steps per augmented Lagrangian minimisation
constexpr int kMaxPolishSteps = 30;       // exact steps from the fallback's answer (polish())

class Newton final : public LviEngine {
 public:
  explicit Newton(const SolverSettings& s) { set_settings(s); }
  std::string_view name() const override { return "newton"; }

 private:
  enum class Reduced { kConverged, kInfeasible, kStalled };

  // newton.cpp
  void do_setup(int n, int m_e, int m_i) override;
  static bool slack_rows_only(const QpProblem& qp);
  void do_solve(const QpProblem& qp, SolverResult& result) override;
  template <int kRows>
  void run(const QpProblem& qp, SolverResult& result);
  void finish(SolverResult& result, SolverStatus status, int iterations, double f2) const;

  // Number of rows: fixed at compile time for planar position tasks (kRows = 2), else m_e.
  template <int kRows>
  static int rows(const QpProblem& qp) {
    return kRows > 0 ? kRows : qp.m_eq();
  }

  // newton_reduced.cpp (reduced_iterate instantiated for kRows = 0 and 2)
  template <int kRows>
  double evaluate(const QpProblem& qp);
  template <int kRows>
  bool solve_newton_system(const QpProblem& qp, double prox);
  template <int kRows>
  Reduced reduced_iterate(const QpProblem& qp, int& k, double& f2);

  // newton_line_search.cpp (exact_step instantiated for kRows = 0 and 2)
  template <int kRows>
  double exact_step(const QpProblem& qp);

  // newton_fallback.cpp
  void setup_fallback(int n, int m_e, int m_i);
  // newton stopped after `iterations` at `x` with `residual` (result.info.diagnosis says why).
  void run_fallback(const QpProblem& qp, SolverResult& result, int iterations, double residual,
                    const Eigen::Ref<const Eigen::VectorXd>& x);

  // newton_kkt.cpp
  bool general_solve(const QpProblem& qp, SolverResult& result);
  void set_omega(const QpProblem& qp);
  void set_norms(const QpProblem& qp);
  double target_at(const Eigen::VectorXd& w) const;
  bool exact_step_lands(const QpProblem& qp, double& e2);
  // A QP whose only constraints are the bounds (rows slack or none), by the primal active-set method.
  bool box_solve(const QpProblem& qp, SolverResult& result);
  // Exact steps from u_ (e2 its residual) while each lowers the residual, until one lands.
  bool polish(const QpProblem& qp, double& e2);
  double natural_residual2(const QpProblem& qp, const Eigen::VectorXd& w);
  void apply_m(const QpProblem& qp, const Eigen::VectorXd& w, Eigen::VectorXd& out) const;

  // newton_multipliers.cpp
  double excess(int r, double s) const;
  bool augmented_lagrangian(const QpProblem& qp, int& iterations);
  bool minimise_augmented_lagrangian(const QpProblem& qp, int& iterations);

  double full_scale_ = 0.0;
  Eigen::VectorXd v_, x_, y_, F_, delta_, row_scale_, jtd_, dv_, inv_w_, w_diag_, x1_, v1_, F1_;
  bool full_step_ready_ = false;
  std::vector<char> free_;
  std::vector<std::pair<double, double>> events_;  // the line search's breakpoints: (s, change of slope)
  Eigen::MatrixXd G_, L_;
  // The general path: u = [x; y; z], the natural map's pieces (M u + g, e), Omega's bounds, the exact step du and
  // its right-hand side; the exact step's free joints and free duals by index, B' (free joints x free duals),
  // W_FF^-1 B', W_FF's factor, the Schur complement S and its unknowns w, and W_FF^-1 r_x.
  Eigen::VectorXd u_, mu_, e_, rhs_, du_, lo_u_, hi_u_;
  Eigen::VectorXd trial_;
  double trial_e2_ = 0.0;
  Eigen::VectorXd box_x_, box_g_;    // box_solve(): x and the gradient W x + zeta
  std::vector<signed char> box_at_;  // box_solve(): -1 at lo, +1 at hi, 0 free  // the residual of exact_step_lands()'s
                                     // last trial (infinity when it made none)
  std::vector<int> free_x_, free_w_;
  Eigen::MatrixXd bt_, yt_, wff_, s_kkt_;
  Eigen::VectorXd w_, h_;
  // The method of multipliers: rows C (as C'), their intervals, penalties, multipliers, s = C x + lambda / rho, C dx;
  // x, the gradient, the Newton step and the Hessian of the augmented Lagrangian, and its Cholesky factor.
  Eigen::MatrixXd Ct_;  // the rows c_r as columns
  Eigen::VectorXd row_lo_, row_hi_, rho_, lambda_, s_, delta_r_, xa_, ga_, dxa_, wx_, wdx_;
  std::vector<double> breaks_ab_;
  double rho_scale_ = 1.0;
  double norm_w_ = 0.0, norm_j_ = 0.0, norm_jt_ = 0.0, norm_a_ = 0.0, norm_at_ = 0.0, data_scale_ = 0.0;
  Eigen::MatrixXd ha_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  std::unique_ptr<LviEngine> fallback_;
  SolverResult fallback_result_;
};

}  // namespace redres::newton_internal

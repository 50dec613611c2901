#pragma once
// QP helpers for the engine tests: random QPs feasible by construction, an independent KKT check, and the
// paper's step QP built from plugins.

#include <memory>
#include <random>
#include <string>

#include "redres/control/scheme.hpp"
#include "redres/qp/lvi.hpp"

namespace redres::testing {

/// A QP with a known feasible point.
struct RandomQp {
  QpProblem qp;
  Eigen::VectorXd feasible;  //!< satisfies every constraint
};

/// A random QP, feasible by construction: random J (orthonormal rows scaled by [0.5, 1.5], so conditioned like a
/// Jacobian away from singularity), W diagonal in [0.5, 2] (or dense SPD with eigenvalues >= 0.5 if `dense_w`),
/// bounds around a known feasible x (about a third of them narrow, so bounds are often active), optional
/// inequality rows.
RandomQp random_qp(std::mt19937& rng, int n, int m_e, int m_i, bool dense_w = false);

/// Independent KKT residual of (x, y, z) for `qp`, written from the KKT conditions (not from the LVI): the largest
/// of the equality violation, the bound violation, |min(z_k, b_k - A_k x)| (signs and complementarity of the
/// inequality rows) and the stationarity error |x - P_[lo,hi](x - (W x + zeta - J'y + A'z))| (box multipliers
/// eliminated).
double kkt_residual(const QpProblem& qp, const SolverResult& r);

/// x'Wx/2 + zeta'x.
double qp_objective(const QpProblem& qp, const Eigen::VectorXd& x);

/// The paper's robot and scheme (TVCMM: min_velocity_norm + manipulability sine p = 2, task_tracking K = 8,
/// joint_angle_margin kappa = 4, margin 0.0349, joint_velocity_limits).
struct PaperStep {
  std::unique_ptr<RobotModel> robot;
  std::unique_ptr<Scheme> scheme;
  SchemeData data;  // the plugins' data
  std::unique_ptr<KinematicsData> kin;
  Eigen::VectorXd r_d, r_d_dot;
  QpProblem qp;
  Context ctx;

  /// Builds the QP at theta, time t (T = 40 s), desired velocity r_d_dot and position offset dr from f(theta).
  void build(const Eigen::VectorXd& theta, double t, const Eigen::Vector2d& rd_dot, const Eigen::Vector2d& dr);
};

/// One QP of the paper-like family: the paper's arm and TVCMM scheme at a random configuration inside the safety
/// region, a random time, a random desired end-effector velocity of up to `speed` m/s and a position error of up to
/// 1 mm. With speed = 0.6 m/s, bounds are active at the solution in about 30 % of the feasible problems (and about
/// 15 % of the problems are infeasible: the velocity limits cannot deliver the speed).
void paper_family_qp(std::mt19937& rng, PaperStep& step, double speed = 0.6);

/// Loads the paper's arm and scheme from TOML text (`scheme_toml` holds [[objectives]] and [[constraints]]).
std::unique_ptr<PaperStep> make_paper_step(const std::string& scheme_toml = "");

/// The TVCMM scheme text.
extern const char* const kPaperSchemeToml;

}  // namespace redres::testing

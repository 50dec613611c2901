#pragma once
/// @file
/// The best fit of a QP's constraint rows inside its bounds (bounded least squares): the test behind the engines'
/// `infeasible` and the failure diagnosis (LviEngine).

#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "redres/qp/qp.hpp"

namespace redres {

/// The best the constraint rows can be met inside the bounds: an x in [lo, hi] that minimises
/// |J x - d|^2 + |(A x - b)+|^2, found by an active-set bounded least-squares method (exact, up to rounding, for
/// equality rows alone; for inequality rows an active-set iteration polished by projected gradient steps). The
/// engines' `infeasible` is this test's verdict: the rows miss by more than the tolerance at x.
struct RowFit {
  Eigen::VectorXd x;               //!< the fit (n), inside the bounds
  double equality_miss = 0.0;      //!< max_r |J_r x - d_r|
  double inequality_excess = 0.0;  //!< max(0, max_r A_r x - b_r)
  Eigen::VectorXd misses;          //!< J x - d (m_e)
  Eigen::VectorXd excesses;        //!< max(0, A x - b) (m_i)
  /// The misses and excesses as the LVI residual measures them, in 2-norm. An engine stops when ||e(u)||_2 <=
  /// tolerance, which needs the rows met to about that, so rows whose best fit misses by more cannot be solved at
  /// the tolerance: the rule for `infeasible`.
  [[nodiscard]] double miss_norm() const { return std::sqrt(misses.squaredNorm() + excesses.squaredNorm()); }
};

/// Computes RowFit for QPs of one size, allocating nothing after setup(): every matrix, decomposition and list is
/// sized there. The least-squares problems of the active-set passes keep the full size m_e + m_i by n, with the
/// columns of the variables at a bound and the rows not in the pass set to zero (their minimum-norm solution is the
/// smaller problem's), so that the decompositions never change size.
class RowFitter {
 public:
  RowFitter() = default;
  /// Sizes everything for n variables, m_e equality and m_i inequality rows.
  void setup(int n, int m_e, int m_i);
  /// The fit of qp's rows inside its bounds (qp has the sizes given to setup(); std::invalid_argument otherwise).
  /// The reference stays valid until the next fit().
  const RowFit& fit(const QpProblem& qp);
  /// The singular values of qp's equality rows J (largest first), for the diagnosis of a singular configuration.
  const Eigen::VectorXd& equality_singular_values(const QpProblem& qp);

 private:
  void bounded_least_squares(const QpProblem& qp, int rows, Eigen::VectorXd& x);
  void min_norm_solve();  // z_ = the minimum-norm least-squares solution of cf_ z = r_ (from cod_)
  double value(const QpProblem& qp, const Eigen::VectorXd& x);

  int n_ = 0, m_e_ = 0, m_i_ = 0;
  RowFit fit_;
  Eigen::MatrixXd c_, cf_;  // the pass's rows (m_e + m_i by n), and those with the free columns only
  Eigen::VectorXd e_, r_, z_, c_work_, permuted_, g_, res_, target_, best_, trial_;
  Eigen::VectorXd eq_, in_, viol_, grad_, next_;
  Eigen::VectorXd householder_work_;
  Eigen::MatrixXd stacked_;
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod_;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd_, svd_j_;
  std::vector<char> state_;
  std::vector<int> releases_, active_;
};

/// See RowFit: a RowFitter set up for qp's sizes, once. Allocates; for tests and one-off diagnoses.
[[nodiscard]] RowFit best_row_fit(const QpProblem& qp);

}  // namespace redres

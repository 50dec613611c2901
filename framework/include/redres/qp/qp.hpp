#pragma once
/// @file
/// The quadratic program built at every control step (eqs. 10-12, docs/lvi.md), with x = theta_dot in R^n:
///
///   minimise   x'Wx/2 + zeta'x
///   subject to J x = d          (m_e equality rows, e.g. the end-effector task, eq. 11)
///              A x <= b         (m_i inequality rows)
///              lo <= x <= hi    (eq. 12: lo_i = max of all lower bounds, hi_i = min of all upper bounds)
///
/// Every buffer is sized once (QpProblem::resize); building and solving allocate nothing afterwards. Each bound
/// remembers which source (plugin) set it, so a conflict lo_i > hi_i names the plugins that caused it.

#include <functional>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "redres/common/error.hpp"
#include "redres/common/text_sink.hpp"

namespace redres {

/// Value standing for "no bound" on a joint velocity before any constraint tightens it.
inline constexpr double kNoBound = std::numeric_limits<double>::infinity();

/// One QP (eqs. 10-12 plus inequality rows). Sized once; then filled each step.
struct QpProblem {
  Eigen::MatrixXd W;                        //!< Hessian (n x n), symmetric positive definite
  Eigen::VectorXd zeta;                     //!< linear term (n)
  Eigen::MatrixXd J;                        //!< equality rows (m_e x n)
  Eigen::VectorXd d;                        //!< equality right-hand side (m_e)
  Eigen::MatrixXd A;                        //!< inequality rows (m_i x n)
  Eigen::VectorXd b;                        //!< inequality right-hand side (m_i)
  Eigen::VectorXd lo;                       //!< lower bounds (n); -inf where unbounded
  Eigen::VectorXd hi;                       //!< upper bounds (n); +inf where unbounded
  bool w_diagonal = true;                   //!< true while only diagonal terms were added to W (then every
                                            //!< entry off W's diagonal is zero: engines and clear() rely on it)
  std::vector<int> lo_source;               //!< index of the source that set lo_i; meaningful where lo_i is
                                            //!< finite (clear() opens the bounds and leaves these alone)
  std::vector<int> hi_source;               //!< the same for hi_i
  std::vector<std::string> source_names;    //!< names of the bound and row sources, indexed as above
  std::vector<std::string> variable_names;  //!< joint names, for diagnoses (may be empty)
  std::vector<int> eq_source;               //!< source of each equality row
  std::vector<int> in_source;               //!< source of each inequality row
  /// Writes what inequality row r stands for at the last build (e.g. "link 'j3' shape 1 vs obstacle 2 at 0.012 m"),
  /// for diagnoses; may write nothing. Called only when a solve fails, into the diagnosis's reserved storage.
  std::function<void(int, TextSink&)> in_row_description;

  /// Sizes every buffer: n variables, m_e equality rows, m_i inequality rows.
  void resize(int n, int m_e, int m_i);
  /// Number of variables n.
  [[nodiscard]] int n() const noexcept { return static_cast<int>(zeta.size()); }
  /// Number of equality rows m_e.
  [[nodiscard]] int m_eq() const noexcept { return static_cast<int>(d.size()); }
  /// Number of inequality rows m_i.
  [[nodiscard]] int m_in() const noexcept { return static_cast<int>(b.size()); }
  /// Zeroes W, zeta, rows, and opens the bounds (-inf, +inf): an infinite bound has no source.
  void clear();
  /// Throws std::invalid_argument naming the first wrong size or non-finite entry (NaN in a bound too).
  void validate() const;
};

/// The conflict lo_i > hi_i of the first such joint, or index -1 when the box is consistent.
struct BoundConflict {
  int joint = -1;              //!< 0-based joint index, -1 if none
  double lo = 0.0;             //!< the merged lower bound
  double hi = 0.0;             //!< the merged upper bound
  std::string_view lo_source;  //!< plugin that set lo (a name held by the QP)
  std::string_view hi_source;  //!< plugin that set hi (a name held by the QP)
};

/// Finds the first joint whose merged bounds conflict (lo_i > hi_i).
[[nodiscard]] BoundConflict find_bound_conflict(const QpProblem& qp);

/// "joint 3 ('j3'): lower bound 0.2 (from 'joint_angle_margin') > upper bound 0.1 (from
/// 'joint_velocity_limits')".
[[nodiscard]] std::string describe(const BoundConflict& conflict, const std::vector<std::string>& joint_names = {});
/// The same, written into `out` (allocation-free).
void describe(const BoundConflict& conflict, const std::vector<std::string>& joint_names, TextSink& out);

/// The name of source `s` of `qp` ("(none)" when unset).
[[nodiscard]] std::string_view source_name(const QpProblem& qp, int s);

}  // namespace redres

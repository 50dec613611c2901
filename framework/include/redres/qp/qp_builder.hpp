#pragma once
/// @file
/// QpBuilder: how a plugin writes its terms, rows and bounds into the step's QP. The framework positions it on the
/// plugin's rows (and, for objectives, its weight) before each contribution.

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "redres/qp/qp.hpp"

namespace redres {

/// Writes one plugin's contributions into the QP. The framework positions it on the plugin's rows and weight.
class QpBuilder {
 public:
  /// Builds into `qp`, which must be sized.
  explicit QpBuilder(QpProblem& qp) : qp_(&qp) {}

  /// W += weight * scale * I.
  void add_identity(double scale = 1.0) {
    const double add = weight_ * scale;
    const Eigen::Index n = qp_->W.rows();
    double* W = qp_->W.data();
    for (Eigen::Index i = 0; i < n; ++i) W[i * (n + 1)] += add;
    wrote_w(WrittenW::kDiagonal);
  }
  /// W_ii += weight * scale for the first `count` variables (e.g. the joints of a QP that has slack variables too).
  void add_identity(double scale, Eigen::Index count) {
    const double add = weight_ * scale;
    const Eigen::Index n = qp_->W.rows();
    if (count < 0 || count > n) bad_size("QpBuilder::add_identity", "0 <= count <= n");
    double* W = qp_->W.data();
    for (Eigen::Index i = 0; i < count; ++i) W[i * (n + 1)] += add;
    wrote_w(WrittenW::kDiagonal);
  }
  /// W_ii = weight * value (a slack variable's own weight, which nothing else writes).
  void set_diagonal(Eigen::Index i, double value) {
    if (i < 0 || i >= qp_->W.rows()) bad_size("QpBuilder::set_diagonal", "0 <= i < n");
    qp_->W(i, i) = weight_ * value;
    wrote_w(WrittenW::kDiagonal);
  }
  /// W += weight * diag(diagonal).
  void add_diagonal(const Eigen::Ref<const Eigen::VectorXd>& diagonal);
  /// W += weight * H (H symmetric); marks W as non-diagonal when H has off-diagonal entries.
  void add_hessian(const Eigen::Ref<const Eigen::MatrixXd>& H);
  /// A least squares (w / 2) |J x - d|^2 (J: k x m, on the first m <= n variables): W += weight * w * J'J,
  /// zeta -= weight * w * J'd. Allocation-free.
  void add_least_squares(const Eigen::Ref<const Eigen::MatrixXd>& J, const Eigen::Ref<const Eigen::VectorXd>& d,
                         double w);
  /// zeta += weight * z.
  void add_linear(const Eigen::Ref<const Eigen::VectorXd>& z) {
    const Eigen::Index n = qp_->zeta.size();
    if (z.size() != n) bad_size("QpBuilder::add_linear", "z.size() == n");
    double* zeta = qp_->zeta.data();
    const double* v = z.data();
    for (Eigen::Index i = 0; i < n; ++i) zeta[i] += weight_ * v[i];
    wrote_zeta_ = true;
  }
  /// zeta += weight * (scale * z), without a scratch vector for scale * z.
  void add_linear(double scale, const Eigen::Ref<const Eigen::VectorXd>& z) {
    const Eigen::Index n = qp_->zeta.size();
    if (z.size() != n) bad_size("QpBuilder::add_linear", "z.size() == n");
    double* zeta = qp_->zeta.data();
    const double* v = z.data();
    for (Eigen::Index i = 0; i < n; ++i) zeta[i] += weight_ * (scale * v[i]);
    wrote_zeta_ = true;
  }
  /// This plugin's equality rows of J (rows x n) and d; the plugin overwrites them.
  [[nodiscard]] Eigen::Block<Eigen::MatrixXd> equality_matrix() { return qp_->J.middleRows(eq_offset_, eq_rows_); }
  [[nodiscard]] Eigen::VectorBlock<Eigen::VectorXd> equality_rhs() { return qp_->d.segment(eq_offset_, eq_rows_); }
  /// This plugin's inequality rows of A (rows x n) and b (A x <= b).
  [[nodiscard]] Eigen::Block<Eigen::MatrixXd> inequality_matrix() { return qp_->A.middleRows(in_offset_, in_rows_); }
  [[nodiscard]] Eigen::VectorBlock<Eigen::VectorXd> inequality_rhs() { return qp_->b.segment(in_offset_, in_rows_); }
  /// lo = max(lo, lower), hi = min(hi, upper), entry-wise, remembering this plugin as the source of each change.
  /// Bounds may be infinite; a NaN throws std::invalid_argument naming the joint.
  void intersect_bounds(const Eigen::Ref<const Eigen::VectorXd>& lower,
                        const Eigen::Ref<const Eigen::VectorXd>& upper) {
    const Eigen::Index n = qp_->lo.size();
    if (lower.size() != n || upper.size() != n) {
      bad_size("QpBuilder::intersect_bounds", "lower and upper have n entries");
    }
    const double* a = lower.data();
    const double* b = upper.data();
    double* lo = qp_->lo.data();
    double* hi = qp_->hi.data();
    int* lo_source = qp_->lo_source.data();
    int* hi_source = qp_->hi_source.data();
    bool nan = false;
    for (Eigen::Index i = 0; i < n; ++i) {
      nan |= std::isnan(a[i]) || std::isnan(b[i]);
      if (a[i] > lo[i]) {
        lo[i] = a[i];
        lo_source[i] = source_;
      }
      if (b[i] < hi[i]) {
        hi[i] = b[i];
        hi_source[i] = source_;
      }
    }
    if (nan) {
      for (Eigen::Index i = 0; i < n; ++i) intersect_bound(static_cast<int>(i), a[i], b[i]);  // throws at the first
    }
  }
  /// intersect_bounds() for bounds that yield to those already there: each is first clipped into the current
  /// [lo_i, hi_i] (a lower bound above hi_i becomes hi_i), so that they never conflict. For a constraint whose
  /// yields_bounds() is true; the scheme adds such constraints after the others.
  void yield_bounds(Eigen::Ref<Eigen::VectorXd> lower, Eigen::Ref<Eigen::VectorXd> upper) {
    const Eigen::Index n = qp_->lo.size();
    if (lower.size() != n || upper.size() != n) bad_size("QpBuilder::yield_bounds", "lower and upper have n entries");
    for (Eigen::Index i = 0; i < n; ++i) {
      lower[i] = std::min(lower[i], qp_->hi[i]);  // NaN stays NaN (min returns its first argument): still refused
      upper[i] = std::max(upper[i], qp_->lo[i]);
    }
    intersect_bounds(lower, upper);
  }
  /// The same for one joint.
  void intersect_bound(int joint, double lower, double upper) {
    if (joint < 0 || joint >= qp_->n() || std::isnan(lower) || std::isnan(upper)) bad_bound(joint, lower, upper);
    const auto j = static_cast<std::size_t>(joint);
    if (lower > qp_->lo(joint)) {
      qp_->lo(joint) = lower;
      qp_->lo_source[j] = source_;
    }
    if (upper < qp_->hi(joint)) {
      qp_->hi(joint) = upper;
      qp_->hi_source[j] = source_;
    }
  }
  /// The plugin's weight.
  [[nodiscard]] double weight() const noexcept { return weight_; }
  /// The QP being built (read access).
  [[nodiscard]] const QpProblem& problem() const noexcept { return *qp_; }

  /// Framework use: positions the builder on one plugin.
  void begin(int source, double weight, int eq_offset, int eq_rows, int in_offset, int in_rows) {
    source_ = source;
    weight_ = weight;
    eq_offset_ = eq_offset;
    eq_rows_ = eq_rows;
    in_offset_ = in_offset;
    in_rows_ = in_rows;
    written_w_ = WrittenW::kNone;
    wrote_zeta_ = false;
  }
  /// Framework use: what the plugin positioned by begin() added to W: nothing, its diagonal only, or any entry.
  enum class WrittenW { kNone, kDiagonal, kFull };
  [[nodiscard]] WrittenW written_w() const noexcept { return written_w_; }
  /// Framework use: whether the plugin positioned by begin() added to zeta.
  [[nodiscard]] bool wrote_zeta() const noexcept { return wrote_zeta_; }
  /// Framework use: where the plugin's own rows are (for the checks after its contribution).
  [[nodiscard]] int eq_offset() const noexcept { return eq_offset_; }
  [[nodiscard]] int eq_rows() const noexcept { return eq_rows_; }
  [[nodiscard]] int in_offset() const noexcept { return in_offset_; }
  [[nodiscard]] int in_rows() const noexcept { return in_rows_; }

 private:
  QpProblem* qp_;
  int source_ = -1;
  double weight_ = 1.0;
  int eq_offset_ = 0, eq_rows_ = 0, in_offset_ = 0, in_rows_ = 0;
  WrittenW written_w_ = WrittenW::kNone;
  bool wrote_zeta_ = false;
  void wrote_w(WrittenW w) noexcept { written_w_ = std::max(written_w_, w); }
  [[noreturn]] void bad_bound(int joint, double lower, double upper) const;
  [[noreturn]] static void bad_size(const char* function, const char* condition);
};

}  // namespace redres

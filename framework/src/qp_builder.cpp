#include "redres/qp_builder.hpp"

#include <cmath>
#include <string>

#include "redres/error.hpp"

namespace redres {

void QpBuilder::begin(int source, double weight, int eq_offset, int eq_rows, int in_offset, int in_rows) {
  source_ = source;
  weight_ = weight;
  eq_offset_ = eq_offset;
  eq_rows_ = eq_rows;
  in_offset_ = in_offset;
  in_rows_ = in_rows;
  written_w_ = WrittenW::kNone;
}

void QpBuilder::add_identity(double scale) {
  qp_->W.diagonal().array() += weight_ * scale;
  wrote_w(WrittenW::kDiagonal);
}

void QpBuilder::add_diagonal(const Eigen::Ref<const Eigen::VectorXd>& diagonal) {
  REDRES_REQUIRE(diagonal.size() == qp_->n(), "QpBuilder::add_diagonal", "diagonal.size() == n");
  qp_->W.diagonal() += weight_ * diagonal;
  wrote_w(WrittenW::kDiagonal);
}

void QpBuilder::add_hessian(const Eigen::Ref<const Eigen::MatrixXd>& H) {
  REDRES_REQUIRE(H.rows() == qp_->n() && H.cols() == qp_->n(), "QpBuilder::add_hessian", "H is n x n");
  qp_->W += weight_ * H;
  wrote_w(WrittenW::kFull);
  for (Eigen::Index c = 0; c < H.cols(); ++c) {
    for (Eigen::Index r = 0; r < H.rows(); ++r) {
      if (r != c && H(r, c) != 0.0) qp_->w_diagonal = false;
    }
  }
}

void QpBuilder::add_linear(const Eigen::Ref<const Eigen::VectorXd>& z) {
  REDRES_REQUIRE(z.size() == qp_->n(), "QpBuilder::add_linear", "z.size() == n");
  qp_->zeta += weight_ * z;
}

void QpBuilder::intersect_bound(int joint, double lower, double upper) {
  REDRES_REQUIRE(joint >= 0 && joint < qp_->n(), "QpBuilder::intersect_bound", "0 <= joint < n");
  REDRES_REQUIRE(!std::isnan(lower) && !std::isnan(upper), "QpBuilder::intersect_bound",
                 "bounds of joint " + std::to_string(joint + 1) + " are not NaN");
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

void QpBuilder::intersect_bounds(const Eigen::Ref<const Eigen::VectorXd>& lower,
                                 const Eigen::Ref<const Eigen::VectorXd>& upper) {
  REDRES_REQUIRE(lower.size() == qp_->n() && upper.size() == qp_->n(), "QpBuilder::intersect_bounds",
                 "lower and upper have n entries");
  for (int i = 0; i < qp_->n(); ++i) intersect_bound(i, lower(i), upper(i));
}

}  // namespace redres

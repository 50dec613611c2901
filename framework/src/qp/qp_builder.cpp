#include "redres/qp/qp_builder.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

#include "redres/common/error.hpp"

namespace redres {

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

void QpBuilder::add_least_squares(const Eigen::Ref<const Eigen::MatrixXd>& J,
                                  const Eigen::Ref<const Eigen::VectorXd>& d, double w) {
  const Eigen::Index n = J.cols(), k = J.rows();
  REDRES_REQUIRE(n <= qp_->n() && d.size() == k, "QpBuilder::add_least_squares",
                 "J has at most n columns and d has one entry per row of J");
  const double s = weight_ * w;
  Eigen::MatrixXd& W = qp_->W;
  // Each column's rows from its first to its last non-zero entry: two columns whose spans do not overlap have a zero
  // inner product, so a posture's J = I costs O(n k), not O(n^2 k). The sums run over the overlap in the same order as
  // over every row (the terms left out are exact zeros, except that 0 x inf or 0 x NaN is no longer summed: a
  // non-finite J is refused by the checked build all the same). Up to kSpans columns (a stack array), else every row.
  constexpr Eigen::Index kSpans = 128;
  std::array<std::pair<Eigen::Index, Eigen::Index>, kSpans> span;
  const bool spans = n <= kSpans && J.allFinite();
  if (spans) {
    for (Eigen::Index c = 0; c < n; ++c) {
      Eigen::Index first = k, last = -1;
      for (Eigen::Index i = 0; i < k; ++i) {
        if (J(i, c) != 0.0) {
          first = std::min(first, i);
          last = i;
        }
      }
      span[static_cast<std::size_t>(c)] = {first, last};
    }
  }
  for (Eigen::Index c = 0; c < n; ++c) {
    for (Eigen::Index r = 0; r < n; ++r) {
      Eigen::Index from = 0, to = k - 1;
      if (spans) {
        from = std::max(span[static_cast<std::size_t>(r)].first, span[static_cast<std::size_t>(c)].first);
        to = std::min(span[static_cast<std::size_t>(r)].second, span[static_cast<std::size_t>(c)].second);
        if (from > to) continue;  // a zero inner product: W keeps its entry
      }
      double g = 0.0;
      for (Eigen::Index i = from; i <= to; ++i) g += J(i, r) * J(i, c);
      W(r, c) += s * g;
      if (r != c && g != 0.0) qp_->w_diagonal = false;
    }
    double z = 0.0;
    for (Eigen::Index i = 0; i < k; ++i) z += J(i, c) * d(i);
    qp_->zeta(c) -= s * z;
  }
  wrote_w(WrittenW::kFull);
  wrote_zeta_ = true;
}

void QpBuilder::bad_size(const char* function, const char* condition) { throw_invalid_argument(function, condition); }

void QpBuilder::bad_bound(int joint, double lower, double upper) const {
  REDRES_REQUIRE(joint >= 0 && joint < qp_->n(), "QpBuilder::intersect_bound",
                 "0 <= joint < n (got joint " + std::to_string(joint) + ", n " + std::to_string(qp_->n()) + ")");
  throw_invalid_argument("QpBuilder::intersect_bound", "a bound of joint " + std::to_string(joint + 1) +
                                                           " is NaN (lower " + std::to_string(lower) + ", upper " +
                                                           std::to_string(upper) + ")");
}

}  // namespace redres

// QpBuilder::add_least_squares skips the products of columns whose non-zero rows do not overlap (a posture's J = I):
// W and zeta are those of (w/2) |J x - d|^2 written out by Eigen, and W is marked dense exactly when J'J has a
// non-zero entry off its diagonal, on random J with every sparsity from the identity to dense.

#include <random>

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include "redres/qp/qp_builder.hpp"

namespace redres {
namespace {

RC_GTEST_PROP(QpBuilderProperty, LeastSquaresIsJtJAndJtdWhateverTheSparsity, ()) {
  const int n = *rc::gen::inRange(1, 40), k = *rc::gen::inRange(1, 40);
  std::mt19937 rng(*rc::gen::arbitrary<unsigned>());
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int kind = *rc::gen::inRange(0, 4);  // identity-like, banded, random zeros, dense
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(k, n);
  for (int i = 0; i < k; ++i) {
    for (int c = 0; c < n; ++c) {
      const bool on = kind == 0 ? i == c : kind == 1 ? std::abs(i - c) <= 1 : kind == 2 ? u(rng) > 0.5 : true;
      if (on) J(i, c) = u(rng);
    }
  }
  const Eigen::VectorXd d = Eigen::VectorXd::NullaryExpr(k, [&] { return u(rng); });
  const double weight = 0.5 + u(rng) * 0.25, w = 2.0 + u(rng);
  QpProblem qp;
  qp.resize(n, 0, 0);
  qp.clear();
  Eigen::MatrixXd W0 = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) W0(i, i) = 1.0 + i;  // what an earlier plugin wrote
  qp.W = W0;
  qp.zeta.setConstant(0.25);
  qp.w_diagonal = true;
  QpBuilder builder(qp);
  builder.begin(0, weight, 0, 0, 0, 0);
  builder.add_least_squares(J, d, w);
  const Eigen::MatrixXd gram = J.transpose() * J;
  const Eigen::MatrixXd W = W0 + weight * w * gram;
  const Eigen::VectorXd zeta = Eigen::VectorXd::Constant(n, 0.25) - weight * w * (J.transpose() * d);
  RC_ASSERT((qp.W - W).cwiseAbs().maxCoeff() <= 1e-13);
  RC_ASSERT((qp.zeta - zeta).cwiseAbs().maxCoeff() <= 1e-13);
  const bool off = (gram - Eigen::MatrixXd(gram.diagonal().asDiagonal())).cwiseAbs().maxCoeff() > 0.0;
  RC_ASSERT(qp.w_diagonal == !off);
  RC_CLASSIFY(kind == 0, "identity-like J: W stays diagonal");
}

}  // namespace
}  // namespace redres

#pragma once
// An independent reference for strict task priorities (issue 29): a cascade of NLopt SLSQP problems, one per
// level, each minimising its own tasks' squared residual while every higher level keeps its optimum and every
// hard constraint holds. It shares no code with redres's cascade: the tests hold the framework's levels to it.
//
// Level l minimises  sum ||J_e x - d_e||^2 (its equality and soft tasks) + sum ||max(0, G x - h)||^2 (its
// inequality tasks, G x <= h)  subject to  lo <= x <= hi,  A x <= b,  and for every higher level k: J_k x = J_k x*_k
// (its equality and soft rows, where level k ended) and G_k x <= max(h_k, G_k x*_k) (its inequality rows, at what
// level k reached).

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SVD>
#include <nlopt.hpp>

namespace redres::testing {

struct ReferenceLevel {
  Eigen::MatrixXd J;  // equality and soft rows: J x ~ d
  Eigen::VectorXd d;
  Eigen::MatrixXd G;  // inequality rows: G x <= h
  Eigen::VectorXd h;
};

struct ReferenceProblem {
  Eigen::VectorXd lo, hi;  // bounds on x
  Eigen::MatrixXd A;       // hard inequality rows A x <= b (may have no rows)
  Eigen::VectorXd b;
  std::vector<ReferenceLevel> levels;  // highest priority first
};

struct ReferenceSolution {
  Eigen::VectorXd x;                // after the last level
  std::vector<Eigen::VectorXd> at;  // x after each level
  std::vector<double> residual;     // each level's objective at its optimum
};

namespace detail {

inline double level_objective(unsigned n, const double* x, double* grad, void* data) {
  const auto& L = *static_cast<const ReferenceLevel*>(data);
  const Eigen::Map<const Eigen::VectorXd> v(x, n);
  double f = 0.0;
  Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
  if (L.J.rows() > 0) {
    const Eigen::VectorXd r = L.J * v - L.d;
    f += r.squaredNorm();
    g += 2.0 * L.J.transpose() * r;
  }
  if (L.G.rows() > 0) {
    const Eigen::VectorXd s = (L.G * v - L.h).cwiseMax(0.0);
    f += s.squaredNorm();
    g += 2.0 * L.G.transpose() * s;
  }
  if (grad != nullptr) std::copy(g.data(), g.data() + n, grad);
  return f;
}

// Rows M x - c (<= 0 or = 0) for NLopt's vector constraints.
struct Rows {
  Eigen::MatrixXd M;
  Eigen::VectorXd c;
};

inline void rows_value(unsigned m, double* result, unsigned n, const double* x, double* grad, void* data) {
  const auto& R = *static_cast<const Rows*>(data);
  const Eigen::Map<const Eigen::VectorXd> v(x, n);
  const Eigen::VectorXd r = R.M * v - R.c;
  std::copy(r.data(), r.data() + m, result);
  if (grad != nullptr) {
    for (unsigned i = 0; i < m; ++i) {
      for (unsigned j = 0; j < n; ++j) grad[i * n + j] = R.M(i, j);  // row-major, as NLopt wants it
    }
  }
}

}  // namespace detail

/// Solves the cascade from `x0` (inside the bounds). Throws std::runtime_error when SLSQP fails at a level.
inline ReferenceSolution solve_lexicographic(const ReferenceProblem& p, const Eigen::VectorXd& x0,
                                             double tolerance = 1e-12) {
  const int n = static_cast<int>(x0.size());
  ReferenceSolution out;
  Eigen::VectorXd x = x0.cwiseMax(p.lo).cwiseMin(p.hi);
  std::vector<detail::Rows> held_eq, held_in;  // what the higher levels keep
  for (const ReferenceLevel& level : p.levels) {
    nlopt::opt opt(nlopt::LD_SLSQP, static_cast<unsigned>(n));
    std::vector<double> lo(p.lo.data(), p.lo.data() + n), hi(p.hi.data(), p.hi.data() + n);
    opt.set_lower_bounds(lo);
    opt.set_upper_bounds(hi);
    opt.set_min_objective(detail::level_objective, const_cast<ReferenceLevel*>(&level));
    detail::Rows hard{p.A, p.b};
    const std::vector<double> tol_in(static_cast<std::size_t>(std::max<Eigen::Index>(p.A.rows(), 1)), 1e-12);
    if (p.A.rows() > 0) opt.add_inequality_mconstraint(detail::rows_value, &hard, tol_in);
    for (auto& r : held_eq) {
      opt.add_equality_mconstraint(detail::rows_value, &r,
                                   std::vector<double>(static_cast<std::size_t>(r.M.rows()), 1e-12));
    }
    for (auto& r : held_in) {
      opt.add_inequality_mconstraint(detail::rows_value, &r,
                                     std::vector<double>(static_cast<std::size_t>(r.M.rows()), 1e-12));
    }
    opt.set_ftol_abs(tolerance * tolerance);
    opt.set_xtol_rel(tolerance);
    opt.set_maxeval(20000);
    std::vector<double> v(x.data(), x.data() + n);
    double f = 0.0;
    try {
      (void)opt.optimize(v, f);
    } catch (const nlopt::roundoff_limited&) {
      // the optimum within rounding: accepted
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string("solve_lexicographic: SLSQP failed at level ") +
                               std::to_string(out.at.size()) + ": " + e.what());
    }
    x = Eigen::Map<Eigen::VectorXd>(v.data(), n);
    out.at.push_back(x);
    out.residual.push_back(f);
    if (level.J.rows() > 0) held_eq.push_back({level.J, level.J * x});
    if (level.G.rows() > 0) held_in.push_back({level.G, (level.G * x).cwiseMax(level.h)});
  }
  out.x = x;
  return out;
}

/// The null-space cascade for equality tasks without bounds (the textbook reference where no bound is active):
/// x_1 = J_1^+ d_1, x_k = x_{k-1} + (J_k N_{k-1})^+ (d_k - J_k x_{k-1}), N_k the null space of the stacked J_1..J_k.
inline Eigen::VectorXd null_space_cascade(const std::vector<ReferenceLevel>& levels, int n) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd N = Eigen::MatrixXd::Identity(n, n);
  for (const ReferenceLevel& level : levels) {
    const Eigen::MatrixXd JN = level.J * N;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(JN, Eigen::ComputeFullU | Eigen::ComputeFullV);
    svd.setThreshold(1e-10);
    x += N * svd.solve(level.d - level.J * x);
    // N <- N (I - (J N)^+ (J N))
    const int rank = static_cast<int>(svd.rank());
    const Eigen::MatrixXd V = svd.matrixV().leftCols(rank);
    N = N * (Eigen::MatrixXd::Identity(n, n) - V * V.transpose());
  }
  return x;
}

}  // namespace redres::testing

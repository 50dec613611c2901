#pragma once
// An independent reference for strict task priorities (issue 29): a cascade of NLopt SLSQP problems, one per
// level, each minimising its own tasks' squared residual while every higher level keeps its optimum and every
// hard constraint holds. It shares no code with redres's cascade: the tests hold the framework's levels to it.
//
// Level l minimises  sum ||J_e x - d_e||^2 (its equality and soft tasks) + sum ||max(0, G x - h)||^2 (its
// inequality tasks, G x <= h; written with slack variables s, G x - s <= h, and ||s||^2)  subject to  lo <= x <= hi,  A
// x <= b,  and for every higher level k: J_k x = J_k x*_k (its equality and soft rows, where level k ended; kept as an
// orthonormal basis of their span) and G_k x <= max(h_k, G_k x*_k) (its inequality rows, at what level k reached).

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <nlopt.hpp>
#include <random>

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

// |J x - d|^2 + |s|^2 over v = (x, s): a level's equality and soft rows, and the slacks of its inequality rows.
struct LevelData {
  const ReferenceLevel* level;
  unsigned n;  // the joints; v has n + G.rows() entries
};

inline double level_objective(unsigned nv, const double* v, double* grad, void* data) {
  const auto& D = *static_cast<const LevelData*>(data);
  const ReferenceLevel& L = *D.level;
  const Eigen::Map<const Eigen::VectorXd> x(v, D.n);
  const Eigen::Map<const Eigen::VectorXd> slack(v + D.n, nv - D.n);
  double f = slack.squaredNorm();
  Eigen::VectorXd g = Eigen::VectorXd::Zero(nv);
  g.tail(nv - D.n) = 2.0 * slack;
  if (L.J.rows() > 0) {
    const Eigen::VectorXd r = L.J * x - L.d;
    f += r.squaredNorm();
    g.head(D.n) += 2.0 * L.J.transpose() * r;
  }
  if (grad != nullptr) std::copy(g.data(), g.data() + nv, grad);
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
  Eigen::MatrixXd stacked(0, n);               // every equality and soft row held so far
  // [M, 0]: rows on x alone, widened to v = (x, s).
  const auto widen = [](const detail::Rows& r, int nv) {
    detail::Rows w{Eigen::MatrixXd::Zero(r.M.rows(), nv), r.c};
    w.M.leftCols(r.M.cols()) = r.M;
    return w;
  };
  for (const ReferenceLevel& level : p.levels) {
    // v = (x, s): the level's inequality rows G x - s <= h with s free, and |s|^2 in the objective (a smooth QP,
    // where max(0, G x - h)^2 would not be twice differentiable).
    const int k = static_cast<int>(level.G.rows());
    const int nv = n + k;
    nlopt::opt opt(nlopt::LD_SLSQP, static_cast<unsigned>(nv));
    std::vector<double> lo(static_cast<std::size_t>(nv), -HUGE_VAL), hi(static_cast<std::size_t>(nv), HUGE_VAL);
    std::copy(p.lo.data(), p.lo.data() + n, lo.begin());
    std::copy(p.hi.data(), p.hi.data() + n, hi.begin());
    opt.set_lower_bounds(lo);
    opt.set_upper_bounds(hi);
    detail::LevelData data{&level, static_cast<unsigned>(n)};
    opt.set_min_objective(detail::level_objective, &data);
    std::vector<detail::Rows> rows_in, rows_eq;  // kept alive while NLopt runs
    rows_in.reserve(held_in.size() + 2);
    rows_eq.reserve(held_eq.size());
    if (p.A.rows() > 0) rows_in.push_back(widen({p.A, p.b}, nv));
    if (k > 0) {
      detail::Rows slack{Eigen::MatrixXd::Zero(k, nv), level.h};
      slack.M.leftCols(n) = level.G;
      slack.M.rightCols(k) = -Eigen::MatrixXd::Identity(k, k);
      rows_in.push_back(slack);
    }
    for (const auto& r : held_in) rows_in.push_back(widen(r, nv));
    for (const auto& r : held_eq) rows_eq.push_back(widen(r, nv));
    for (auto& r : rows_in) {
      opt.add_inequality_mconstraint(detail::rows_value, &r,
                                     std::vector<double>(static_cast<std::size_t>(r.M.rows()), 1e-12));
    }
    for (auto& r : rows_eq) {
      opt.add_equality_mconstraint(detail::rows_value, &r,
                                   std::vector<double>(static_cast<std::size_t>(r.M.rows()), 1e-12));
    }
    opt.set_ftol_abs(tolerance * tolerance);
    opt.set_xtol_rel(tolerance);
    opt.set_maxeval(20000);
    // From several starts (the level above's answer, the origin, and points about it): SLSQP may stop short where
    // bounds and held rows meet; the best feasible end is kept.
    std::vector<double> v;
    double f = HUGE_VAL;
    std::string failure = "every end infeasible";
    std::mt19937 rng(static_cast<unsigned>(out.at.size()) * 7919U + 17U);
    std::uniform_real_distribution<double> jitter(-0.5, 0.5);
    for (int start = 0; start < 4; ++start) {
      Eigen::VectorXd x_start = start == 1 ? Eigen::VectorXd::Zero(n) : x;
      if (start >= 2) x_start += Eigen::VectorXd::NullaryExpr(n, [&] { return jitter(rng); });
      x_start = x_start.cwiseMax(p.lo).cwiseMin(p.hi);
      std::vector<double> w(static_cast<std::size_t>(nv), 0.0);
      std::copy(x_start.data(), x_start.data() + n, w.begin());
      if (k > 0) {
        const Eigen::VectorXd s0 = (level.G * x_start - level.h).cwiseMax(0.0);
        std::copy(s0.data(), s0.data() + k, w.begin() + n);
      }
      double fw = 0.0;
      try {
        (void)opt.optimize(w, fw);
      } catch (const nlopt::roundoff_limited&) {
        fw = opt.last_optimum_value();  // the optimum within rounding: accepted
      } catch (const std::exception& e) {
        failure = e.what();
        continue;
      }
      // Feasible: every constraint within 1e-9.
      const Eigen::Map<const Eigen::VectorXd> wv(w.data(), nv);
      double violation = 0.0;
      for (const auto& r : rows_in) violation = std::max(violation, (r.M * wv - r.c).maxCoeff());
      for (const auto& r : rows_eq) violation = std::max(violation, (r.M * wv - r.c).cwiseAbs().maxCoeff());
      if (violation > 1e-9) continue;
      if (fw < f) {
        f = fw;
        v = w;
      }
    }
    if (v.empty()) {
      throw std::runtime_error("solve_lexicographic: SLSQP failed at level " + std::to_string(out.at.size()) +
                               " from every start: " + failure);
    }
    x = Eigen::Map<Eigen::VectorXd>(v.data(), n);
    out.at.push_back(x);
    out.residual.push_back(f);
    if (level.J.rows() > 0) {
      // The rows held so far, as an orthonormal basis of their span (numerical rank): dependent or zero rows
      // (a task whose rows no joint moves) would make SLSQP's equality constraints degenerate.
      stacked.conservativeResize(stacked.rows() + level.J.rows(), n);
      stacked.bottomRows(level.J.rows()) = level.J;
      // The row space: the eigenvectors of J'J (n x n, symmetric) whose eigenvalues are not zero.
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(stacked.transpose() * stacked);
      const Eigen::VectorXd& ev = eig.eigenvalues();  // increasing
      const double top = std::max(ev(n - 1), 1e-300);
      int first = 0;
      while (first < n && ev(first) <= 1e-14 * top) ++first;
      held_eq.clear();
      if (first < n) {
        const Eigen::MatrixXd basis = eig.eigenvectors().rightCols(n - first).transpose();
        held_eq.push_back({basis, basis * x});
      }
    }
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

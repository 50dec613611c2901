#include "redres/qp/lvi.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/QR>
#include <Eigen/SVD>

namespace redres {

const char* to_string(SolverStatus status) {
  switch (status) {
    case SolverStatus::kSolved: return "solved";
    case SolverStatus::kMaxIterations: return "max_iterations";
    case SolverStatus::kInfeasible: return "infeasible";
    case SolverStatus::kNumericalError: return "numerical_error";
    case SolverStatus::kNotRun: return "not_run";
    case SolverStatus::kInvalidProblem: return "invalid_problem";
    case SolverStatus::kRelaxed: return "relaxed";
  }
  return "unknown";
}

double lvi_residual(const QpProblem& qp, const SolverResult& u, double varpi) {
  // Written out entry by entry so that it allocates nothing (engines call it per solve).
  const auto gap = [](double value, double step, double lo, double hi) {
    const double e = value - std::min(std::max(value - step, lo), hi);
    return e * e;
  };
  double e2 = 0.0;
  for (int i = 0; i < qp.n(); ++i) {
    const double rx = qp.W.row(i).dot(u.x) - qp.J.col(i).dot(u.y) + qp.A.col(i).dot(u.z) + qp.zeta(i);
    e2 += gap(u.x(i), rx, qp.lo(i), qp.hi(i));
  }
  for (int r = 0; r < qp.m_eq(); ++r) e2 += gap(u.y(r), qp.J.row(r).dot(u.x) - qp.d(r), -varpi, varpi);
  for (int r = 0; r < qp.m_in(); ++r) e2 += gap(u.z(r), qp.b(r) - qp.A.row(r).dot(u.x), 0.0, varpi);
  return std::sqrt(e2);
}

namespace {

std::string joint_label(const QpProblem& qp, int i) {
  std::string s = "joint " + std::to_string(i + 1);
  if (i < static_cast<int>(qp.variable_names.size()))
    s += " ('" + qp.variable_names[static_cast<std::size_t>(i)] + "')";
  return s;
}

// min 1/2 |C x - e|^2 over lo <= x <= hi (bounds may be infinite), from a feasible x: an active-set method in the
// manner of Stark and Parker's BVLS. Each pass solves the least-squares problem over the free variables (minimum
// norm, so that rank-deficient rows are fine), walks from x towards that solution until a bound stops it, and
// once the free variables' solution lies inside the box frees the bound variable whose gradient most wants it
// inside. Every pass decreases the objective; it ends at a KKT point, or at the pass cap (a feasible x either way).
void bounded_least_squares(const Eigen::MatrixXd& C, const Eigen::VectorXd& e, const Eigen::VectorXd& lo,
                           const Eigen::VectorXd& hi, Eigen::VectorXd& x) {
  const int n = static_cast<int>(C.cols());
  enum : char { kFree, kAtLower, kAtUpper };
  std::vector<char> state(static_cast<std::size_t>(n), kFree);
  for (int i = 0; i < n; ++i) {
    if (x(i) <= lo(i)) state[static_cast<std::size_t>(i)] = kAtLower;
    if (x(i) >= hi(i)) state[static_cast<std::size_t>(i)] = kAtUpper;
  }
  const double scale = std::max(1.0, C.cwiseAbs().maxCoeff() * (e.cwiseAbs().maxCoeff() + 1.0));
  std::vector<int> free;
  std::vector<int> releases(static_cast<std::size_t>(n), 0);  // a variable freed again and again is degenerate
  for (int pass = 0; pass < 20 * n + 100; ++pass) {
    free.clear();
    for (int i = 0; i < n; ++i) {
      if (state[static_cast<std::size_t>(i)] == kFree) free.push_back(i);
    }
    if (!free.empty()) {
      Eigen::VectorXd r = e;
      Eigen::MatrixXd CF(C.rows(), static_cast<Eigen::Index>(free.size()));
      for (int i = 0; i < n; ++i) {
        if (state[static_cast<std::size_t>(i)] != kFree) r -= C.col(i) * x(i);
      }
      for (std::size_t j = 0; j < free.size(); ++j) CF.col(static_cast<Eigen::Index>(j)) = C.col(free[j]);
      const Eigen::VectorXd z = CF.completeOrthogonalDecomposition().solve(r);
      double alpha = 1.0;
      int blocking = -1;  // the variable whose bound stops the step
      bool blocked_low = false;
      for (std::size_t j = 0; j < free.size(); ++j) {
        const int i = free[j];
        const double to = z(static_cast<Eigen::Index>(j)), from = x(i);
        double a = 1.0;
        if (to < lo(i)) a = (lo(i) - from) / (to - from);
        if (to > hi(i)) a = (hi(i) - from) / (to - from);
        if (a < alpha) {
          alpha = std::max(0.0, a);
          blocking = i;
          blocked_low = to < lo(i);
        }
      }
      for (std::size_t j = 0; j < free.size(); ++j) {
        const int i = free[j];
        x(i) = std::clamp(x(i) + alpha * (z(static_cast<Eigen::Index>(j)) - x(i)), lo(i), hi(i));
      }
      if (blocking >= 0) {
        x(blocking) = blocked_low ? lo(blocking) : hi(blocking);
        state[static_cast<std::size_t>(blocking)] = blocked_low ? kAtLower : kAtUpper;
        continue;
      }
    }
    // The free variables are optimal: free the bound variable that most wants to move inside, if any does.
    const Eigen::VectorXd g = C.transpose() * (C * x - e);
    int release = -1;
    double worst = 1e-13 * scale;
    for (int i = 0; i < n; ++i) {
      const char st = state[static_cast<std::size_t>(i)];
      const double want = st == kAtLower ? -g(i) : st == kAtUpper ? g(i) : 0.0;
      if (want > worst && releases[static_cast<std::size_t>(i)] < 3) {
        worst = want;
        release = i;
      }
    }
    if (release < 0) return;
    state[static_cast<std::size_t>(release)] = kFree;
    ++releases[static_cast<std::size_t>(release)];
  }
}

}  // namespace

RowFit best_row_fit(const QpProblem& qp) {
  const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
  RowFit fit;
  fit.x = Eigen::VectorXd::Zero(n).cwiseMax(qp.lo).cwiseMin(qp.hi);
  const auto measure = [&qp](const Eigen::VectorXd& x, double& eq, double& in) {
    eq = qp.m_eq() > 0 ? (qp.J * x - qp.d).cwiseAbs().maxCoeff() : 0.0;
    in = qp.m_in() > 0 ? std::max(0.0, (qp.A * x - qp.b).maxCoeff()) : 0.0;
  };
  // The inequality rows that x violates are taken as rows to meet with equality, x is fitted again by bounded least
  // squares, and the best point on the segment from the old x to the new one is kept: a semismooth Newton method
  // on |J x - d|^2 + |(A x - b)+|^2 with a line search, exact for equality rows alone (one pass). Projected
  // gradient steps then polish the fit with inequality rows.
  const auto value = [&qp, mi](const Eigen::VectorXd& x) {
    return (qp.J * x - qp.d).squaredNorm() + (mi > 0 ? (qp.A * x - qp.b).cwiseMax(0.0).squaredNorm() : 0.0);
  };
  double best_value = value(fit.x);
  for (int outer = 0; outer < (mi > 0 ? 4 * mi + 20 : 1); ++outer) {
    std::vector<int> active;
    for (int r = 0; r < mi; ++r) {
      if (qp.A.row(r).dot(fit.x) > qp.b(r)) active.push_back(r);
    }
    const int rows = me + static_cast<int>(active.size());
    if (rows == 0) break;
    Eigen::MatrixXd C(rows, n);
    Eigen::VectorXd e(rows);
    C.topRows(me) = qp.J;
    e.head(me) = qp.d;
    for (std::size_t k = 0; k < active.size(); ++k) {
      C.row(me + static_cast<Eigen::Index>(k)) = qp.A.row(active[k]);
      e(me + static_cast<Eigen::Index>(k)) = qp.b(active[k]);
    }
    Eigen::VectorXd target = fit.x;
    bounded_least_squares(C, e, qp.lo, qp.hi, target);
    // The segment's best point among a few (the objective is convex and piecewise quadratic along it).
    Eigen::VectorXd best = fit.x;
    double best_here = best_value;
    for (const double a : {1.0, 0.5, 0.25, 0.125, 0.0625}) {
      const Eigen::VectorXd x = fit.x + a * (target - fit.x);
      const double v = value(x);
      if (v < best_here) {
        best_here = v;
        best = x;
      }
    }
    const bool improved = best_here < best_value * (1.0 - 1e-12);
    fit.x = best;
    best_value = best_here;
    if (!improved) break;
  }
  if (mi > 0) {
    // Step 1 / L with L the largest eigenvalue of [J; A]'[J; A], which bounds the gradient's Lipschitz constant.
    Eigen::MatrixXd stacked(me + mi, n);
    stacked << qp.J, qp.A;
    const double lipschitz = std::max(Eigen::JacobiSVD<Eigen::MatrixXd>(stacked).singularValues()(0), 1e-150);
    Eigen::VectorXd x = fit.x;
    for (int k = 0; k < 20000; ++k) {
      const Eigen::VectorXd viol = (qp.A * x - qp.b).cwiseMax(0.0);
      const Eigen::VectorXd grad = qp.J.transpose() * (qp.J * x - qp.d) + qp.A.transpose() * viol;
      const Eigen::VectorXd next = (x - grad / (lipschitz * lipschitz)).cwiseMax(qp.lo).cwiseMin(qp.hi);
      const double moved = (next - x).cwiseAbs().maxCoeff();
      x = next;
      if (moved <= 1e-16 * (1.0 + x.cwiseAbs().maxCoeff())) break;
    }
    if (value(x) < best_value) fit.x = x;
  }
  measure(fit.x, fit.equality_miss, fit.inequality_excess);
  return fit;
}

namespace {

// Why the rows cannot be met: the best fit of the rows inside the bounds (best_row_fit), and the joints held at a
// bound there. Runs only after a failure. *infeasible: the rows miss by more than 10 tolerances at best.
std::string diagnose_rows(const QpProblem& qp, double tolerance, bool* infeasible) {
  const int n = qp.n();
  const RowFit fit = best_row_fit(qp);
  const Eigen::VectorXd& x = fit.x;
  const Eigen::VectorXd eq = qp.J * x - qp.d;
  const Eigen::VectorXd in = (qp.A * x - qp.b).cwiseMax(0.0);
  const double worst = std::max(fit.equality_miss, fit.inequality_excess);
  *infeasible = worst > 10.0 * tolerance;
  std::ostringstream s;
  s.precision(6);
  if (!*infeasible) {
    s << "the rows can be met inside the bounds (best residual " << worst << ")";
    return s.str();
  }
  s << "the constraint rows cannot be met inside the bounds:";
  for (Eigen::Index r = 0; r < eq.size(); ++r) {
    if (std::abs(eq(r)) > 10.0 * tolerance) {
      s << " equality row " << r + 1 << " (from '" << source_name(qp, qp.eq_source[static_cast<std::size_t>(r)])
        << "') misses by " << std::abs(eq(r)) << " at best;";
    }
  }
  for (Eigen::Index r = 0; r < in.size(); ++r) {
    if (in(r) > 10.0 * tolerance) {
      s << " inequality row " << r + 1 << " (from '" << source_name(qp, qp.in_source[static_cast<std::size_t>(r)])
        << "'";
      if (qp.in_row_description) {
        const std::string what = qp.in_row_description(static_cast<int>(r));
        if (!what.empty()) s << ": " << what;
      }
      s << ") is exceeded by " << in(r) << " at best;";
    }
  }
  s << " joints held at a bound there:";
  bool any = false;
  for (int i = 0; i < n; ++i) {
    const bool at_lo = std::isfinite(qp.lo(i)) && x(i) <= qp.lo(i) + 1e-12;
    const bool at_hi = std::isfinite(qp.hi(i)) && x(i) >= qp.hi(i) - 1e-12;
    if (!at_lo && !at_hi) continue;
    any = true;
    s << " " << joint_label(qp, i) << " at its " << (at_lo ? "lower" : "upper") << " bound "
      << (at_lo ? qp.lo(i) : qp.hi(i)) << " (from '"
      << source_name(qp, at_lo ? qp.lo_source[static_cast<std::size_t>(i)] : qp.hi_source[static_cast<std::size_t>(i)])
      << "');";
  }
  if (!any) s << " none (the rows are inconsistent by themselves);";
  std::string out = s.str();
  out.pop_back();
  return out;
}

// What the equality rows' singular values say, when they say something: "" for well-conditioned rows.
std::string singular_rows(const QpProblem& qp) {
  if (qp.m_eq() == 0) return {};
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(qp.J).singularValues();
  const double largest = sv.size() > 0 ? sv(0) : 0.0;
  int rank = 0;
  for (Eigen::Index k = 0; k < sv.size(); ++k) rank += sv(k) > 1e-9 * largest && sv(k) > 0.0;
  const double smallest = qp.m_eq() > qp.n() ? 0.0 : sv(sv.size() - 1);
  std::ostringstream s;
  s.precision(3);
  if (rank < qp.m_eq()) {
    s << "the " << qp.m_eq() << " equality rows have rank " << rank << " here (a singular configuration: smallest "
      << "singular value " << smallest << ", largest " << largest << ")";
  } else if (smallest < 1e-4 * largest) {
    s << "the equality rows are nearly singular here (smallest singular value " << smallest << ", largest " << largest
      << ")";
  }
  return s.str();
}

}  // namespace

void LviEngine::diagnose_failure(const QpProblem& qp, bool capped, SolverInfo& info) const {
  // One decision gives both the status and the text: the rows are infeasible exactly when the best fit of the rows
  // inside the bounds misses them (best_row_fit); otherwise the engine failed on a QP that has a solution, and the
  // text says how, with the residual compared to the tolerance only in the direction it holds.
  bool unmeetable = false;
  const std::string rows = diagnose_rows(qp, settings_.tolerance, &unmeetable);
  const std::string singular = singular_rows(qp);
  std::ostringstream s;
  s.precision(6);
  if (unmeetable) {
    info.status = SolverStatus::kInfeasible;
    s << rows;
  } else {
    const SolverStatus reported = info.status;
    if (capped || reported == SolverStatus::kInfeasible || reported == SolverStatus::kSolved) {
      info.status = SolverStatus::kNumericalError;
      s << info.engine << ": the duals of the rows reached varpi = " << settings_.varpi << " although " << rows
        << ": this step's multipliers are larger than varpi (raise [solver] varpi, or keep the arm away "
        << "from this configuration)";
    } else {
      s << info.engine;
      if (reported == SolverStatus::kMaxIterations) {
        s << " reached max_iterations = " << settings_.max_iterations;
      } else {
        s << " failed";
      }
      if (!info.diagnosis.empty()) s << " (" << info.diagnosis << ")";
      s << " with residual " << info.residual
        << (info.residual > settings_.tolerance ? " > tolerance " : " (within tolerance ") << settings_.tolerance
        << (info.residual > settings_.tolerance ? "" : ", but the engine did not accept it)") << " after "
        << info.iterations << (info.iterations == 1 ? " iteration; " : " iterations; ") << rows;
    }
  }
  if (!singular.empty()) s << "; " << singular;
  info.diagnosis = s.str();
}

void LviEngine::setup(int n, int m_e, int m_i, SolverResult& result) {
  REDRES_REQUIRE(n > 0 && m_e >= 0 && m_i >= 0, "LviEngine::setup", "n > 0, m_e >= 0, m_i >= 0");
  n_ = n;
  m_e_ = m_e;
  m_i_ = m_i;
  result.x = Eigen::VectorXd::Zero(n);
  result.y = Eigen::VectorXd::Zero(m_e);
  result.z = Eigen::VectorXd::Zero(m_i);
  result.info = SolverInfo{};
  result.info.diagnosis.reserve(256);
  warm_ = false;
  do_setup(n, m_e, m_i);
}

void LviEngine::check_sizes(const QpProblem& qp, const SolverResult& result) const {
  REDRES_REQUIRE(n_ > 0, "LviEngine::solve", "setup() was called");
  REDRES_REQUIRE(qp.n() == n_ && qp.m_eq() == m_e_ && qp.m_in() == m_i_, "LviEngine::solve",
                 "the QP has the sizes given to setup() (n " + std::to_string(n_) + ", m_e " + std::to_string(m_e_) +
                     ", m_i " + std::to_string(m_i_) + ")");
  REDRES_REQUIRE(result.x.size() == n_ && result.y.size() == m_e_ && result.z.size() == m_i_, "LviEngine::solve",
                 "result was sized by setup()");
}

void LviEngine::solve(const QpProblem& qp, SolverResult& result) {
  check_sizes(qp, result);
  qp.validate();
  run(qp, result);
}

void LviEngine::solve_valid(const QpProblem& qp, SolverResult& result) {
  check_sizes(qp, result);
  run(qp, result);
}

void LviEngine::run(const QpProblem& qp, SolverResult& result) {
  SolverInfo& info = result.info;
  info.diagnosis.clear();
  info.iterations = 0;
  info.engine = name();

  bool conflicting = false;
  const double* lo = qp.lo.data();
  const double* hi = qp.hi.data();
  for (int i = 0; i < n_; ++i) conflicting |= lo[i] > hi[i];  // no early exit: the usual case is none
  if (conflicting) {
    const BoundConflict conflict = find_bound_conflict(qp);
    info.status = SolverStatus::kInfeasible;
    double gap = 0.0;
    for (int i = 0; i < n_; ++i) gap = std::max(gap, lo[i] - hi[i]);
    info.residual = std::isfinite(gap) ? gap : std::numeric_limits<double>::max();
    info.diagnosis = "bounds conflict at " + describe(conflict, qp.variable_names);
    result.x.setZero();  // a definite value; callers must check the status
    result.y.setZero();
    result.z.setZero();
    warm_ = false;
    return;
  }

  do_solve(qp, result);

  // Duals at the +-varpi cap mean the LVI met its box only because the rows were given up: infeasible.
  const double cap = settings_.varpi * (1.0 - 1e-9);
  bool capped = false;
  for (int r = 0; r < m_e_; ++r) capped |= std::abs(result.y(r)) >= cap;
  for (int r = 0; r < m_i_; ++r) capped |= result.z(r) >= cap;
  if (info.status != SolverStatus::kSolved || capped) {
    diagnose_failure(qp, capped, info);
    warm_ = false;
    result.y.setZero();
    result.z.setZero();
    return;
  }
  warm_ = true;
}

void LviEngine::set_settings(const SolverSettings& s) {
  require_valid(s, SolverSettings::schema(), "solver settings");
  settings_ = s;
}

const Schema<SolverSettings>& SolverSettings::schema() {
  using C = SolverSettings;
  static const Schema<C> s{
      {field("tolerance", &C::tolerance, "", "stopping test ||e(u)||_2 <= tolerance (below 1e-14 rounding decides)",
             between(1e-14, 1.0)),
       field("varpi", &C::varpi, "", "bound on the duals standing for infinity", between(1.0, 1e12)),
       field("max_iterations", &C::max_iterations, "", "iteration cap per solve", at_least<int>(1)),
       field("warm_start", &C::warm_start, "", "start each solve from the previous u")}};
  return s;
}

}  // namespace redres

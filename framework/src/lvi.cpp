#include "redres/lvi.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace redres {

const char* to_string(SolverStatus status) {
  switch (status) {
    case SolverStatus::kSolved: return "solved";
    case SolverStatus::kMaxIterations: return "max_iterations";
    case SolverStatus::kInfeasible: return "infeasible";
    case SolverStatus::kNumericalError: return "numerical_error";
    case SolverStatus::kNotRun: return "not_run";
    case SolverStatus::kInvalidProblem: return "invalid_problem";
  }
  return "unknown";
}

EngineRegistry& engine_registry() {
  static EngineRegistry registry("LVI engine");
  return registry;
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

// Why the rows cannot be met: the box-constrained least-squares residual min |J x - d| (and the inequality
// violation), found by projected gradient, and the joints held at a bound there. Runs only after a failure.
std::string diagnose_rows(const QpProblem& qp, double tolerance, bool* infeasible) {
  const int n = qp.n();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n).cwiseMax(qp.lo).cwiseMin(qp.hi);
  const double lipschitz = qp.J.squaredNorm() + qp.A.squaredNorm() + 1e-300;
  for (int k = 0; k < 5000; ++k) {
    const Eigen::VectorXd viol = (qp.A * x - qp.b).cwiseMax(0.0);
    const Eigen::VectorXd grad = qp.J.transpose() * (qp.J * x - qp.d) + qp.A.transpose() * viol;
    x = (x - grad / lipschitz).cwiseMax(qp.lo).cwiseMin(qp.hi);
  }
  const Eigen::VectorXd eq = qp.J * x - qp.d;
  const Eigen::VectorXd in = (qp.A * x - qp.b).cwiseMax(0.0);
  const double worst = std::max(eq.size() ? eq.cwiseAbs().maxCoeff() : 0.0, in.size() ? in.maxCoeff() : 0.0);
  *infeasible = worst > 10.0 * tolerance;
  std::ostringstream s;
  s.precision(6);
  if (!*infeasible) return "the rows can be met inside the bounds (best residual " + std::to_string(worst) + ")";
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

}  // namespace

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
    bool infeasible = false;
    const std::string rows = diagnose_rows(qp, settings_.tolerance, &infeasible);
    if (infeasible || capped) {
      info.status = SolverStatus::kInfeasible;
      info.diagnosis = rows;
    } else if (info.diagnosis.empty()) {
      std::ostringstream s;
      s << info.engine << " stopped with residual " << info.residual << " > tolerance " << settings_.tolerance
        << " after " << info.iterations << " iterations; " << rows;
      info.diagnosis = s.str();
    }
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

namespace {
// `engine` itself, so that the listing and the reading share one definition.
struct EngineChoice {
  std::string engine = "projection";
  static const Schema<EngineChoice>& schema() {
    static const Schema<EngineChoice> s{{field("engine", &EngineChoice::engine, "", "the LVI engine (see below)")}};
    return s;
  }
};
}  // namespace

const std::vector<KeyInfo>& solver_common_keys() {
  static const std::vector<KeyInfo> keys = [] {
    std::vector<KeyInfo> k = describe_keys(EngineChoice::schema());
    for (auto& x : describe_keys(SolverSettings::schema())) k.push_back(std::move(x));
    return k;
  }();
  return keys;
}

std::unique_ptr<LviEngine> make_engine(const TableReader& solver) {
  EngineChoice choice;
  read_config(solver, EngineChoice::schema(), choice);
  const EngineRegistry& reg = engine_registry();
  const auto* entry = reg.find(choice.engine);
  if (entry == nullptr) {
    std::string names;
    for (const auto* e : reg.entries()) names += (names.empty() ? "'" : ", '") + e->type + "'";
    solver.fail("engine", "expected one of " + names + ", got '" + choice.engine + "'");
  }
  SolverSettings s;
  read_config(solver, SolverSettings::schema(), s);
  const std::any config = entry->read(solver);
  solver.finish();
  try {
    return entry->make(config, s);
  } catch (const FieldError& e) {
    rethrow_at(solver, e);
  }
}

std::unique_ptr<LviEngine> make_engine(const std::string& name, const SolverSettings& settings) {
  const auto* e = engine_registry().find(name);
  if (e == nullptr) {
    throw std::invalid_argument("make_engine: unknown engine '" + name +
                                "'; known engines: " + engine_registry().names());
  }
  require_valid(settings, SolverSettings::schema(), "make_engine(" + name + ")");
  return e->make(e->defaults, settings);
}

}  // namespace redres

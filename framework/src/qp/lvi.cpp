/// The LVI engine base (LviEngine): sizes, checks, the bound-conflict test, the run of an engine and the check of
/// its duals, the settings and their schema; the status names and the LVI residual ||e(u)||. A failed solve is
/// diagnosed in diagnosis.cpp, from the row fit of row_fit.cpp.

#include "redres/qp/lvi.hpp"
#include "redres/common/hot.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

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
    case SolverStatus::kBraked: return "braked";
    case SolverStatus::kInaccuratePrimal: return "inaccurate_primal";
    case SolverStatus::kInaccurateDual: return "inaccurate_dual";
    case SolverStatus::kInaccurateComplementarity: return "inaccurate_complementarity";
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

void LviEngine::setup(int n, int m_e, int m_i, SolverResult& result) {
  REDRES_REQUIRE(n > 0 && m_e >= 0 && m_i >= 0, "LviEngine::setup", "n > 0, m_e >= 0, m_i >= 0");
  n_ = n;
  m_e_ = m_e;
  m_i_ = m_i;
  result.x = Eigen::VectorXd::Zero(n);
  result.y = Eigen::VectorXd::Zero(m_e);
  result.z = Eigen::VectorXd::Zero(m_i);
  result.info = SolverInfo{};
  result.info.diagnosis.reserve(kDiagnosisCapacity);
  note_.reserve(kDiagnosisCapacity);
  warm_ = false;
  fitter_.setup(n, m_e, m_i);
  do_setup(n, m_e, m_i);
}

REDRES_HOT void LviEngine::check_sizes(const QpProblem& qp, const SolverResult& result) const {
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
  w_diagonal_ = qp.w_diagonal && off_diagonal_zero(qp.W);  // a QP filled by hand may have left the flag
  run(qp, result);
}

REDRES_HOT void LviEngine::solve_valid(const QpProblem& qp, SolverResult& result) {
  check_sizes(qp, result);
  w_diagonal_ = qp.w_diagonal;  // kept by QpBuilder and clear() for a QP built through them
  run(qp, result);
}

REDRES_HOT void LviEngine::run(const QpProblem& qp, SolverResult& result) {
  SolverInfo& info = result.info;
  info.diagnosis.clear();
  info.iterations = 0;
  info.engine = name();
  info.primal_residual = info.dual_residual = info.complementarity = 0.0;

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
    keep_diagnosis_capacity(info.diagnosis);
    TextSink text(info.diagnosis);
    text << "bounds conflict at ";
    describe(conflict, qp.variable_names, text);
    result.x.setZero();  // a definite value; callers must check the status
    result.y.setZero();
    result.z.setZero();
    warm_ = false;
    return;
  }

  // The step after an infeasible one: equality rows that still cannot be met inside the bounds are found by their
  // best fit (the test behind every `infeasible`, diagnose_failure(); exact for equality rows alone, where it is an
  // active-set bounded least squares) at a fraction of what an engine spends before it gives up (newton's dual runs
  // off to varpi in about 60 iterations on a cascade's unmeetable level). With inequality rows the fit is iterative
  // and may stop short of a point that meets them, so the engine decides.
  if (const RowFit* fit = last_infeasible_ && m_i_ == 0 ? &fitter_.fit(qp) : nullptr;
      fit != nullptr && fit->miss_norm() > settings_.tolerance) {
    info.status = SolverStatus::kInfeasible;
    info.residual = fit->miss_norm();
    result.x = fit->x;
    result.y.setZero();
    result.z.setZero();
    if (diagnoses_) diagnose_failure(qp, false, info, *fit);
    warm_ = false;
    return;
  }
  do_solve(qp, result);
  last_infeasible_ = false;

  // Duals at the +-varpi cap mean the LVI met its box only because the rows were given up: infeasible.
  const double cap = settings_.varpi * (1.0 - 1e-9);
  bool capped = false;
  for (int r = 0; r < m_e_; ++r) capped |= std::abs(result.y(r)) >= cap;
  for (int r = 0; r < m_i_; ++r) capped |= result.z(r) >= cap;
  // `solved` is a certificate: whatever the engine's own test, the answer is checked in the QP's units.
  const Certificate certificate = certify(qp, result);
  info.primal_residual = certificate.primal;
  info.dual_residual = certificate.dual;
  info.complementarity = certificate.complementarity;
  if (info.status == SolverStatus::kSolved && !capped && certificate.verdict() != SolverStatus::kSolved) {
    info.status = certificate.verdict();
    keep_diagnosis_capacity(info.diagnosis);
    info.diagnosis.clear();
    TextSink text(info.diagnosis);
    describe(certificate, qp, text);
  }
  if (info.status != SolverStatus::kSolved || capped) {
    if (diagnoses_) diagnose_failure(qp, capped, info);
    last_infeasible_ = info.status == SolverStatus::kInfeasible;
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
      {field("tolerance", &C::tolerance, "",
             "stopping test ||e(u)||_2 <= tolerance (below 1e-14 rounding decides), and the certificate's absolute "
             "limit",
             between(1e-14, 1.0)),
       field("relative_tolerance", &C::relative_tolerance, "",
             "the certificate behind `solved`: each residual (primal, dual, complementarity) within tolerance + "
             "relative_tolerance x the size of the data it compares",
             between(0.0, 1e-2)),
       field("varpi", &C::varpi, "", "bound on the duals standing for infinity", between(1.0, 1e12)),
       field("max_iterations", &C::max_iterations, "", "iteration cap per solve", at_least<int>(1)),
       field("warm_start", &C::warm_start, "", "start each solve from the previous u")}};
  return s;
}

}  // namespace redres

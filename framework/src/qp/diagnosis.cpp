/// The diagnosis of a failed solve (LviEngine::diagnose_failure): the status and the text, from the row fit
/// (RowFitter) and the equality rows' singular values.

#include "redres/qp/lvi.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

#include "redres/common/text_sink.hpp"
#include "redres/qp/row_fit.hpp"

namespace redres {

namespace {

void joint_label(const QpProblem& qp, int i, TextSink& s) {
  s << "joint " << i + 1;
  if (i < static_cast<int>(qp.variable_names.size()))
    s << " ('" << qp.variable_names[static_cast<std::size_t>(i)] << "')";
}

// Why the rows cannot be met: the best fit of the rows inside the bounds (RowFitter), the rows it misses by more
// than the tolerance, and the joints held at a bound there. Runs only after a failure.
void diagnose_rows(const QpProblem& qp, const RowFit& fit, double tolerance, bool infeasible, TextSink& s) {
  const int n = qp.n();
  const Eigen::VectorXd& x = fit.x;
  const Eigen::VectorXd& eq = fit.misses;
  const Eigen::VectorXd& in = fit.excesses;
  s.precision(6);
  if (!infeasible) {
    s << "the rows can be met inside the bounds (best residual " << std::max(fit.equality_miss, fit.inequality_excess)
      << ", " << fit.miss_norm() << " in 2-norm)";
    return;
  }
  s << "the constraint rows cannot be met inside the bounds:";
  bool first = true;
  const auto next = [&] {
    if (!first) s << ";";
    first = false;
  };
  // The rows missed by most are named (at most kNamedRows of them, so the joints at their bounds and the rank still
  // fit in the diagnosis); the rest are counted.
  constexpr int kNamedRows = 8;
  int named = 0, unnamed = 0;
  double cut = 0.0;  // rows missed by no more than this are counted, not named
  {
    int over = 0;
    for (Eigen::Index r = 0; r < eq.size(); ++r) over += std::abs(eq(r)) > tolerance;
    for (Eigen::Index r = 0; r < in.size(); ++r) over += in(r) > tolerance;
    if (over > kNamedRows) {
      // The kNamedRows-th largest miss, by repeated selection (allocation-free; only on such failures).
      double below = std::numeric_limits<double>::infinity();
      for (int k = 0; k < kNamedRows; ++k) {
        double best = -1.0;
        for (Eigen::Index r = 0; r < eq.size(); ++r) {
          const double m = std::abs(eq(r));
          if (m > tolerance && m < below && m > best) best = m;
        }
        for (Eigen::Index r = 0; r < in.size(); ++r) {
          if (in(r) > tolerance && in(r) < below && in(r) > best) best = in(r);
        }
        below = best;
      }
      cut = std::nextafter(below, 0.0);
    }
  }
  const auto shown = [&](double miss) {
    if (miss > cut && named < kNamedRows) {
      ++named;
      return true;
    }
    ++unnamed;
    return false;
  };
  for (Eigen::Index r = 0; r < eq.size(); ++r) {
    if (std::abs(eq(r)) > tolerance && shown(std::abs(eq(r)))) {
      next();
      s << " equality row " << r + 1 << " (from '" << source_name(qp, qp.eq_source[static_cast<std::size_t>(r)])
        << "') misses by " << std::abs(eq(r)) << " at best";
    }
  }
  for (Eigen::Index r = 0; r < in.size(); ++r) {
    if (in(r) > tolerance && shown(in(r))) {
      next();
      s << " inequality row " << r + 1 << " (from '" << source_name(qp, qp.in_source[static_cast<std::size_t>(r)])
        << "'";
      if (qp.in_row_description) {
        const std::size_t before = s.str().size();
        s << ": ";
        const std::size_t mark = s.str().size();
        qp.in_row_description(static_cast<int>(r), s);
        if (s.str().size() == mark && !s.cut()) s.str().resize(before);  // the row said nothing
      }
      s.precision(6);
      s << ") is exceeded by " << in(r) << " at best";
    }
  }
  if (unnamed > 0) {
    next();
    s << " and " << unnamed << " more row" << (unnamed == 1 ? "" : "s") << " missed by less";
  }
  next();
  s << " joints held at a bound there:";
  bool any = false;
  for (int i = 0; i < n; ++i) {
    const bool at_lo = std::isfinite(qp.lo(i)) && x(i) <= qp.lo(i) + 1e-12;
    const bool at_hi = std::isfinite(qp.hi(i)) && x(i) >= qp.hi(i) - 1e-12;
    if (!at_lo && !at_hi) continue;
    if (any) s << ";";
    any = true;
    s << " ";
    joint_label(qp, i, s);
    s << " at its " << (at_lo ? "lower" : "upper") << " bound " << (at_lo ? qp.lo(i) : qp.hi(i)) << " (from '"
      << source_name(qp, at_lo ? qp.lo_source[static_cast<std::size_t>(i)] : qp.hi_source[static_cast<std::size_t>(i)])
      << "')";
  }
  if (!any) s << " none (the rows are inconsistent by themselves)";
}

// What the equality rows' singular values say, when they say something: nothing for well-conditioned rows.
void singular_rows(const QpProblem& qp, RowFitter& fitter, TextSink& s) {
  if (qp.m_eq() == 0) return;
  const Eigen::VectorXd& sv = fitter.equality_singular_values(qp);
  const double largest = sv.size() > 0 ? sv(0) : 0.0;
  int rank = 0;
  for (Eigen::Index k = 0; k < sv.size(); ++k) rank += sv(k) > 1e-9 * largest && sv(k) > 0.0;
  const double smallest = qp.m_eq() > qp.n() ? 0.0 : sv(sv.size() - 1);
  s.precision(3);
  if (rank < qp.m_eq()) {
    s << "; the " << qp.m_eq() << " equality rows have rank " << rank
      << " here (a singular configuration: smallest singular value " << smallest << ", largest " << largest << ")";
  } else if (smallest < 1e-4 * largest) {
    s << "; the equality rows are nearly singular here (smallest singular value " << smallest << ", largest " << largest
      << ")";
  }
}

}  // namespace

bool LviEngine::rows_unmeetable(const QpProblem& qp) { return fitter_.fit(qp).miss_norm() > settings_.tolerance; }

void LviEngine::diagnose_failure(const QpProblem& qp, bool capped, SolverInfo& info) {
  diagnose_failure(qp, capped, info, fitter_.fit(qp));
}

void LviEngine::diagnose_failure(const QpProblem& qp, bool capped, SolverInfo& info, const RowFit& fit) {
  // One decision gives both the status and the text: the rows are infeasible exactly when the best fit of the rows
  // inside the bounds misses them (RowFitter); otherwise the engine failed on a QP that has a solution, and the
  // text says how, with the residual compared to the tolerance only in the direction it holds. The text is written
  // into the diagnosis's reserved storage (the engine's own note is kept aside in note_ meanwhile): no allocation.
  const bool unmeetable = fit.miss_norm() > settings_.tolerance;
  note_.assign(info.diagnosis);  // note_ is reserved: a copy, so each string keeps its own storage
  keep_diagnosis_capacity(info.diagnosis);
  info.diagnosis.clear();
  TextSink s(info.diagnosis);
  s.precision(6);
  if (unmeetable) {
    info.status = SolverStatus::kInfeasible;
    diagnose_rows(qp, fit, settings_.tolerance, true, s);
  } else {
    const SolverStatus reported = info.status;
    if (capped || reported == SolverStatus::kInfeasible || reported == SolverStatus::kSolved) {
      info.status = SolverStatus::kNumericalError;
      s << info.engine << ": the duals of the rows reached varpi = " << settings_.varpi << " although ";
      diagnose_rows(qp, fit, settings_.tolerance, false, s);
      s << ": this step's multipliers are larger than varpi (raise [solver] varpi, or keep the arm away "
        << "from this configuration)";
    } else if (reported == SolverStatus::kInaccuratePrimal || reported == SolverStatus::kInaccurateDual ||
               reported == SolverStatus::kInaccurateComplementarity) {
      s << info.engine << " stopped after " << info.iterations << (info.iterations == 1 ? " iteration" : " iterations")
        << ", but its answer is not certified: " << note_ << "; ";
      diagnose_rows(qp, fit, settings_.tolerance, false, s);
    } else {
      s << info.engine;
      if (reported == SolverStatus::kMaxIterations && note_.empty()) {
        s << " reached max_iterations = " << settings_.max_iterations;
      } else {
        s << " failed";
      }
      if (!note_.empty()) s << " (" << note_ << ")";
      s << " with residual " << info.residual
        << (info.residual > settings_.tolerance ? " > tolerance " : " (within tolerance ") << settings_.tolerance
        << (info.residual > settings_.tolerance ? "" : ", but the engine did not accept it)") << " after "
        << info.iterations << (info.iterations == 1 ? " iteration; " : " iterations; ");
      diagnose_rows(qp, fit, settings_.tolerance, false, s);
    }
  }
  if (singular_values_) singular_rows(qp, fitter_, s);
}

void LviEngine::describe_singular_rows(const QpProblem& qp, TextSink& out) { singular_rows(qp, fitter_, out); }

}  // namespace redres

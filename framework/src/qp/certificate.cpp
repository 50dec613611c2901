/// The certificate behind `solved` (redres/qp/certificate.hpp): primal, dual and complementarity residuals of an
/// answer, in the QP's own units, each against an absolute and a relative limit.

#include "redres/qp/certificate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "redres/common/hot.hpp"
#include "redres/qp/lvi.hpp"

namespace redres {

namespace {

// A_r x for row r of a column-major matrix.
double row_dot(const Eigen::MatrixXd& M, Eigen::Index r, const double* x) {
  const Eigen::Index rows = M.rows(), cols = M.cols();
  const double* m = M.data() + r;
  double s = 0.0;
  for (Eigen::Index c = 0; c < cols; ++c) s += m[c * rows] * x[c];
  return s;
}

double row_norm_inf(const Eigen::MatrixXd& M, Eigen::Index r) {
  const Eigen::Index rows = M.rows(), cols = M.cols();
  const double* m = M.data() + r;
  double s = 0.0;
  for (Eigen::Index c = 0; c < cols; ++c) s = std::max(s, std::abs(m[c * rows]));
  return s;
}

double col_dot(const Eigen::MatrixXd& M, Eigen::Index c, const double* v) {
  const Eigen::Index rows = M.rows();
  const double* m = M.data() + c * rows;
  double s = 0.0;
  for (Eigen::Index r = 0; r < rows; ++r) s += m[r] * v[r];
  return s;
}

bool all_finite(const Eigen::VectorXd& v) {
  const double* p = v.data();
  double acc = 0.0;
  for (Eigen::Index i = 0; i < v.size(); ++i) acc += p[i] * 0.0;  // NaN or inf make it NaN
  return acc == 0.0;
}

}  // namespace

bool off_diagonal_zero(const Eigen::MatrixXd& W) noexcept {
  const Eigen::Index n = W.rows();
  const double* w = W.data();
  for (Eigen::Index c = 0; c < n; ++c) {
    bool zero = true;
    for (Eigen::Index r = 0; r < n; ++r) zero &= r == c || w[c * n + r] == 0.0;
    if (!zero) return false;
  }
  return true;
}

namespace {

// certify() for W diagonal or not, kRows equality rows and kCols joints (0: any number), so that the paper's case
// (diagonal W, two rows, six joints) runs loops of fixed length, as the engines do.
template <bool kDiagonal, int kRows, int kCols>
REDRES_HOT Certificate certify_impl(const QpProblem& qp, const SolverResult& answer, double absolute, double relative) {
  Certificate c;
  const int n = kCols > 0 ? kCols : qp.n(), me = kRows > 0 ? kRows : qp.m_eq(), mi = qp.m_in();
  const double* __restrict x = answer.x.data();
  const double* __restrict y = answer.y.data();
  const double* __restrict z = answer.z.data();
  const double* __restrict lo = qp.lo.data();
  const double* __restrict hi = qp.hi.data();
  const double* __restrict d = qp.d.data();
  const double* __restrict b = qp.b.data();
  // Primal: the rows' and the bounds' misses; the scale is that of what the rows compare.
  double scale_p = 0.0, primal = 0.0;
  Certificate::Where where = Certificate::Where::kNone;
  int at = -1;
  const double* __restrict J = qp.J.data();
  for (int r = 0; r < me; ++r) {
    double jx = 0.0;
    for (int i = 0; i < n; ++i) jx += J[static_cast<std::ptrdiff_t>(i) * me + r] * x[i];
    scale_p = std::max(scale_p, std::max(std::abs(jx), std::abs(d[r])));
    const double miss = std::abs(jx - d[r]);
    if (miss > primal) {
      primal = miss;
      where = Certificate::Where::kEqualityRow;
      at = r;
    }
  }
  for (int r = 0; r < mi; ++r) {
    const double ax = row_dot(qp.A, r, x);
    scale_p = std::max(scale_p, std::abs(ax));
    if (ax - b[r] > primal) {
      primal = ax - b[r];
      where = Certificate::Where::kInequalityRow;
      at = r;
    }
  }
  for (int i = 0; i < n; ++i) {
    if (lo[i] - x[i] > primal) {
      primal = lo[i] - x[i];
      where = Certificate::Where::kLowerBound;
      at = i;
    }
    if (x[i] - hi[i] > primal) {
      primal = x[i] - hi[i];
      where = Certificate::Where::kUpperBound;
      at = i;
    }
  }
  c.primal = primal;
  c.primal_where = where;
  c.primal_at = at;
  c.primal_limit = absolute + relative * scale_p;
  const double active = c.primal_limit;  // a bound or row this close counts as active
  // Dual: g = W x + zeta - J'y + A'z, with each bound's force allowed only where the bound is active and only in
  // the direction that holds x inside.
  const double* __restrict W = qp.W.data();
  const double* __restrict zeta = qp.zeta.data();
  double scale_d = 0.0, dual = 0.0;
  int dual_at = -1;
  for (int i = 0; i < n; ++i) {
    // W is symmetric: its row i is column i.
    double wx = 0.0;
    if constexpr (kDiagonal) {
      wx = W[static_cast<std::ptrdiff_t>(i) * (n + 1)] * x[i];
    } else {
      wx = col_dot(qp.W, i, x);
    }
    double jy = 0.0;
    for (int r = 0; r < me; ++r) jy += J[static_cast<std::ptrdiff_t>(i) * me + r] * y[r];
    const double az = mi > 0 ? col_dot(qp.A, i, z) : 0.0;
    scale_d =
        std::max(std::max(scale_d, std::abs(wx)), std::max(std::abs(zeta[i]), std::max(std::abs(jy), std::abs(az))));
    const double g = wx + zeta[i] - jy + az;
    const bool at_lo = x[i] - lo[i] <= active, at_hi = hi[i] - x[i] <= active;
    const double residual = at_lo ? (at_hi ? 0.0 : -g) : at_hi ? g : std::abs(g);
    if (residual > dual) {
      dual = residual;
      dual_at = i;
    }
  }
  for (int r = 0; r < mi; ++r) {
    if (z[r] >= 0.0) continue;
    const double negative = -z[r] * row_norm_inf(qp.A, r);
    if (negative > dual) {
      dual = negative;
      dual_at = n + r;
    }
  }
  c.dual = dual;
  c.dual_at = dual_at;
  c.dual_limit = absolute + relative * scale_d;
  // Complementarity: the force of the inequality rows that are not active.
  for (int r = 0; r < mi; ++r) {
    if (z[r] <= 0.0) continue;
    if (b[r] - row_dot(qp.A, r, x) <= active) continue;
    const double force = z[r] * row_norm_inf(qp.A, r);
    if (force > c.complementarity) {
      c.complementarity = force;
      c.complementarity_at = r;
    }
  }
  return c;
}

}  // namespace

REDRES_HOT Certificate certify(const QpProblem& qp, const SolverResult& answer, bool w_diagonal, double absolute,
                               double relative) {
  if (!all_finite(answer.x) || !all_finite(answer.y) || !all_finite(answer.z)) {
    Certificate c;
    c.primal = c.dual = std::numeric_limits<double>::infinity();
    return c;  // a non-finite answer is certified by nothing (primal_where kNone names it)
  }
  if (w_diagonal && qp.m_eq() == 2 && qp.n() == 6) return certify_impl<true, 2, 6>(qp, answer, absolute, relative);
  if (w_diagonal) return certify_impl<true, 0, 0>(qp, answer, absolute, relative);
  return certify_impl<false, 0, 0>(qp, answer, absolute, relative);
}

namespace {
void name_joint(const QpProblem& qp, int i, TextSink& out) {
  out << "joint " << i + 1;
  if (static_cast<std::size_t>(i) < qp.variable_names.size()) out << " ('" << qp.variable_names[i] << "')";
}
void name_row(const QpProblem& qp, bool equality, int r, TextSink& out) {
  out << (equality ? "equality row " : "inequality row ") << r;
  const std::vector<int>& sources = equality ? qp.eq_source : qp.in_source;
  if (static_cast<std::size_t>(r) < sources.size() && sources[static_cast<std::size_t>(r)] >= 0) {
    out << " (from '" << source_name(qp, sources[static_cast<std::size_t>(r)]) << "')";
  }
}
}  // namespace

void describe(const Certificate& c, const QpProblem& qp, TextSink& out) {
  out.precision(3);
  switch (c.verdict()) {
    case SolverStatus::kInaccuratePrimal:
      out << "primal residual " << c.primal << " > limit " << c.primal_limit;
      switch (c.primal_where) {
        case Certificate::Where::kNone: out << " (the answer is not finite)"; break;
        case Certificate::Where::kEqualityRow:
          out << " at ";
          name_row(qp, true, c.primal_at, out);
          break;
        case Certificate::Where::kInequalityRow:
          out << " at ";
          name_row(qp, false, c.primal_at, out);
          break;
        case Certificate::Where::kLowerBound:
        case Certificate::Where::kUpperBound: {
          const bool lower = c.primal_where == Certificate::Where::kLowerBound;
          out << " at ";
          name_joint(qp, c.primal_at, out);
          out << (lower ? "'s lower bound" : "'s upper bound");
          const std::vector<int>& sources = lower ? qp.lo_source : qp.hi_source;
          const auto j = static_cast<std::size_t>(c.primal_at);
          if (j < sources.size() && sources[j] >= 0) out << " (from '" << source_name(qp, sources[j]) << "')";
          break;
        }
      }
      break;
    case SolverStatus::kInaccurateDual:
      out << "dual residual " << c.dual << " > limit " << c.dual_limit << " at ";
      if (c.dual_at >= qp.n()) {
        name_row(qp, false, c.dual_at - qp.n(), out);
        out << "'s multiplier, which is negative";
      } else {
        name_joint(qp, c.dual_at, out);
      }
      break;
    case SolverStatus::kInaccurateComplementarity:
      out << "complementarity " << c.complementarity << " > limit " << c.dual_limit << ": ";
      name_row(qp, false, c.complementarity_at, out);
      out << " is not active but carries a multiplier";
      break;
    default: out << "certified"; break;
  }
}

}  // namespace redres

/// The certificate behind `solved` (redres/qp/certificate.hpp): primal, dual and complementarity residuals of an
/// answer, in the QP's own units, each against an absolute and a relative limit.

#include "redres/qp/certificate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

// The three figures for W diagonal or not. kLocate: also where each figure's largest term is, for describe(); the
// step's path measures without it and measures again with it only when the verdict fails, so that a certified answer
// costs a few branch-free passes over the data. Both variants add the same terms in the same order: the figures are
// the same. Without kLocate a non-finite answer is caught by one sum (a NaN or an infinity in x, y or z makes some
// stationarity term NaN or infinite). kRows, kCols (0: any): the equality rows and joints fixed, no inequality rows.
template <bool kDiagonal, bool kLocate, int kRows = 0, int kCols = 0>
[[gnu::noinline]] REDRES_HOT Certificate measure(const QpProblem& qp, const SolverResult& answer, double absolute,
                                                 double relative) {
  Certificate c;
  const int n = kCols > 0 ? kCols : qp.n(), me = kRows > 0 ? kRows : qp.m_eq(), mi = kCols > 0 ? 0 : qp.m_in();
  const double* __restrict x = answer.x.data();
  const double* __restrict y = answer.y.data();
  const double* __restrict z = answer.z.data();
  const double* __restrict lo = qp.lo.data();
  const double* __restrict hi = qp.hi.data();
  const double* __restrict d = qp.d.data();
  const double* __restrict b = qp.b.data();
  const double* __restrict J = qp.J.data();
  // Keeps the larger of `value` and `figure`; with kLocate, also where it is.
  const auto keep = [](double& figure, double value, auto&& located) {
    if constexpr (kLocate) {
      if (value > figure) {
        figure = value;
        located();
      }
    } else {
      figure = std::max(figure, value);
    }
  };
  // Primal: the rows' and the bounds' misses; the scale is that of what the rows compare.
  double scale_p = 0.0, primal = 0.0;
  for (int r = 0; r < me; ++r) {
    double jx = 0.0;
    for (int i = 0; i < n; ++i) jx += J[static_cast<std::ptrdiff_t>(i) * me + r] * x[i];
    scale_p = std::max(scale_p, std::max(std::abs(jx), std::abs(d[r])));
    keep(primal, std::abs(jx - d[r]), [&] {
      c.primal_where = Certificate::Where::kEqualityRow;
      c.primal_at = r;
    });
  }
  for (int r = 0; r < mi; ++r) {
    const double ax = row_dot(qp.A, r, x);
    scale_p = std::max(scale_p, std::abs(ax));
    keep(primal, ax - b[r], [&] {
      c.primal_where = Certificate::Where::kInequalityRow;
      c.primal_at = r;
    });
  }
  for (int i = 0; i < n; ++i) {
    keep(primal, lo[i] - x[i], [&] {
      c.primal_where = Certificate::Where::kLowerBound;
      c.primal_at = i;
    });
    keep(primal, x[i] - hi[i], [&] {
      c.primal_where = Certificate::Where::kUpperBound;
      c.primal_at = i;
    });
  }
  c.primal = primal;
  c.primal_limit = absolute + relative * scale_p;
  const double active = c.primal_limit;  // a bound or row this close counts as active
  // Dual: g = W x + zeta - J'y + A'z, with each bound's force allowed only where the bound is active and only in
  // the direction that holds x inside: g_i > 0 counts unless x_i is at lo_i, g_i < 0 unless it is at hi_i.
  const double* __restrict W = qp.W.data();
  const double* __restrict zeta = qp.zeta.data();
  double scale_d = 0.0, dual = 0.0, nonfinite = 0.0;
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
    nonfinite += g * 0.0;  // NaN when x_i, y, z or the data make g NaN or infinite
    const bool at_lo = x[i] - lo[i] <= active, at_hi = hi[i] - x[i] <= active;
    const double residual = std::max(at_lo ? 0.0 : g, at_hi ? 0.0 : -g);
    keep(dual, residual, [&] { c.dual_at = i; });
  }
  for (int r = 0; r < mi; ++r) {
    if (z[r] >= 0.0) continue;
    keep(dual, -z[r] * row_norm_inf(qp.A, r), [&] { c.dual_at = n + r; });
  }
  c.dual = dual;
  c.dual_limit = absolute + relative * scale_d;
  // Complementarity: the force of the inequality rows that are not active.
  for (int r = 0; r < mi; ++r) {
    if (z[r] <= 0.0) continue;
    if (b[r] - row_dot(qp.A, r, x) <= active) continue;
    keep(c.complementarity, z[r] * row_norm_inf(qp.A, r), [&] { c.complementarity_at = r; });
  }
  if constexpr (!kLocate) {
    if (!(nonfinite == 0.0)) c.primal = c.dual = std::numeric_limits<double>::infinity();
  }
  return c;
}

#if defined(__SSE2__)
// measure<true, false, 2, 6> with two joints (or the two rows) per SSE2 register: the paper's case, every step. Each
// sum adds the same terms in the same order as measure's (row r's J x over the joints in order; J'y over the rows in
// order), and maxima are exact, so the figures are measure's, bit for bit (CertificateTest checks it).
REDRES_HOT Certificate measure_6x2_sse2(const QpProblem& qp, const SolverResult& answer, double absolute,
                                        double relative) {
  Certificate c;
  const double* J = qp.J.data();  // column-major 2 x 6: joint i's column is J[2i], J[2i+1]
  const double* x = answer.x.data();
  const double* y = answer.y.data();
  const __m128d sign = _mm_set1_pd(-0.0), zero = _mm_setzero_pd();
  const auto abs = [&](__m128d v) { return _mm_andnot_pd(sign, v); };
  const auto high = [](__m128d v) { return _mm_unpackhi_pd(v, v); };
  // Primal: both rows at once, and the bounds two joints at a time. The loops are kept rolled: the step's code then
  // fills fewer instruction-cache lines (docs/performance.md).
  const __m128d d = _mm_loadu_pd(qp.d.data());
  __m128d jx = zero, primal = zero;
#pragma GCC unroll 1
  for (int p = 0; p < 3; ++p) {
    const __m128d xs = _mm_loadu_pd(x + 2 * p);
    jx = _mm_add_pd(jx, _mm_mul_pd(_mm_loadu_pd(J + 4 * p), _mm_unpacklo_pd(xs, xs)));
    jx = _mm_add_pd(jx, _mm_mul_pd(_mm_loadu_pd(J + 4 * p + 2), _mm_unpackhi_pd(xs, xs)));
    primal = _mm_max_pd(primal, _mm_max_pd(_mm_sub_pd(_mm_loadu_pd(qp.lo.data() + 2 * p), xs),
                                           _mm_sub_pd(xs, _mm_loadu_pd(qp.hi.data() + 2 * p))));
  }
  __m128d scale = _mm_max_pd(abs(jx), abs(d));
  primal = _mm_max_pd(primal, abs(_mm_sub_pd(jx, d)));
  c.primal = std::max(_mm_cvtsd_f64(primal), _mm_cvtsd_f64(high(primal)));
  c.primal_limit = absolute + relative * std::max(_mm_cvtsd_f64(scale), _mm_cvtsd_f64(high(scale)));
  // Dual, two joints at a time.
  const __m128d active = _mm_set1_pd(c.primal_limit);
  const __m128d vy0 = _mm_set1_pd(y[0]), vy1 = _mm_set1_pd(y[1]);
  const double* w = qp.W.data();
  __m128d dual = zero, nonfinite = zero;
  scale = zero;
#pragma GCC unroll 1
  for (int p = 0; p < 3; ++p) {
    const __m128d xs = _mm_loadu_pd(x + 2 * p);
    const __m128d lo = _mm_loadu_pd(qp.lo.data() + 2 * p), hi = _mm_loadu_pd(qp.hi.data() + 2 * p);
    const __m128d ce = _mm_loadu_pd(J + 4 * p), co = _mm_loadu_pd(J + 4 * p + 2);  // joints 2p and 2p + 1
    const __m128d jy = _mm_add_pd(_mm_add_pd(zero, _mm_mul_pd(_mm_unpacklo_pd(ce, co), vy0)),
                                  _mm_mul_pd(_mm_unpackhi_pd(ce, co), vy1));
    const __m128d wx = _mm_mul_pd(_mm_set_pd(w[(2 * p + 1) * 7], w[2 * p * 7]), xs);  // W's diagonal, n = 6
    const __m128d zeta = _mm_loadu_pd(qp.zeta.data() + 2 * p);
    scale = _mm_max_pd(_mm_max_pd(scale, abs(wx)), _mm_max_pd(abs(zeta), abs(jy)));
    const __m128d g = _mm_sub_pd(_mm_add_pd(wx, zeta), jy);
    nonfinite = _mm_add_pd(nonfinite, _mm_mul_pd(g, zero));
    const __m128d at_lo = _mm_cmple_pd(_mm_sub_pd(xs, lo), active);
    const __m128d at_hi = _mm_cmple_pd(_mm_sub_pd(hi, xs), active);
    // g > 0 counts unless x is at lo, g < 0 unless at hi (a mask's zero lanes give 0).
    dual = _mm_max_pd(dual, _mm_max_pd(_mm_andnot_pd(at_lo, g), _mm_andnot_pd(at_hi, _mm_xor_pd(sign, g))));
  }
  c.dual = std::max(_mm_cvtsd_f64(dual), _mm_cvtsd_f64(high(dual)));
  c.dual_limit = absolute + relative * std::max(_mm_cvtsd_f64(scale), _mm_cvtsd_f64(high(scale)));
  if (!(_mm_cvtsd_f64(nonfinite) + _mm_cvtsd_f64(high(nonfinite)) == 0.0)) {
    c.primal = c.dual = std::numeric_limits<double>::infinity();
  }
  return c;
}
#endif

// The paper's case: diagonal W, two rows, six joints, no inequality rows.
REDRES_HOT Certificate measure_paper_case(const QpProblem& qp, const SolverResult& answer, double absolute,
                                          double relative) {
#if defined(__SSE2__)
  return measure_6x2_sse2(qp, answer, absolute, relative);
#else
  return measure<true, false, 2, 6>(qp, answer, absolute, relative);
#endif
}

// `failed` (measured without kLocate, its verdict not kSolved) with where each figure's largest term is: the path of
// a failed verdict.
[[gnu::cold, gnu::noinline]] Certificate locate(const Certificate& failed, const QpProblem& qp,
                                                const SolverResult& answer, bool w_diagonal, double absolute,
                                                double relative) {
  if (!all_finite(answer.x) || !all_finite(answer.y) || !all_finite(answer.z)) {
    Certificate c;
    c.primal = c.dual = std::numeric_limits<double>::infinity();
    return c;  // a non-finite answer is certified by nothing (primal_where kNone names it)
  }
  const Certificate c = w_diagonal ? measure<true, true>(qp, answer, absolute, relative)
                                   : measure<false, true>(qp, answer, absolute, relative);
  return c.verdict() == failed.verdict() ? c : failed;  // they differ only where the data hold a NaN
}

}  // namespace

REDRES_HOT Certificate certify(const QpProblem& qp, const SolverResult& answer, bool w_diagonal, double absolute,
                               double relative) {
  const Certificate c = !w_diagonal ? measure<false, false>(qp, answer, absolute, relative)
                        : qp.m_eq() == 2 && qp.n() == 6 && qp.m_in() == 0
                            ? measure_paper_case(qp, answer, absolute, relative)
                            : measure<true, false>(qp, answer, absolute, relative);
  if (c.verdict() == SolverStatus::kSolved) return c;
  return locate(c, qp, answer, w_diagonal, absolute, relative);
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

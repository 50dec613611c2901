/// `projection`: the paper's LVI-based numerical algorithm, eq. 15:
///   u^{k+1} = u^k - (||e(u^k)||^2 / ||phi(u^k)||^2) phi(u^k),  phi = (M' + I) e,
/// stopped when ||e(u^k)||_2 <= tolerance. It converges globally and linearly.
///
/// Choices (docs/lvi.md):
/// - The iterate u^k is not kept inside Omega, so its x may leave [lo, hi] by about the tolerance. The returned x
///   is the projection of the final iterate onto [lo, hi] (the bounds then hold exactly); the reported residual is
///   ||e|| of the iterate itself, i.e. the paper's stopping test. The engine keeps the unprojected iterate for the
///   warm start, so the sequence of iterates is exactly the paper's.
/// - Diagonal W is exploited in W x and W' e; the products are the same floating-point sums as the dense ones
///   (the skipped terms are exact zeros), so the iterates do not change. Every variant (diagonal or dense W, with
///   or without inequality rows, the unrolled 6 x 2 case) accumulates the norms and J x, J e in two partial sums
///   (even and odd joints), which shortens the dependency chains; all variants give bit-identical iterates.
/// - Warm start: u^0 is the previous solve's final iterate (after an infeasible or failed solve it is reset to 0).
///
/// No engine-specific TOML keys.

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "redres/common/hot.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/engines/projection.hpp"

// On the inner loops: no libFuzzer coverage instrumentation in the sanitizer build, which compiles everything with
// clang's -fsanitize=fuzzer-no-link (docs/fuzzing.md). The loops are arithmetic on a QP, which the fuzzers do not
// steer by its branches, and the comparison hooks made them several times slower in the tests' failed steps (up to
// 20,000 iterations each). AddressSanitizer's and UBSan's checks stay.
#if defined(__clang__)
#define REDRES_NO_COVERAGE __attribute__((no_sanitize("coverage")))
#else
#define REDRES_NO_COVERAGE
#endif

namespace redres {
namespace {

// P_[lo, hi](v) for lo <= hi, as min(max(v, lo), hi): the same value as std::clamp, without branches.
inline double box(double v, double lo, double hi) { return std::min(std::max(v, lo), hi); }

class Projection final : public LviEngine {
 public:
  explicit Projection(const SolverSettings& s) { set_settings(s); }
  std::string_view name() const override { return "projection"; }

 private:
  void do_setup(int n, int m_e, int m_i) override {
    for (Eigen::VectorXd* v : {&ux_, &rx_, &ex_, &px_}) v->setZero(n);
    for (Eigen::VectorXd* v : {&uy_, &ry_, &ey_, &py_, &ry2_, &py2_}) v->setZero(m_e);
    for (Eigen::VectorXd* v : {&uz_, &rz_, &ez_, &pz_}) v->setZero(m_i);
  }

  REDRES_HOT void do_solve(const QpProblem& qp, SolverResult& result) override {
    if (!warm()) {
      ux_.setZero();
      uy_.setZero();
      uz_.setZero();
    }
    // Eq. 15 until ||e(u)|| <= tolerance; then the answer (x projected onto the box) must pass the certificate
    // (LviEngine::certify). Where it does not (the box projection moved x, or the data's scale makes the absolute
    // test too loose), the same iteration continues from where it stopped with a test 100 times tighter, within
    // the same iteration cap. The paper's steps pass at the first test.
    const double tol2 = settings().tolerance * settings().tolerance;  // the engine's own test
    tol2_ = tol2;
    int total = 0;
    Outcome out;
    for (;;) {
      budget_ = settings().max_iterations - total;
      out = dispatch(qp);
      total += out.iterations;
      result.x = ux_.cwiseMax(qp.lo).cwiseMin(qp.hi);
      result.y = uy_;
      result.z = uz_;
      if (out.broke_down || out.e2 > tol2_ || total >= settings().max_iterations) break;
      if (certify(qp, result).verdict() == SolverStatus::kSolved) break;
      if (tol2_ < 1e-28) break;  // below rounding: the certificate reports what is left
      tol2_ *= 1e-4;
    }
    SolverInfo& info = result.info;
    info.iterations = total;
    info.residual = std::sqrt(out.e2);
    if (out.broke_down) {
      info.status = SolverStatus::kNumericalError;
      keep_diagnosis_capacity(info.diagnosis);
      info.diagnosis.clear();
      TextSink(info.diagnosis) << "eq. 15 broke down: ||phi|| = 0 with ||e|| = " << info.residual;
    } else {
      info.status = out.e2 <= tol2 ? SolverStatus::kSolved : SolverStatus::kMaxIterations;
    }
  }

  struct Outcome {
    int iterations = 0;
    double e2 = 0.0;
    bool broke_down = false;
  };

  // The variants differ only in which loops exist; each performs the same floating-point operations in the same
  // order, so the iterates are identical.
  Outcome dispatch(const QpProblem& qp) {
    if (w_diagonal() && qp.m_in() == 0 && qp.m_eq() == 2 && qp.n() == 6) {
#if defined(__SSE2__)
      return iterate_6x2_sse2(qp);  // the paper's case: two joints per SSE2 register
#else
      return iterate<true, false, 2, 6>(qp);  // the paper's case: every loop unrolls
#endif
    }
    if (w_diagonal() && qp.m_in() == 0 && qp.m_eq() == 2) return iterate<true, false, 2>(qp);
    if (w_diagonal()) return qp.m_in() == 0 ? iterate<true, false>(qp) : iterate<true, true>(qp);
    return qp.m_in() == 0 ? iterate<false, false>(qp) : iterate<false, true>(qp);
  }

#if defined(__SSE2__)
  // The paper's case (diagonal W, 6 joints, 2 rows, no inequality rows) with the even and odd joints in the two
  // lanes of an SSE2 register. The lanes are exactly the even/odd partial sums of iterate<>, and every operation
  // is the same IEEE operation in the same order (max/min with the operand order of std::max/std::min), so the
  // iterates are bit-identical to the scalar variants.
  REDRES_HOT REDRES_NO_COVERAGE Outcome iterate_6x2_sse2(const QpProblem& qp) {
    const double varpi = settings().varpi;
    const double tol2 = tol2_;
    const int max_iterations = budget_;
    const double* J = qp.J.data();  // column-major 2 x 6
    __m128d j0[3], j1[3], w[3], zeta[3], lo[3], hi[3], x[3];
    for (int p = 0; p < 3; ++p) {
      const __m128d ce = _mm_loadu_pd(J + 4 * p);      // (J_0,2p,   J_1,2p)
      const __m128d co = _mm_loadu_pd(J + 4 * p + 2);  // (J_0,2p+1, J_1,2p+1)
      j0[p] = _mm_unpacklo_pd(ce, co);
      j1[p] = _mm_unpackhi_pd(ce, co);
      w[p] = _mm_set_pd(qp.W(2 * p + 1, 2 * p + 1), qp.W(2 * p, 2 * p));
      zeta[p] = _mm_loadu_pd(qp.zeta.data() + 2 * p);
      lo[p] = _mm_loadu_pd(qp.lo.data() + 2 * p);
      hi[p] = _mm_loadu_pd(qp.hi.data() + 2 * p);
      x[p] = _mm_loadu_pd(ux_.data() + 2 * p);
    }
    const double d0 = qp.d(0), d1 = qp.d(1);
    double y0 = uy_(0), y1 = uy_(1);
    const __m128d zero = _mm_setzero_pd();
    Outcome out;
    int k = 0;
    for (;; ++k) {
      // r = M u + g.
      const __m128d vy0 = _mm_set1_pd(y0), vy1 = _mm_set1_pd(y1);
      __m128d ry0 = _mm_set_pd(0.0, -d0), ry1 = _mm_set_pd(0.0, -d1);
      __m128d rx[3];
      for (int p = 0; p < 3; ++p) {
        const __m128d wx = _mm_mul_pd(w[p], x[p]);
        const __m128d jty = _mm_add_pd(_mm_add_pd(zero, _mm_mul_pd(j0[p], vy0)), _mm_mul_pd(j1[p], vy1));
        ry0 = _mm_add_pd(ry0, _mm_mul_pd(j0[p], x[p]));
        ry1 = _mm_add_pd(ry1, _mm_mul_pd(j1[p], x[p]));
        rx[p] = _mm_add_pd(_mm_add_pd(_mm_sub_pd(wx, jty), zero), zeta[p]);
      }
      const double r0 = _mm_cvtsd_f64(ry0) + _mm_cvtsd_f64(_mm_unpackhi_pd(ry0, ry0));
      const double r1 = _mm_cvtsd_f64(ry1) + _mm_cvtsd_f64(_mm_unpackhi_pd(ry1, ry1));
      // e = u - P_Omega(u - r).
      __m128d ex[3], e2v = zero;
      for (int p = 0; p < 3; ++p) {
        const __m128d v = _mm_sub_pd(x[p], rx[p]);
        ex[p] = _mm_sub_pd(x[p], _mm_min_pd(hi[p], _mm_max_pd(lo[p], v)));
        e2v = _mm_add_pd(e2v, _mm_mul_pd(ex[p], ex[p]));
      }
      double e2 = _mm_cvtsd_f64(e2v) + _mm_cvtsd_f64(_mm_unpackhi_pd(e2v, e2v));
      const double ey0 = y0 - box(y0 - r0, -varpi, varpi);
      e2 += ey0 * ey0;
      const double ey1 = y1 - box(y1 - r1, -varpi, varpi);
      e2 += ey1 * ey1;
      out.e2 = e2;
      if (e2 <= tol2 || k >= max_iterations) break;
      // phi = (M' + I) e.
      const __m128d vey0 = _mm_set1_pd(ey0), vey1 = _mm_set1_pd(ey1);
      __m128d py0 = _mm_set_pd(0.0, ey0), py1 = _mm_set_pd(0.0, ey1), p2v = zero, px[3];
      for (int p = 0; p < 3; ++p) {
        const __m128d we = _mm_mul_pd(w[p], ex[p]);
        const __m128d jte = _mm_add_pd(_mm_add_pd(zero, _mm_mul_pd(j0[p], vey0)), _mm_mul_pd(j1[p], vey1));
        py0 = _mm_sub_pd(py0, _mm_mul_pd(j0[p], ex[p]));
        py1 = _mm_sub_pd(py1, _mm_mul_pd(j1[p], ex[p]));
        px[p] = _mm_add_pd(_mm_sub_pd(_mm_add_pd(we, jte), zero), ex[p]);
        p2v = _mm_add_pd(p2v, _mm_mul_pd(px[p], px[p]));
      }
      double p2 = _mm_cvtsd_f64(p2v) + _mm_cvtsd_f64(_mm_unpackhi_pd(p2v, p2v));
      const double q0 = _mm_cvtsd_f64(py0) + _mm_cvtsd_f64(_mm_unpackhi_pd(py0, py0));
      p2 += q0 * q0;
      const double q1 = _mm_cvtsd_f64(py1) + _mm_cvtsd_f64(_mm_unpackhi_pd(py1, py1));
      p2 += q1 * q1;
      if (!(p2 > 0.0) || !std::isfinite(p2)) {
        out.broke_down = true;
        break;
      }
      const double step = e2 / p2;
      const __m128d vstep = _mm_set1_pd(step);
      for (int p = 0; p < 3; ++p) x[p] = _mm_sub_pd(x[p], _mm_mul_pd(vstep, px[p]));
      y0 -= step * q0;
      y1 -= step * q1;
    }
    for (int p = 0; p < 3; ++p) _mm_storeu_pd(ux_.data() + 2 * p, x[p]);
    uy_(0) = y0;
    uy_(1) = y1;
    out.iterations = k;
    return out;
  }
#endif

  template <bool kDiagonal, bool kInequalities, int kRows = 0, int kCols = 0>
  REDRES_HOT REDRES_NO_COVERAGE Outcome iterate(const QpProblem& qp) {
    const int n = kCols > 0 ? kCols : qp.n(), me = kRows > 0 ? kRows : qp.m_eq(), mi = kInequalities ? qp.m_in() : 0;
    const double varpi = settings().varpi;
    const double tol2 = tol2_;
    const int max_iterations = budget_;
    const double* __restrict W = qp.W.data();
    const double* __restrict J = qp.J.data();
    const double* __restrict A = qp.A.data();
    const double* __restrict lo = qp.lo.data();
    const double* __restrict hi = qp.hi.data();
    const double* __restrict zeta = qp.zeta.data();
    const double* __restrict d = qp.d.data();
    const double* __restrict b = qp.b.data();
    double* __restrict x = ux_.data();
    double* __restrict y = uy_.data();
    double* __restrict z = uz_.data();
    double* __restrict rx = rx_.data();
    double* __restrict ry = ry_.data();
    double* __restrict ry2 = ry2_.data();
    double* __restrict py2 = py2_.data();
    double* __restrict rz = rz_.data();
    double* __restrict ex = ex_.data();
    double* __restrict ey = ey_.data();
    double* __restrict ez = ez_.data();
    double* __restrict px = px_.data();
    double* __restrict py = py_.data();
    double* __restrict pz = pz_.data();

    Outcome out;
    int k = 0;
    for (;; ++k) {
      // r = M u + g.
      for (int r = 0; r < me; ++r) {
        ry[r] = -d[r];
        ry2[r] = 0.0;
      }
      for (int r = 0; r < mi; ++r) rz[r] = b[r];
      for (int i = 0; i < n; ++i) {
        double* ry_part = (i & 1) ? ry2 : ry;                       // two partial sums halve the dependency chain
        const double* Wi = W + static_cast<std::ptrdiff_t>(i) * n;  // column i (W symmetric)
        double wx = 0.0;
        if constexpr (kDiagonal) {
          wx = Wi[i] * x[i];
        } else {
          for (int j = 0; j < n; ++j) wx += Wi[j] * x[j];
        }
        const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
        double jty = 0.0, atz = 0.0;
        for (int r = 0; r < me; ++r) {
          jty += Ji[r] * y[r];
          ry_part[r] += Ji[r] * x[i];
        }
        if constexpr (kInequalities) {
          const double* Ai = A + static_cast<std::ptrdiff_t>(i) * mi;
          for (int r = 0; r < mi; ++r) {
            atz += Ai[r] * z[r];
            rz[r] -= Ai[r] * x[i];
          }
        }
        rx[i] = wx - jty + atz + zeta[i];
      }
      for (int r = 0; r < me; ++r) ry[r] += ry2[r];
      // e = u - P_Omega(u - r).
      double e2 = 0.0, e2_odd = 0.0;
      for (int i = 0; i < n; ++i) {
        ex[i] = x[i] - box(x[i] - rx[i], lo[i], hi[i]);
        ((i & 1) ? e2_odd : e2) += ex[i] * ex[i];
      }
      e2 += e2_odd;
      for (int r = 0; r < me; ++r) {
        ey[r] = y[r] - box(y[r] - ry[r], -varpi, varpi);
        e2 += ey[r] * ey[r];
      }
      for (int r = 0; r < mi; ++r) {
        ez[r] = z[r] - box(z[r] - rz[r], 0.0, varpi);
        e2 += ez[r] * ez[r];
      }
      out.e2 = e2;
      if (e2 <= tol2 || k >= max_iterations) break;
      // phi = (M' + I) e, M' = [W' J' -A'; -J 0 0; A 0 0].
      for (int r = 0; r < me; ++r) {
        py[r] = ey[r];
        py2[r] = 0.0;
      }
      for (int r = 0; r < mi; ++r) pz[r] = ez[r];
      double p2 = 0.0, p2_odd = 0.0;
      for (int i = 0; i < n; ++i) {
        double* py_part = (i & 1) ? py2 : py;
        const double* Wi = W + static_cast<std::ptrdiff_t>(i) * n;
        double we = 0.0;
        if constexpr (kDiagonal) {
          we = Wi[i] * ex[i];
        } else {
          for (int j = 0; j < n; ++j) we += Wi[j] * ex[j];
        }
        const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
        double jte = 0.0, ate = 0.0;
        for (int r = 0; r < me; ++r) {
          jte += Ji[r] * ey[r];
          py_part[r] -= Ji[r] * ex[i];
        }
        if constexpr (kInequalities) {
          const double* Ai = A + static_cast<std::ptrdiff_t>(i) * mi;
          for (int r = 0; r < mi; ++r) {
            ate += Ai[r] * ez[r];
            pz[r] += Ai[r] * ex[i];
          }
        }
        px[i] = we + jte - ate + ex[i];
        ((i & 1) ? p2_odd : p2) += px[i] * px[i];
      }
      p2 += p2_odd;
      for (int r = 0; r < me; ++r) {
        py[r] += py2[r];
        p2 += py[r] * py[r];
      }
      for (int r = 0; r < mi; ++r) p2 += pz[r] * pz[r];
      if (!(p2 > 0.0) || !std::isfinite(p2)) {
        out.broke_down = true;
        break;
      }
      const double step = e2 / p2;
      for (int i = 0; i < n; ++i) x[i] -= step * px[i];
      for (int r = 0; r < me; ++r) y[r] -= step * py[r];
      for (int r = 0; r < mi; ++r) z[r] -= step * pz[r];
    }
    out.iterations = k;
    return out;
  }

  double tol2_ = 0.0;  // the current stopping test ||e||^2 <= tol2_
  int budget_ = 0;     // iterations left in this solve
  Eigen::VectorXd ux_, uy_, uz_, rx_, ry_, rz_, ex_, ey_, ez_, px_, py_, pz_, ry2_, py2_;
};

const bool kProjectionRegistered = engine_registry().add<ProjectionConfig>(
    "projection", "the paper's eq. 15 (linear convergence; the reference for fidelity)",
    [](const ProjectionConfig& /*config*/, const SolverSettings& s) -> std::unique_ptr<LviEngine> {
      return std::make_unique<Projection>(s);
    });

}  // namespace
}  // namespace redres

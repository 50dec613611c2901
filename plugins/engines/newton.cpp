/// `newton`: an exact, fast engine for the same LVI (docs/lvi.md). For diagonal W > 0 with equality rows and
/// bounds, eq. 14 reduces to the m_e dual unknowns y:
///   x(y) = P_[lo,hi](W^-1 (J' y - zeta)),   F(y) = J x(y) - d = 0,
/// where F is minus the gradient of the concave dual function
///   phi(y) = min_{lo <= x <= hi} x'Wx/2 + zeta'x - y'(J x - d).
/// Semismooth Newton: G = J D W^-1 J' (D selects the joints strictly inside their bounds), G delta = -F, with an
/// exact line search on phi (phi is concave and piecewise quadratic along delta, so its maximiser is found by
/// walking the breakpoints where a joint reaches a bound). Where the free joints do not span the rows (a
/// degenerate solution), G is regularised by |F| I (Levenberg-Marquardt), which vanishes at the solution. Once
/// the free set is right the step is exact, so warm-started steps take one or two iterations. At x(y), e_x(u) = 0
/// by construction and e_y(u) = F(y) while |y| < varpi, so ||e(u)||_2 = ||F(y)||_2 is the paper's stopping test;
/// the engine reports `solved` only once ||F|| <= min(tolerance, 1e-12 (1 + |d|_inf)), i.e. after the exact step,
/// so its KKT residual is tiny.
///
/// Infeasible rows make phi unbounded: the line search then finds phi increasing linearly for ever (a proof of
/// infeasibility), or y leaves [-varpi, varpi]; either way the solve is reported `infeasible`.
///
/// General path: with live inequality rows or a non-diagonal W (still symmetric positive definite), semismooth
/// Newton on the natural map of the whole LVI, u = [x; y; z], exact once its active set is right (one step warm),
/// globalised by the method of multipliers with an exact semismooth Newton inner solve (see general_solve()).
///
/// Fallback: where neither path settles (on the reduced path a step without ascent or 100 iterations; on the
/// general one multipliers past varpi, i.e. an infeasible step, or 50 outer iterations), the step is solved by
/// `projection` (eq. 15) instead, and the info's `engine` says so.
/// No engine-specific TOML keys.

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "redres/engines/newton.hpp"
#include "redres/control/engine_registry.hpp"

namespace redres {
namespace {

// P_[lo, hi](v) for lo <= hi, as min(max(v, lo), hi): the same value as std::clamp, without branches.
inline double box(double v, double lo, double hi) { return std::min(std::max(v, lo), hi); }

constexpr int kMaxNewtonIterations = 100;
constexpr int kMaxOuterIterations = 50;   // the general path's method of multipliers
constexpr int kMaxInnerIterations = 100;  // Newton steps per augmented Lagrangian minimisation

class Newton final : public LviEngine {
 public:
  explicit Newton(const SolverSettings& s) { set_settings(s); }
  std::string_view name() const override { return "newton"; }

 private:
  void do_setup(int n, int m_e, int m_i) override {
    x_.setZero(n);
    free_.assign(static_cast<std::size_t>(n), 0);
    v_.setZero(n);
    jtd_.setZero(n);
    x1_.setZero(n);
    v1_.setZero(n);
    F1_.setZero(m_e);
    inv_w_.setZero(n);
    w_diag_.setZero(n);
    dv_.setZero(n);
    breaks_.assign(2 * static_cast<std::size_t>(n), 0.0);
    y_.setZero(m_e);
    F_.setZero(m_e);
    delta_.setZero(m_e);
    row_scale_.setZero(m_e);
    G_.setZero(m_e, m_e);
    L_.setZero(m_e, m_e);
    const int N = n + m_e + m_i;
    M_.setZero(N, N);
    K_.setZero(N, N);
    lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(N);
    u_.setZero(N);
    mu_.setZero(N);
    e_.setZero(N);
    rhs_.setZero(N);
    du_.setZero(N);
    lo_u_.setZero(N);
    hi_u_.setZero(N);
    trial_.setZero(N);
    const int R = m_e + m_i + n;
    Ct_.setZero(n, R);
    row_lo_.setZero(R);
    row_hi_.setZero(R);
    rho_.setZero(R);
    lambda_.setZero(R);
    s_.setZero(R);
    delta_r_.setZero(R);
    breaks_ab_.assign(2 * static_cast<std::size_t>(R), 0.0);
    xa_.setZero(n);
    ga_.setZero(n);
    dxa_.setZero(n);
    wx_.setZero(n);
    wdx_.setZero(n);
    // Sized by a factorisation (LLT(n) leaves its status uninitialised, and copying that is undefined).
    ha_.setIdentity(n, n);
    llt_.compute(ha_);
    fallback_ = make_engine("projection", settings());
    fallback_result_.x.resize(0);
    fallback_->setup(n, m_e, m_i, fallback_result_);
  }

  // Number of rows: fixed at compile time for planar position tasks (kRows = 2), else m_e.
  template <int kRows>
  static int rows(const QpProblem& qp) {
    return kRows > 0 ? kRows : qp.m_eq();
  }

  // x(y), v(y), the free set, F(y) = J x(y) - d, G = J D W^-1 J' over the free joints (lower triangle, in G_) and
  // full_scale_ = the largest diagonal entry of J W^-1 J' (all joints), in one pass over the joints; returns |F|^2.
  template <int kRows>
  double evaluate(const QpProblem& qp) {
    const int n = qp.n(), me = rows<kRows>(qp);
    const double* __restrict J = qp.J.data();
    const double* __restrict zeta = qp.zeta.data();
    const double* __restrict lo = qp.lo.data();
    const double* __restrict hi = qp.hi.data();
    const double* __restrict inv_w = inv_w_.data();
    const double* __restrict y = y_.data();
    double* __restrict v = v_.data();
    double* __restrict x = x_.data();
    char* __restrict free_mask = free_.data();
    double* __restrict F = F_.data();
    double* __restrict G = G_.data();
    if constexpr (kRows == 2) {
      // The same sums as the general loops below, kept in registers.
      const double y0 = y[0], y1 = y[1];
      double f0 = -qp.d(0), f1 = -qp.d(1), g00 = 0.0, g10 = 0.0, g11 = 0.0, s0 = 0.0, s1 = 0.0;
      for (int i = 0; i < n; ++i) {
        const double j0 = J[2 * i], j1 = J[2 * i + 1], iw = inv_w[i];
        const double vi = (j0 * y0 + j1 * y1 - zeta[i]) * iw;
        const double xi = box(vi, lo[i], hi[i]);
        const bool is_free = (vi > lo[i]) & (vi < hi[i]);
        v[i] = vi;
        x[i] = xi;
        free_mask[i] = static_cast<char>(is_free);
        f0 += j0 * xi;
        f1 += j1 * xi;
        // Clamped joints add zero; no branch on the free set.
        const double fw = is_free ? iw : 0.0;
        g00 += j0 * j0 * fw;
        g10 += j1 * j0 * fw;
        g11 += j1 * j1 * fw;
        s0 += j0 * j0 * iw;
        s1 += j1 * j1 * iw;
      }
      F[0] = f0;
      F[1] = f1;
      G[0] = g00;
      G[1] = g10;
      G[3] = g11;
      full_scale_ = std::max(s0, s1);
      return f0 * f0 + f1 * f1;
    }
    for (int r = 0; r < me; ++r) F[r] = -qp.d(r);
    G_.setZero();
    double* __restrict scale = row_scale_.data();
    for (int r = 0; r < me; ++r) scale[r] = 0.0;
    for (int i = 0; i < n; ++i) {
      const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
      const double iw = inv_w[i];
      double jty = 0.0;
      for (int r = 0; r < me; ++r) jty += Ji[r] * y[r];
      const double vi = (jty - zeta[i]) * iw;
      const double xi = box(vi, lo[i], hi[i]);
      const bool is_free = (vi > lo[i]) & (vi < hi[i]);
      v[i] = vi;
      x[i] = xi;
      free_mask[i] = static_cast<char>(is_free);
      const double fw = is_free ? iw : 0.0;
      for (int r = 0; r < me; ++r) {
        F[r] += Ji[r] * xi;
        scale[r] += Ji[r] * Ji[r] * iw;
      }
      for (int c = 0; c < me; ++c) {
        for (int r = c; r < me; ++r) G[r + c * me] += Ji[r] * Ji[c] * fw;
      }
    }
    full_scale_ = 0.0;
    double f2 = 0.0;
    for (int r = 0; r < me; ++r) {
      full_scale_ = std::max(full_scale_, scale[r]);
      f2 += F[r] * F[r];
    }
    return f2;
  }

  // Solves (G + (reg + prox) I) delta = -F, with G from evaluate(). Without `prox`, false if a pivot is not clearly
  // positive (the free joints do not span the rows).
  template <int kRows>
  bool solve_newton_system(const QpProblem& qp, double prox) {
    const int me = rows<kRows>(qp);
    const double full_scale = full_scale_;
    const double reg = 1e-13 * (1.0 + full_scale) + prox * full_scale;
    const bool check = prox == 0.0;
    // A pivot lost to cancellation (below 1e-8 of its diagonal entry) means the free joints (nearly) do not span
    // the rows. The test is on pivot / scale, written without the division (scale > 0).
    const auto pivot_ok = [&](double pivot, double diag, double scale) {
      return (!check || pivot > (1e-8 * diag + 1e-10 * full_scale) * scale) && pivot > 0.0;
    };
    if constexpr (kRows == 2) {
      // Two rows: the same pivots as the Cholesky below (a, then the Schur complement det / a), solved in closed
      // form with one division instead of two square roots and four divisions.
      const double a = G_(0, 0) + reg, b = G_(1, 0), c = G_(1, 1) + reg;
      const double det = a * c - b * b;
      if (!pivot_ok(a, a, 1.0) || !pivot_ok(det, c, a)) return false;
      const double inv = 1.0 / det;
      delta_(0) = (-F_(0) * c + F_(1) * b) * inv;
      delta_(1) = (-F_(1) * a + F_(0) * b) * inv;
      return true;
    }
    // Cholesky L L' = G + reg I in L_ (lower triangle); G_ is kept for a regularised retry.
    for (int c = 0; c < me; ++c) {
      for (int r = c; r < me; ++r) L_(r, c) = G_(r, c) + (r == c ? reg : 0.0);
    }
    for (int c = 0; c < me; ++c) {
      const double diag_entry = L_(c, c);
      double diag = diag_entry;
      for (int k = 0; k < c; ++k) diag -= L_(c, k) * L_(c, k);
      if (!pivot_ok(diag, diag_entry, 1.0)) return false;
      const double l = std::sqrt(diag);
      L_(c, c) = l;
      for (int r = c + 1; r < me; ++r) {
        double t = L_(r, c);
        for (int k = 0; k < c; ++k) t -= L_(r, k) * L_(c, k);
        L_(r, c) = t / l;
      }
    }
    for (int r = 0; r < me; ++r) {  // L w = -F
      double t = -F_(r);
      for (int k = 0; k < r; ++k) t -= L_(r, k) * delta_(k);
      delta_(r) = t / L_(r, r);
    }
    for (int r = me - 1; r >= 0; --r) {  // L' delta = w
      double t = delta_(r);
      for (int k = r + 1; k < me; ++k) t -= L_(k, r) * delta_(k);
      delta_(r) = t / L_(r, r);
    }
    return true;
  }

  // phi'(s) along y + s delta: -delta . F(y + s delta) = sum_i -(J' delta)_i x_i(s) + delta . d, with
  // x_i(s) = P(v_i + s dv_i); piecewise linear and nonincreasing in s.
  double slope_at(const QpProblem& qp, double s) const {
    double out = delta_.dot(qp.d);
    for (int i = 0; i < qp.n(); ++i) {
      out -= jtd_(i) * box(v_(i) + s * dv_(i), qp.lo(i), qp.hi(i));
    }
    return out;
  }

  // The exact maximiser of the concave, piecewise quadratic phi along delta (phi' is piecewise linear between the
  // breakpoints where some v_i crosses a bound). Returns +inf when phi' stays positive for ever: the dual is then
  // unbounded, which proves that J x = d cannot be met inside the bounds.
  template <int kRows>
  double exact_step(const QpProblem& qp) {
    const int n = qp.n(), me = rows<kRows>(qp);
    const double* __restrict J = qp.J.data();
    const double* __restrict lo = qp.lo.data();
    const double* __restrict hi = qp.hi.data();
    const double* __restrict inv_w = inv_w_.data();
    const double* __restrict delta = delta_.data();
    const double* __restrict v = v_.data();
    double* __restrict jtd_out = jtd_.data();
    double* __restrict dv = dv_.data();
    double* __restrict v1 = v1_.data();
    double* __restrict x1 = x1_.data();
    double* __restrict F1 = F1_.data();
    // The usual case: no joint changes status between s = 0 and the full Newton step s = 1 (v is linear in s,
    // so equal status at both ends means no crossing); phi' is then linear on [0, 1] and its root is at s = 1 up
    // to rounding. Checked without divisions or sorting, in the same pass that computes x, v and F at s = 1, so
    // that a full step needs no re-evaluation.
    bool same_status = true;
    for (int r = 0; r < me; ++r) F1[r] = -qp.d(r);
    for (int i = 0; i < n; ++i) {
      const double* Ji = J + static_cast<std::ptrdiff_t>(i) * me;
      double jtd = 0.0;
      for (int r = 0; r < me; ++r) jtd += Ji[r] * delta[r];
      jtd_out[i] = jtd;
      const double dvi = jtd * inv_w[i];
      const double v0i = v[i], v1i = v0i + dvi;
      dv[i] = dvi;
      v1[i] = v1i;
      const double x1i = box(v1i, lo[i], hi[i]);
      x1[i] = x1i;
      for (int r = 0; r < me; ++r) F1[r] += Ji[r] * x1i;
      // Status -1 (at lo), 0 (free), +1 (at hi), computed without branches (the pattern varies by problem).
      const int s0 = static_cast<int>(v0i >= hi[i]) - static_cast<int>(v0i <= lo[i]);
      const int s1 = static_cast<int>(v1i >= hi[i]) - static_cast<int>(v1i <= lo[i]);
      same_status &= s0 == s1;
    }
    double g0 = 0.0, g1 = 0.0;
    for (int r = 0; r < me; ++r) {
      g0 -= delta[r] * F_(r);
      g1 -= delta[r] * F1[r];
    }
    full_step_ready_ = false;
    if (!(g0 > 0.0)) return 0.0;
    if (same_status && g1 < g0) {
      // phi' is linear on [0, 1]; its root g0 / (g0 - g1) is s = 1 up to the regularisation and rounding (g1 is
      // then tiny, of either sign): take the full step.
      const double step = g0 / (g0 - g1);
      if (std::abs(step - 1.0) <= 1e-9) {
        full_step_ready_ = true;
        return 1.0;
      }
      if (g1 <= 0.0) return step;  // the root lies inside [0, 1]
    }
    int count = 0;
    for (int i = 0; i < n; ++i) {
      if (dv_(i) == 0.0) continue;
      for (const double bound : {qp.lo(i), qp.hi(i)}) {
        const double s = (bound - v_(i)) / dv_(i);
        if (std::isfinite(s) && s > 0.0) breaks_[static_cast<std::size_t>(count++)] = s;
      }
    }
    std::sort(breaks_.begin(), breaks_.begin() + count);
    double s0 = 0.0;
    double g_prev = g0;
    for (int k = 0; k <= count; ++k) {
      // Beyond the last breakpoint phi' is linear for ever; probe it one unit further.
      const double s1 = k < count ? breaks_[static_cast<std::size_t>(k)] : s0 + std::max(1.0, s0);
      if (s1 <= s0) continue;
      const double g_next = slope_at(qp, s1);
      if (g_next <= 0.0) return s0 + (s1 - s0) * g_prev / (g_prev - g_next);  // root of the linear piece
      if (k == count && !(g_next < g_prev * (1.0 - 1e-12))) return std::numeric_limits<double>::infinity();
      if (k == count) return s1 + (s1 - s0) * g_next / (g_prev - g_next);
      s0 = s1;
      g_prev = g_next;
    }
    return s0;
  }

  void run_fallback(const QpProblem& qp, SolverResult& result) {
    fallback_->solve(qp, fallback_result_);
    result.x = fallback_result_.x;
    result.y = fallback_result_.y;
    result.z = fallback_result_.z;
    // Field by field, so that result.info.diagnosis keeps the capacity reserved at setup (no allocation).
    const SolverInfo& fb = fallback_result_.info;
    result.info.status = fb.status;
    result.info.iterations = fb.iterations;
    result.info.residual = fb.residual;
    result.info.engine = fb.engine;  // names "projection" as the engine that ran
    if (!fb.diagnosis.empty()) result.info.diagnosis = fb.diagnosis;
    y_ = result.y;
  }

  // The general path, for inequality rows and any symmetric positive definite W, on the whole LVI u = [x; y; z].
  //  1. The exact step, on the natural map e(u) = u - P_Omega(u - (M u + g)): with D the components where
  //     u - (M u + g) lies strictly inside Omega, (I - D + D M) du = -e moves a component on a bound to it and makes
  //     a free one's row of M u + g vanish. e is piecewise linear, so once the active set is right this step lands
  //     on the solution (exact_step_lands()). Warm starts usually land at once.
  //  2. Where it does not land, the active set is found by the method of multipliers (augmented_lagrangian()):
  //     every constraint, the bounds included, becomes a row c_r x in [l_r, h_r] with a multiplier lambda_r, and
  //     each outer iteration minimises the augmented Lagrangian
  //       L(x) = x'Wx/2 + zeta'x + sum_r rho_r/2 dist(c_r x + lambda_r / rho_r, [l_r, h_r])^2,
  //     a strictly convex, continuously differentiable, piecewise quadratic function, by semismooth Newton with an
  //     exact line search (its Hessian W + sum over rows outside their interval of rho_r c_r c_r' is positive
  //     definite, and the minimiser along a direction is found by walking the breakpoints). That inner iteration
  //     ends exactly, when a full Newton step keeps every row's side; then lambda_r <- rho_r (s_r - P(s_r)). The
  //     method converges for every convex QP with a solution (no constraint qualification needed), and after each
  //     outer iteration step 1 is tried from u = [x; -lambda_J; lambda_A], so the answer is exact.
  // Returns false (and the caller falls back to projection) when the multipliers grow past varpi (no solution:
  // the rows cannot be met inside the bounds) or the iteration caps are reached.
  bool general_solve(const QpProblem& qp, SolverResult& result) {
    const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
    const double varpi = settings().varpi;
    // M's blocks that hold data are written here; the zero block [y; z] x [y; z] stays as setup left it.
    M_.topLeftCorner(n, n) = qp.W;
    M_.block(0, n, n, me) = -qp.J.transpose();
    M_.block(0, n + me, n, mi) = qp.A.transpose();
    M_.block(n, 0, me, n) = qp.J;
    M_.block(n + me, 0, mi, n) = -qp.A;
    lo_u_.head(n) = qp.lo;
    hi_u_.head(n) = qp.hi;
    lo_u_.segment(n, me).setConstant(-varpi);
    hi_u_.segment(n, me).setConstant(varpi);
    lo_u_.tail(mi).setZero();
    hi_u_.tail(mi).setConstant(varpi);
    int iterations = 0;
    if (warm()) {
      u_.head(n) = result.x;
      u_.segment(n, me) = result.y;
      u_.tail(mi) = result.z;
    } else {
      // Cold: the reduced path's solution for W's diagonal, without the inequality rows (exact when W is
      // diagonal and the rows are slack), as the start: it puts the duals of J x = d near their values.
      for (int i = 0; i < n; ++i) {
        w_diag_(i) = qp.W(i, i);
        inv_w_(i) = 1.0 / w_diag_(i);
      }
      y_.setZero();
      double f2 = 0.0;
      (void)reduced_iterate<0>(qp, iterations, f2);
      u_.setZero();
      u_.head(n) = x_;
      u_.segment(n, me) = y_;
    }
    set_norms(qp);
    const auto solved = [&](double e2) {
      result.x = u_.head(n).cwiseMax(qp.lo).cwiseMin(qp.hi);
      result.y = u_.segment(n, me);
      result.z = u_.tail(mi);
      result.info.status = SolverStatus::kSolved;
      result.info.iterations = iterations;
      result.info.residual = std::sqrt(e2);
      return true;
    };
    double e2 = natural_residual2(qp, u_);
    if (std::sqrt(e2) <= target_at(u_)) return solved(e2);
    ++iterations;
    if (exact_step_lands(qp, e2)) return solved(e2);
    return augmented_lagrangian(qp, iterations) && (e2 = natural_residual2(qp, u_), solved(e2));
  }

  // Infinity norms of W, J, J', A and A' for target_at(), once per solve (loops: no temporaries).
  void set_norms(const QpProblem& qp) {
    const auto row_sums = [](const Eigen::MatrixXd& m, bool transposed) {
      double best = 0.0;
      const Eigen::Index outer = transposed ? m.cols() : m.rows(), inner = transposed ? m.rows() : m.cols();
      for (Eigen::Index i = 0; i < outer; ++i) {
        double sum = 0.0;
        for (Eigen::Index k = 0; k < inner; ++k) sum += std::abs(transposed ? m(k, i) : m(i, k));
        best = std::max(best, sum);
      }
      return best;
    };
    norm_w_ = row_sums(qp.W, false);
    norm_j_ = row_sums(qp.J, false);
    norm_jt_ = row_sums(qp.J, true);
    norm_a_ = row_sums(qp.A, false);
    norm_at_ = row_sums(qp.A, true);
    data_scale_ = std::max({qp.zeta.lpNorm<Eigen::Infinity>(), qp.m_eq() > 0 ? qp.d.lpNorm<Eigen::Infinity>() : 0.0,
                            qp.m_in() > 0 ? qp.b.lpNorm<Eigen::Infinity>() : 0.0});
  }

  // The general path's accuracy at w = [x; y; z]: min(tolerance, 1e-12 s) with s the size of the terms the
  // residual adds up there, 1 + max(|zeta|, |d|, |b|, |W||x| + |J'||y| + |A'||z|, |J||x|, |A||x|) (infinity
  // norms): rounding alone leaves about 1e-16 s, so a large W or large multipliers raise the bar accordingly.
  double target_at(const Eigen::VectorXd& w) const {
    const Eigen::Index n = xa_.size(), me = y_.size();
    const Eigen::Index mi = w.size() - n - me;
    const double x = w.head(n).lpNorm<Eigen::Infinity>();
    const double y = me > 0 ? w.segment(n, me).lpNorm<Eigen::Infinity>() : 0.0;
    const double z = mi > 0 ? w.tail(mi).lpNorm<Eigen::Infinity>() : 0.0;
    const double terms = std::max({data_scale_, norm_w_ * x + norm_jt_ * y + norm_at_ * z, norm_j_ * x, norm_a_ * x});
    return std::min(settings().tolerance, 1e-12 * (1.0 + terms));
  }

  // Step 1 of general_solve() from u_ (natural_residual2(u_) just computed, so mu_ and e_ hold its values): on
  // landing (||e|| <= target_at() there), moves u_ to u_ + du, leaves ||e||^2 in e2 and returns true.
  bool exact_step_lands(const QpProblem& qp, double& e2) {
    const Eigen::Index N = u_.size();
    for (Eigen::Index i = 0; i < N; ++i) {
      const double v = u_(i) - mu_(i);
      if (v > lo_u_(i) && v < hi_u_(i)) {
        K_.row(i) = M_.row(i);
        rhs_(i) = -mu_(i);
      } else {
        K_.row(i).setZero();
        K_(i, i) = 1.0;
        rhs_(i) = -e_(i);
      }
    }
    lu_.compute(K_);
    if (!(std::abs(lu_.matrixLU().diagonal().prod()) > 0.0)) return false;  // singular: no step
    du_.noalias() = lu_.solve(rhs_);
    if (!du_.allFinite()) return false;
    trial_ = u_ + du_;
    const double landed = natural_residual2(qp, trial_);
    if (!(std::sqrt(landed) <= target_at(trial_))) return false;
    u_.swap(trial_);
    e2 = landed;
    return true;
  }

  // s_r - P_[l_r, h_r](s_r): how far s_r lies outside its interval (signed).
  double excess(int r, double s) const { return s - box(s, row_lo_(r), row_hi_(r)); }

  // Step 2 of general_solve(): the method of multipliers from u_, trying step 1 after each outer iteration.
  // Rows r: J (m_e, l = h = d), A (m_i, l = -inf, h = b), then the bounds (n, the identity).
  bool augmented_lagrangian(const QpProblem& qp, int& iterations) {
    const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in(), R = me + mi + n;
    Ct_.leftCols(me) = qp.J.transpose();
    Ct_.middleCols(me, mi) = qp.A.transpose();
    Ct_.rightCols(n).setIdentity();
    row_lo_.head(me) = qp.d;
    row_hi_.head(me) = qp.d;
    row_lo_.segment(me, mi).setConstant(-std::numeric_limits<double>::infinity());
    row_hi_.segment(me, mi) = qp.b;
    row_lo_.tail(n) = qp.lo;
    row_hi_.tail(n) = qp.hi;
    // rho_r = rho / |c_r|^2, rho a large multiple of W's scale: the outer iteration contracts the multipliers'
    // error by about 1 / (1 + rho sigma), while the inner Hessian W + rho C'C stays well conditioned (see the cap
    // below).
    const double rho = 1e4 * qp.W.diagonal().cwiseAbs().maxCoeff();
    for (int r = 0; r < R; ++r) {
      const double c2 = Ct_.col(r).squaredNorm();
      rho_(r) = c2 > 0.0 ? rho / c2 : 0.0;
    }
    rho_scale_ = 1.0;
    // Multipliers from u_: lambda_J = -y, lambda_A = z, and the bounds' from stationarity, on a finite side only.
    xa_ = u_.head(n);
    lambda_.head(me) = -u_.segment(n, me);
    lambda_.segment(me, mi) = u_.tail(mi);
    ga_.noalias() = qp.W * xa_;
    ga_ += qp.zeta;
    ga_.noalias() -= qp.J.transpose() * u_.segment(n, me);
    ga_.noalias() += qp.A.transpose() * u_.tail(mi);
    for (int i = 0; i < n; ++i) {
      const double l = -ga_(i);
      lambda_(me + mi + i) = (l > 0.0 && std::isfinite(qp.hi(i))) || (l < 0.0 && std::isfinite(qp.lo(i))) ? l : 0.0;
    }
    const double varpi = settings().varpi;
    double last_violation = std::numeric_limits<double>::infinity();
    for (int outer = 0; outer < kMaxOuterIterations; ++outer) {
      if (!minimise_augmented_lagrangian(qp, iterations)) return false;
      // lambda_r <- rho_r (s_r - P(s_r)) at the minimiser.
      double violation = 0.0;
      for (int r = 0; r < R; ++r) {
        const double cx = Ct_.col(r).dot(xa_);
        violation = std::max(violation, std::abs(excess(r, cx)));
        lambda_(r) = rho_(r) * excess(r, cx + (rho_(r) > 0.0 ? lambda_(r) / rho_(r) : 0.0));
        // Runaway duals of the rows (y, z; the LVI bounds them by varpi): the rows cannot be met. The bounds'
        // multipliers are not duals of the LVI (Omega clips x instead) and may be as large as the data make them.
        if (r < me + mi && !(std::abs(lambda_(r)) <= varpi)) return false;
      }
      u_.head(n) = xa_;
      u_.segment(n, me) = -lambda_.head(me);
      u_.tail(mi) = lambda_.segment(me, mi);
      const double target = target_at(u_);
      // Where the violation does not shrink fast (large multipliers at a nearly degenerate solution, which the
      // update approaches by rho * violation per iteration), raise the penalties tenfold, up to 1e6 times (the inner
      // Hessian's conditioning grows with them), and only while the violation is above the accuracy sought.
      if (violation > 0.25 * last_violation && violation > target && rho_scale_ < 1e6) {
        rho_ *= 10.0;
        rho_scale_ *= 10.0;
      }
      last_violation = violation;
      double e2 = natural_residual2(qp, u_);
      if (std::sqrt(e2) <= target) return true;
      ++iterations;
      if (exact_step_lands(qp, e2)) return true;
    }
    return false;
  }

  // Minimises the augmented Lagrangian over x from xa_ (semismooth Newton, exact line search); true when a full
  // step kept every row on its side, i.e. xa_ is the exact minimiser.
  bool minimise_augmented_lagrangian(const QpProblem& qp, int& iterations) {
    const int R = static_cast<int>(rho_.size());
    for (int inner = 0; inner < kMaxInnerIterations; ++inner, ++iterations) {
      // Gradient W x + zeta + sum_r c_r rho_r excess_r and Hessian W + sum_{r outside} rho_r c_r c_r'.
      ga_.noalias() = qp.W * xa_;
      ga_ += qp.zeta;
      ha_ = qp.W;
      for (int r = 0; r < R; ++r) {
        const double s = Ct_.col(r).dot(xa_) + (rho_(r) > 0.0 ? lambda_(r) / rho_(r) : 0.0);
        s_(r) = s;
        const double ex = excess(r, s);
        if (ex != 0.0) {
          ga_.noalias() += (rho_(r) * ex) * Ct_.col(r);
          ha_.selfadjointView<Eigen::Lower>().rankUpdate(Ct_.col(r), rho_(r));  // LLT reads the lower triangle
        }
      }
      llt_.compute(ha_);
      if (llt_.info() != Eigen::Success) return false;
      dxa_.noalias() = llt_.solve(ga_);
      dxa_ = -dxa_;
      if (!dxa_.allFinite()) return false;
      // phi'(t) along x + t dx: a0 + t q + sum_r rho_r delta_r excess_r(s_r + t delta_r), increasing and
      // piecewise linear, with breakpoints where some s_r + t delta_r crosses l_r or h_r.
      wx_.noalias() = qp.W * xa_;
      wdx_.noalias() = qp.W * dxa_;
      const double a0 = dxa_.dot(wx_) + dxa_.dot(qp.zeta);
      const double q = dxa_.dot(wdx_);
      bool same_side = true;
      int count = 0;
      for (int r = 0; r < R; ++r) {
        const double delta = Ct_.col(r).dot(dxa_);
        delta_r_(r) = delta;
        const double s0 = s_(r), s1 = s0 + delta;
        const int side0 = static_cast<int>(s0 > row_hi_(r)) - static_cast<int>(s0 < row_lo_(r));
        const int side1 = static_cast<int>(s1 > row_hi_(r)) - static_cast<int>(s1 < row_lo_(r));
        same_side &= side0 == side1;
        if (delta != 0.0 && rho_(r) > 0.0) {
          for (const double bound : {row_lo_(r), row_hi_(r)}) {
            const double t = (bound - s0) / delta;
            if (std::isfinite(t) && t > 0.0) breaks_ab_[static_cast<std::size_t>(count++)] = t;
          }
        }
      }
      const auto slope = [&](double t) {
        double v = a0 + t * q;
        for (int r = 0; r < R; ++r) {
          if (delta_r_(r) != 0.0) v += rho_(r) * delta_r_(r) * excess(r, s_(r) + t * delta_r_(r));
        }
        return v;
      };
      if (same_side) {
        // The quadratic model is exact on [0, 1]: the full step reaches the minimiser.
        xa_ += dxa_;
        ++iterations;
        return true;
      }
      std::sort(breaks_ab_.begin(), breaks_ab_.begin() + count);
      double t0 = 0.0, g0 = slope(0.0), t = 0.0;
      for (int k = 0;; ++k) {
        // Past the last breakpoint phi' is linear for ever, with a positive slope (>= q > 0).
        const double t1 = k < count ? breaks_ab_[static_cast<std::size_t>(k)] : t0 + std::max(1.0, t0);
        if (t1 <= t0) continue;
        const double g1 = slope(t1);
        if (g1 >= 0.0) {
          t = g1 > g0 ? t0 + (t1 - t0) * (-g0) / (g1 - g0) : t1;
          break;
        }
        if (k >= count) {
          t = t1 + (t1 - t0) * (-g1) / (g1 - g0);
          break;
        }
        t0 = t1;
        g0 = g1;
      }
      if (!(t > 0.0) || !std::isfinite(t)) return false;
      xa_ += t * dxa_;
    }
    return false;
  }

  // ||e(w)||^2 of the natural map at w; leaves M w + g in mu_ and e(w) in e_.
  double natural_residual2(const QpProblem& qp, const Eigen::VectorXd& w) {
    const int n = qp.n(), me = qp.m_eq(), mi = qp.m_in();
    mu_.noalias() = M_ * w;
    mu_.head(n) += qp.zeta;
    mu_.segment(n, me) -= qp.d;
    mu_.tail(mi) += qp.b;
    double e2 = 0.0;
    for (Eigen::Index i = 0; i < w.size(); ++i) {
      e_(i) = w(i) - box(w(i) - mu_(i), lo_u_(i), hi_u_(i));
      e2 += e_(i) * e_(i);
    }
    return e2;
  }

  static bool slack_rows_only(const QpProblem& qp) {
    for (int r = 0; r < qp.m_in(); ++r) {
      if (!(qp.b(r) >= 0.0)) return false;
    }
    const double* a = qp.A.data();
    const Eigen::Index size = qp.A.size();
    for (Eigen::Index k = 0; k < size; ++k) {
      if (a[k] != 0.0) return false;
    }
    return true;
  }

  void do_solve(const QpProblem& qp, SolverResult& result) override {
    // Inequality rows that are all zero with b >= 0 (the slack rows collision constraints leave for pairs out of
    // range) hold for every x with z = 0, so they do not stop the exact path.
    bool applicable = qp.w_diagonal && slack_rows_only(qp);
    if (applicable) {
      // W rarely changes between steps (W = I in the paper): reuse 1 / W_ii when it has not.
      const int n = qp.n();
      const double* __restrict W = qp.W.data();
      double* __restrict w_diag = w_diag_.data();
      double* __restrict inv_w = inv_w_.data();
      for (int i = 0; i < n; ++i) {
        const double w = W[static_cast<std::ptrdiff_t>(i) * (n + 1)];
        applicable &= w > 0.0;
        if (w != w_diag[i]) {
          w_diag[i] = w;
          inv_w[i] = 1.0 / w;
        }
      }
    }
    if (!applicable) {
      if (general_solve(qp, result)) return;
      result.info.diagnosis = "newton's general path did not settle; fell back to projection";
      run_fallback(qp, result);
      return;
    }
    // Planar position tasks (2 rows) get loops of fixed length; the arithmetic is the same.
    if (qp.m_eq() == 2) {
      run<2>(qp, result);
    } else {
      run<0>(qp, result);
    }
  }

  template <int kRows>
  void run(const QpProblem& qp, SolverResult& result) {
    if (!warm()) y_.setZero();
    int k = 0;
    double f2 = 0.0;
    switch (reduced_iterate<kRows>(qp, k, f2)) {
      case Reduced::kConverged: finish(result, SolverStatus::kSolved, k, f2); return;
      case Reduced::kInfeasible: finish(result, SolverStatus::kInfeasible, k, f2); return;
      case Reduced::kStalled:
        result.info.diagnosis = "newton did not converge in " + std::to_string(k) + " iterations (residual " +
                                std::to_string(std::sqrt(f2)) + "); fell back to projection";
        run_fallback(qp, result);
        return;
    }
  }

  enum class Reduced { kConverged, kInfeasible, kStalled };

  // The reduced path's iteration from y_ (inv_w_ holds 1 / W_ii): leaves x(y), y and |F|^2 in x_, y_ and f2, the
  // iterations taken in k. kInfeasible: the dual is unbounded along a step, or y left [-varpi, varpi] (then
  // clamped back); kStalled: no ascent, a Newton system that cannot be solved, or the iteration cap.
  template <int kRows>
  Reduced reduced_iterate(const QpProblem& qp, int& k, double& f2) {
    const int me = rows<kRows>(qp);
    double d_max = 0.0;
    for (int r = 0; r < me; ++r) d_max = std::max(d_max, std::abs(qp.d(r)));
    const double varpi = settings().varpi;
    const double target = std::min(settings().tolerance, 1e-12 * (1.0 + d_max));

    f2 = evaluate<kRows>(qp);
    for (k = 0;; ++k) {
      if (f2 <= target * target) return Reduced::kConverged;
      if (k >= kMaxNewtonIterations) return Reduced::kStalled;
      // Where the free joints do not span the rows (a degenerate solution, where some v_i sits on its bound),
      // G is singular: regularise it proximally with |F| (Levenberg-Marquardt), which vanishes at the solution.
      if (!solve_newton_system<kRows>(qp, 0.0) && !solve_newton_system<kRows>(qp, std::sqrt(f2))) {
        return Reduced::kStalled;
      }
      const double step = exact_step<kRows>(qp);
      if (std::isinf(step)) {
        // phi grows linearly for ever along delta: the dual is unbounded, so J x = d cannot be met.
        ++k;
        return Reduced::kInfeasible;
      }
      if (!(step > 0.0)) return Reduced::kStalled;  // no ascent: leave it to the fallback
      bool outside = false;
      for (int r = 0; r < me; ++r) {
        y_(r) += step * delta_(r);
        outside = outside || std::abs(y_(r)) > varpi;
      }
      if (full_step_ready_) {
        // Same free set as before the step: x, v and F at the new y were computed by exact_step.
        x_.swap(x1_);
        v_.swap(v1_);
        F_.swap(F1_);
        f2 = 0.0;
        for (int r = 0; r < me; ++r) f2 += F_(r) * F_(r);
      } else {
        f2 = evaluate<kRows>(qp);
      }
      if (outside) {
        // The duals left the LVI's box: J x = d cannot be met inside the bounds.
        y_ = y_.cwiseMax(-varpi).cwiseMin(varpi);
        ++k;
        return Reduced::kInfeasible;
      }
    }
  }

  void finish(SolverResult& result, SolverStatus status, int iterations, double f2) const {
    result.info.status = status;
    result.info.iterations = iterations;
    result.info.residual = std::sqrt(f2);
    result.x = x_;
    result.y = y_;
    result.z.setZero();
  }

  double full_scale_ = 0.0;
  Eigen::VectorXd v_, x_, y_, F_, delta_, row_scale_, jtd_, dv_, inv_w_, w_diag_, x1_, v1_, F1_;
  bool full_step_ready_ = false;
  std::vector<char> free_;
  std::vector<double> breaks_;
  Eigen::MatrixXd G_, L_;
  // The general path: u = [x; y; z], M, the Newton matrix K and its LU, the natural map's pieces, Omega's bounds.
  Eigen::MatrixXd M_, K_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  Eigen::VectorXd u_, mu_, e_, rhs_, du_, lo_u_, hi_u_;
  Eigen::VectorXd trial_;
  // The method of multipliers: rows C (as C'), their intervals, penalties, multipliers, s = C x + lambda / rho, C dx;
  // x, the gradient, the Newton step and the Hessian of the augmented Lagrangian, and its Cholesky factor.
  Eigen::MatrixXd Ct_;  // the rows c_r as columns
  Eigen::VectorXd row_lo_, row_hi_, rho_, lambda_, s_, delta_r_, xa_, ga_, dxa_, wx_, wdx_;
  std::vector<double> breaks_ab_;
  double rho_scale_ = 1.0;
  double norm_w_ = 0.0, norm_j_ = 0.0, norm_jt_ = 0.0, norm_a_ = 0.0, norm_at_ = 0.0, data_scale_ = 0.0;
  Eigen::MatrixXd ha_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  std::unique_ptr<LviEngine> fallback_;
  SolverResult fallback_result_;
};

const bool kRegistered = engine_registry().add<NewtonConfig>(
    "newton", "semismooth Newton on eq. 14 (exact; equality and inequality rows, bounds, any W > 0)",
    [](const NewtonConfig& /*config*/, const SolverSettings& s) -> std::unique_ptr<LviEngine> {
      return std::make_unique<Newton>(s);
    });

}  // namespace
}  // namespace redres

/// `newton`'s exact line search on the reduced path (newton.cpp): the maximiser of the concave, piecewise quadratic
/// dual function along the Newton step, found by walking the breakpoints where a joint reaches a bound.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>

#include "newton_internal.hpp"
#include "redres/common/hot.hpp"

namespace redres::newton_internal {

// The exact maximiser of the concave, piecewise quadratic phi along delta (phi' is piecewise linear between the
// breakpoints where some v_i crosses a bound). Returns +inf when phi' stays positive for ever: the dual is then
// unbounded, which proves that J x = d cannot be met inside the bounds.
template <int kRows>
REDRES_HOT double Newton::exact_step(const QpProblem& qp) {
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
  // The walk along the breakpoints. Joint i is free (x_i = v_i + s dv_i) on an interval (a_i, b_i) of s, where
  // it adds -jtd_i dv_i = -jtd_i^2 / W_ii <= 0 to the slope of phi'; elsewhere x_i is constant. So phi' is linear
  // between breakpoints, with a slope c that changes by that amount where a joint enters or leaves its interval:
  // the events, in a heap (O(n) to build, O(log n) per event taken, and the walk stops at the root), so that the
  // search is O(n + k log n) for k events passed, not O(n^2).
  // phi'(1) = g1 is known exactly, so the walk covers one side of s = 1 only: the events in (0, 1) when the root
  // lies there (g1 <= 0), else those beyond 1, starting from s = 1 with the slope there.
  const bool before_one = g1 <= 0.0;
  const double from = before_one ? 0.0 : 1.0, to = before_one ? 1.0 : std::numeric_limits<double>::infinity();
  int count = 0;
  double c = 0.0, c_tail = 0.0;  // the slope just after `from`; the slope beyond every breakpoint (exact)
  const auto later = [](const std::pair<double, double>& p, const std::pair<double, double>& q) {
    return p.first > q.first;
  };
  for (int i = 0; i < n; ++i) {
    const double dvi = dv[i];
    if (dvi == 0.0) continue;
    const double slope = -jtd_out[i] * dvi;
    double enter = (lo[i] - v[i]) / dvi, leave = (hi[i] - v[i]) / dvi;
    if (dvi < 0.0) std::swap(enter, leave);
    if (!(leave > enter)) continue;  // lo == hi: never free
    if (enter <= from && leave > from) c += slope;
    if (enter > from && enter < to) events_[static_cast<std::size_t>(count++)] = {enter, slope};
    if (leave > from && leave < to) events_[static_cast<std::size_t>(count++)] = {leave, -slope};
    if (leave == std::numeric_limits<double>::infinity()) c_tail += slope;
  }
  const auto first = events_.begin(), last = events_.begin() + count;
  std::make_heap(first, last, later);
  double s0 = from, g_prev = before_one ? g0 : g1;
  for (auto end = last; end != first;) {
    const std::pair<double, double> event = *first;
    std::pop_heap(first, end, later);
    --end;
    const double s1 = event.first;
    if (s1 > s0) {
      const double g_next = g_prev + c * (s1 - s0);
      if (g_next <= 0.0) return s0 + (s1 - s0) * g_prev / (g_prev - g_next);  // root of the linear piece
      s0 = s1;
      g_prev = g_next;
    }
    c += event.second;
  }
  // The root lies on the last piece before s = 1, where phi'(1) = g1 <= 0.
  if (before_one) return g_prev > g1 ? s0 + (1.0 - s0) * g_prev / (g_prev - g1) : s0;
  // Beyond the last breakpoint phi' is linear for ever with the exact slope c_tail (a sum of terms <= 0, no
  // cancellation): where it does not fall by more than rounding over max(1, s0), phi grows for ever.
  if (!(-c_tail * std::max(1.0, s0) > 1e-12 * g_prev)) return std::numeric_limits<double>::infinity();
  return s0 + g_prev / -c_tail;
}

template double Newton::exact_step<0>(const QpProblem& qp);
template double Newton::exact_step<2>(const QpProblem& qp);

}  // namespace redres::newton_internal

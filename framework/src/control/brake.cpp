#include "redres/control/brake.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace redres {

BrakeScale braking_scale(const BrakeInput& in) {
  const Eigen::VectorXd& b = *in.velocity;
  const Eigen::VectorXd& a_lo = *in.acceleration_lower;
  const Eigen::VectorXd& a_hi = *in.acceleration_upper;
  const Eigen::VectorXd& v_lo = *in.velocity_lower;
  const Eigen::VectorXd& v_hi = *in.velocity_upper;
  const double tau = in.tau;
  const auto n = b.size();
  double s_lo = 0.0, s_hi = std::numeric_limits<double>::infinity();
  int decides = -1;
  // s in [lo, hi] for every joint with b_j != 0, from a bound lo_j <= (s - 1) b_j / tau <= hi_j.
  const auto within = [&](Eigen::Index j, double lo, double hi, double& s_min, double& s_max) {
    double s1 = 1.0 + tau * lo / b(j), s2 = 1.0 + tau * hi / b(j);
    if (s1 > s2) std::swap(s1, s2);
    s_min = std::max(s_min, s1);
    s_max = std::min(s_max, s2);
  };
  // A joint whose limits are not finite here (a law outside its range) or whose velocity is not finite sets nothing.
  const auto usable_joint = [&](Eigen::Index j, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi) {
    return b(j) != 0.0 && std::isfinite(b(j)) && std::isfinite(lo(j)) && std::isfinite(hi(j));
  };
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!usable_joint(j, a_lo, a_hi)) continue;
    const double before = s_lo;
    within(j, a_lo(j), a_hi(j), s_lo, s_hi);
    if (s_lo > before) decides = static_cast<int>(j);
    // The velocity limits: s b_j within [v_lo_j, v_hi_j], where b_j itself is.
    if (b(j) > 0.0 && b(j) <= v_hi(j)) s_hi = std::min(s_hi, v_hi(j) / b(j));
    if (b(j) < 0.0 && b(j) >= v_lo(j)) s_hi = std::min(s_hi, v_lo(j) / b(j));
  }
  s_hi = std::max(s_hi, s_lo);
  BrakeScale out;
  out.scale = s_lo;
  if (in.jerk_lower != nullptr && in.jerk_upper != nullptr) {
    const Eigen::VectorXd& j_lo = *in.jerk_lower;
    const Eigen::VectorXd& j_hi = *in.jerk_upper;
    // Braking never speeds the arm up: the jerk limits are kept only by a scale of at most 1.
    double lo = s_lo, hi = std::min(s_hi, std::max(1.0, s_lo));
    int jerk_decides = decides;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!usable_joint(j, j_lo, j_hi)) continue;
      // The acceleration (s - 1) b_j / tau within a_prev + tau [j^-, j^+].
      const double a_prev = ((*in.previous)(j) - (*in.previous2)(j)) / tau;
      const double before = lo;
      within(j, a_prev + tau * j_lo(j), a_prev + tau * j_hi(j), lo, hi);
      if (lo > before) jerk_decides = static_cast<int>(j);
    }
    out.jerk_yields = lo > hi;
    if (!out.jerk_yields) {
      out.scale = lo;
      decides = jerk_decides;
    }  // else the acceleration limits' scale s_lo: an arm that was accelerating faster than the jerk limits can turn
       // round in one step brakes at once
  }
  out.deciding_joint = decides;
  return out;
}

}  // namespace redres

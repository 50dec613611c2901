#include "redres/velocity_limits/push_rod.hpp"
#include "redres/common/hot.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

namespace redres {

const Schema<PushRodLawConfig>& PushRodLawConfig::schema() {
  using C = PushRodLawConfig;
  static const Schema<C> s{
      {field("a", &C::a, "m", "triangle edge a", greater(0.0)).required(),
       field("b", &C::b, "m", "triangle edge b", greater(0.0)).required(),
       field("s", &C::s, "m/rot", "push-rod elongation per motor turn", greater(0.0)).required(),
       field("sigma_min", &C::sigma_min, "rot/s", "negative motor rotation-rate limit", less(0.0)).required(),
       field("sigma_max", &C::sigma_max, "rot/s", "positive motor rotation-rate limit", greater(0.0)).required()}};
  return s;
}

REDRES_HOT VelocityBounds PushRodLaw::bounds(double theta) const {
  const double a = config_.a, b = config_.b;
  const double rate = config_.s * std::sqrt(a * a + b * b + 2.0 * a * b * std::sin(theta)) / (a * b * std::cos(theta));
  const double v_min = rate * config_.sigma_min;
  const double v_max = rate * config_.sigma_max;
  // For cos(theta) < 0 the roles of sigma^- and sigma^+ swap.
  return v_min <= v_max ? VelocityBounds{v_min, v_max} : VelocityBounds{v_max, v_min};
}

std::string PushRodLaw::describe() const {
  std::ostringstream s;
  s.precision(10);
  s << "push_rod(a=" << config_.a << " m, b=" << config_.b << " m, s=" << config_.s << " m/rot, sigma=["
    << config_.sigma_min << ", " << config_.sigma_max << "] rot/s)";
  return s.str();
}

std::optional<UndefinedAt> PushRodLaw::undefined_in(double lo, double hi) const {
  // Zeros of cos: pi/2 + k pi. The first one >= lo.
  constexpr double pi = std::numbers::pi;
  const double k = std::ceil((lo - pi / 2.0) / pi);
  const double zero = pi / 2.0 + k * pi;
  if (zero <= hi) return UndefinedAt{zero, "cos(theta) = 0, where eq. 2 divides by zero"};
  return std::nullopt;
}

namespace {
const bool kPushRodRegistered = velocity_limit_registry().add_plugin<PushRodLaw>(
    "push-rod joint, eq. 2: s sigma sqrt(a^2 + b^2 + 2ab sin(theta)) / (ab cos(theta))");
}  // namespace

}  // namespace redres

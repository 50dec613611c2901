/// `push_rod`: the push-rod joint law of eq. 2,
///   theta_dot^{+-}(theta) = s sigma^{+-} sqrt(a^2 + b^2 + 2 a b sin(theta)) / (a b cos(theta)),
/// where a, b are the triangle edges of the joint (m), s the push-rod elongation per motor turn (m/rot) and
/// sigma^{+-} the motor's rotation-rate limits (rot/s). Undefined where cos(theta) = 0, which is rejected at load
/// when the joint range reaches it.
/// TOML keys: `a` (m, > 0), `b` (m, > 0), `s` (m/rot, > 0), `sigma_min` (rot/s, < 0), `sigma_max` (rot/s, > 0).

#include <cmath>
#include <sstream>

#include "redres/velocity_limit.hpp"

namespace redres {
namespace {

constexpr double kPi = 3.14159265358979323846;

class PushRodLaw final : public VelocityLimitLaw {
 public:
  PushRodLaw(double a, double b, double s, double sigma_min, double sigma_max)
      : a_(a), b_(b), s_(s), sigma_min_(sigma_min), sigma_max_(sigma_max) {}

  VelocityBounds bounds(double theta) const override {
    const double rate = s_ * std::sqrt(a_ * a_ + b_ * b_ + 2.0 * a_ * b_ * std::sin(theta)) / (a_ * b_ * std::cos(theta));
    const double v_min = rate * sigma_min_;
    const double v_max = rate * sigma_max_;
    // For cos(theta) < 0 the roles of sigma^- and sigma^+ swap.
    return v_min <= v_max ? VelocityBounds{v_min, v_max} : VelocityBounds{v_max, v_min};
  }

  std::string type() const override { return "push_rod"; }

  std::string describe() const override {
    std::ostringstream s;
    s.precision(10);
    s << "push_rod(a=" << a_ << " m, b=" << b_ << " m, s=" << s_ << " m/rot, sigma=[" << sigma_min_ << ", "
      << sigma_max_ << "] rot/s)";
    return s.str();
  }

  std::optional<UndefinedAt> undefined_in(double lo, double hi) const override {
    // Zeros of cos: pi/2 + k pi. The first one >= lo.
    const double k = std::ceil((lo - kPi / 2.0) / kPi);
    const double zero = kPi / 2.0 + k * kPi;
    if (zero <= hi) return UndefinedAt{zero, "cos(theta) = 0, where eq. 2 divides by zero"};
    return std::nullopt;
  }

 private:
  double a_, b_, s_, sigma_min_, sigma_max_;
};

const bool kRegistered = velocity_limit_registry().add({
    "push_rod",
    "push-rod joint, eq. 2: s sigma sqrt(a^2 + b^2 + 2ab sin(theta)) / (ab cos(theta))",
    {{"a", "", "triangle edge a (m), > 0"},
     {"b", "", "triangle edge b (m), > 0"},
     {"s", "", "push-rod elongation per motor turn (m/rot), > 0"},
     {"sigma_min", "", "negative motor rotation-rate limit (rot/s), < 0"},
     {"sigma_max", "", "positive motor rotation-rate limit (rot/s), > 0"}},
    [](const TableReader& r) -> std::unique_ptr<VelocityLimitLaw> {
      const double a = r.number("a");
      const double b = r.number("b");
      const double s = r.number("s");
      const double sigma_min = r.number("sigma_min");
      const double sigma_max = r.number("sigma_max");
      if (!(a > 0.0)) r.fail("a", "expected a length > 0 m");
      if (!(b > 0.0)) r.fail("b", "expected a length > 0 m");
      if (!(s > 0.0)) r.fail("s", "expected an elongation rate > 0 m/rot");
      if (!(sigma_min < 0.0)) r.fail("sigma_min", "expected a rotation-rate limit < 0 rot/s");
      if (!(sigma_max > 0.0)) r.fail("sigma_max", "expected a rotation-rate limit > 0 rot/s");
      return std::make_unique<PushRodLaw>(a, b, s, sigma_min, sigma_max);
    },
});

}  // namespace
}  // namespace redres

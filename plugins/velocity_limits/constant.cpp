/// `constant`: theta_dot^- = lower, theta_dot^+ = upper, independent of theta.
/// TOML keys: `lower` (rad/s or m/s, < 0, required), `upper` (> 0, required).

#include <sstream>
#include <string>

#include "redres/velocity_limit.hpp"

namespace redres {
namespace {

class ConstantLaw final : public VelocityLimitLaw {
 public:
  ConstantLaw(double lower, double upper) : lower_(lower), upper_(upper) {}
  VelocityBounds bounds(double /*theta*/) const override { return {lower_, upper_}; }
  std::string type() const override { return "constant"; }
  std::string describe() const override {
    std::ostringstream s;
    s.precision(10);
    s << "constant(lower=" << lower_ << ", upper=" << upper_ << ")";
    return s.str();
  }

 private:
  double lower_;
  double upper_;
};

const bool kRegistered = velocity_limit_registry().add({
    "constant",
    "limits that do not depend on the joint position",
    {{"lower", "", "lower velocity limit (rad/s or m/s), < 0"}, {"upper", "", "upper velocity limit, > 0"}},
    [](const TableReader& r) -> std::unique_ptr<VelocityLimitLaw> {
      const double lower = r.number("lower");
      const double upper = r.number("upper");
      if (!(lower < 0.0)) r.fail("lower", "expected a lower velocity limit < 0, got " + std::to_string(lower));
      if (!(upper > 0.0)) r.fail("upper", "expected an upper velocity limit > 0, got " + std::to_string(upper));
      return std::make_unique<ConstantLaw>(lower, upper);
    },
});

}  // namespace
}  // namespace redres

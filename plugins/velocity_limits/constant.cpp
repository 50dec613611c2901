#include "redres/velocity_limits/constant.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"

#include <sstream>

namespace redres {

const Schema<ConstantLawConfig>& ConstantLawConfig::schema() {
  using C = ConstantLawConfig;
  static const Schema<C> s{{field("lower", &C::lower, "rad/s^k or m/s^k",
                                  "lower limit (k = 1: velocity; 2: acceleration; 3: jerk)", less(0.0))
                                .required(),
                            field("upper", &C::upper, "rad/s^k or m/s^k", "upper limit", greater(0.0)).required()}};
  return s;
}

std::string ConstantLaw::describe() const {
  std::ostringstream s;
  s.precision(10);
  s << "constant(lower=" << config_.lower << ", upper=" << config_.upper << ")";
  return s.str();
}

namespace {
const bool kConstantRegistered =
    velocity_limit_registry().add_plugin<ConstantLaw>("limits that do not depend on the joint position");
}  // namespace

}  // namespace redres

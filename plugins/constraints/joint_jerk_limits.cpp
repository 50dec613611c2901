#include "redres/constraints/joint_jerk_limits.hpp"

#include <algorithm>
#include <stdexcept>

#include "redres/constraints/joint_acceleration_limits.hpp"
#include "redres/model/velocity_limit.hpp"

namespace redres {

namespace {
struct JerkData final : PluginData {
  explicit JerkData(int n) : j_lo(n), j_hi(n), lo(n), hi(n), zero(Eigen::VectorXd::Zero(n)) {}
  Eigen::VectorXd j_lo, j_hi, lo, hi, zero;
};
}  // namespace

const Schema<JointJerkLimitsConfig>& JointJerkLimitsConfig::schema() {
  using C = JointJerkLimitsConfig;
  static const Schema<C> s{{field("scale", &C::scale, "", "fraction of the robot's jerk limits",
                                  rule<double>("in (0, 1]", [](double v) { return v > 0.0 && v <= 1.0; }))}};
  return s;
}

JointJerkLimits::JointJerkLimits(const Config& config, const RobotModel& robot)
    : Configured(kType, config), n_(robot.dof()) {
  require_motion_limit(robot, robot.first_without_jerk_limit(), "jerk_limit", kType);
}

std::unique_ptr<PluginData> JointJerkLimits::make_data() const { return std::make_unique<JerkData>(n_); }

void JointJerkLimits::add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const {
  REDRES_REQUIRE(data != nullptr, kType, "the controller made this plugin's data");
  auto& d = static_cast<JerkData&>(*data);
  // The laws at theta: as the Controller evaluated them for the step, or here where a caller's Context has none.
  const Eigen::VectorXd* jerk_lo = ctx.jerk_lower;
  const Eigen::VectorXd* jerk_hi = ctx.jerk_upper;
  if (jerk_lo == nullptr || jerk_hi == nullptr) {
    ctx.robot->jerk_limits(ctx.theta(), d.j_lo, d.j_hi);
    jerk_lo = &d.j_lo;
    jerk_hi = &d.j_hi;
  }
  // A Context without the state between steps (one a caller builds) reads as an arm at rest.
  const Eigen::VectorXd& prev = ctx.theta_dot_prev != nullptr ? *ctx.theta_dot_prev : d.zero;
  const Eigen::VectorXd& prev2 = ctx.theta_dot_prev2 != nullptr ? *ctx.theta_dot_prev2 : d.zero;
  const Eigen::VectorXd& v = ctx.order == ControlOrder::kVelocity || ctx.theta_dot == nullptr ? prev : *ctx.theta_dot;
  const double tau = ctx.tau, scale = config_.scale;
  for (int j = 0; j < n_; ++j) {
    const double a_prev = (prev(j) - prev2(j)) / tau;
    const double j_lo = scale * (*jerk_lo)(j), j_hi = scale * (*jerk_hi)(j);
    // v' = v + tau a with a in a_prev + tau [j^-, j^+] ...
    double a_lo = a_prev + tau * j_lo, a_hi = a_prev + tau * j_hi;
    // ... and, towards a velocity limit, an acceleration that the jerk limit can still bring to zero before the
    // velocity reaches it: v' + a^2 / (2 |j^-|) <= v^+ after the step, i.e. a <= stopping_speed(v^+ - v, |j^-|, tau)
    // (yielding to a_prev + tau j^-, the hardest the jerk limit lets it turn).
    const VelocityBounds vb = ctx.velocity_bounds(j);  // evaluated once for the step by the Controller
    a_hi = std::max(std::min(a_hi, stopping_speed(vb.upper - v(j), -j_lo, tau)), a_lo);
    a_lo = std::min(std::max(a_lo, -stopping_speed(v(j) - vb.lower, j_hi, tau)), a_hi);
    d.lo(j) = ctx.velocity_to_x(v(j) + tau * a_lo, j);
    d.hi(j) = ctx.velocity_to_x(v(j) + tau * a_hi, j);
  }
  builder.yield_bounds(d.lo, d.hi);
}

namespace {
const bool kJointJerkLimitsRegistered = constraint_registry().add_plugin<JointJerkLimits>(
    "a_prev + tau j^- <= (theta_dot - theta_dot_prev) / tau <= a_prev + tau j^+ (the robot file's jerk_limit; both "
    "levels)");
}  // namespace

}  // namespace redres

#include "redres/constraints/joint_acceleration_limits.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace redres {

namespace {
const Rule<double> kFraction = rule<double>("in (0, 1]", [](double v) { return v > 0.0 && v <= 1.0; });

struct AccelerationData final : PluginData {
  explicit AccelerationData(int n) : a_lo(n), a_hi(n), j_lo(n), j_hi(n), lo(n), hi(n), zero(Eigen::VectorXd::Zero(n)) {}
  Eigen::VectorXd a_lo, a_hi, j_lo, j_hi, lo, hi, zero;
};
}  // namespace

void require_motion_limit(const RobotModel& robot, int missing, const char* key, const char* type) {
  if (missing < 0) return;
  throw std::invalid_argument(std::string(type) + " needs a `" + key + "` on every joint of robot '" + robot.name() +
                              "'; joint " + std::to_string(missing + 1) + " ('" + robot.joint(missing).name +
                              "') has none (give it in the robot file's [[joints]] entry)");
}

double stopping_speed(double d, double a, double c) noexcept {
  d = std::max(d, 0.0);
  return a * (-c + std::sqrt(c * c + 2.0 * d / a));
}

const Schema<JointAccelerationLimitsConfig>& JointAccelerationLimitsConfig::schema() {
  using C = JointAccelerationLimitsConfig;
  static const Schema<C> s{
      {field("scale", &C::scale, "", "fraction of the robot's acceleration limits", kFraction),
       field("braking", &C::braking, "",
             "keep every joint able to stop before its position limits at its acceleration limit")}};
  return s;
}

JointAccelerationLimits::JointAccelerationLimits(const Config& config, const RobotModel& robot)
    : Configured(kType, config), n_(robot.dof()), jerk_(robot.has_jerk_limits()) {
  require_motion_limit(robot, robot.first_without_acceleration_limit(), "acceleration_limit", kType);
}

std::unique_ptr<PluginData> JointAccelerationLimits::make_data() const {
  return std::make_unique<AccelerationData>(n_);
}

void JointAccelerationLimits::add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const {
  REDRES_REQUIRE(data != nullptr, kType, "the controller made this plugin's data");
  auto& d = static_cast<AccelerationData&>(*data);
  const RobotModel& robot = *ctx.robot;
  const Eigen::VectorXd& theta = ctx.theta();
  // The laws at theta: as the Controller evaluated them for the step, or here where a caller's Context has none.
  const Eigen::VectorXd* acc_lo = ctx.acceleration_lower;
  const Eigen::VectorXd* acc_hi = ctx.acceleration_upper;
  if (acc_lo == nullptr || acc_hi == nullptr) {
    robot.acceleration_limits(theta, d.a_lo, d.a_hi);
    acc_lo = &d.a_lo;
    acc_hi = &d.a_hi;
  }
  // With jerk limits, full deceleration is reached only after a ramp of |a| / |j|: the joint is taken to move on at v'
  // for that long too (conservative: it already decelerates on the ramp).
  const Eigen::VectorXd* jerk_lo = ctx.jerk_lower;
  const Eigen::VectorXd* jerk_hi = ctx.jerk_upper;
  if (jerk_ && (jerk_lo == nullptr || jerk_hi == nullptr)) {
    robot.jerk_limits(theta, d.j_lo, d.j_hi);
    jerk_lo = &d.j_lo;
    jerk_hi = &d.j_hi;
  }
  const bool velocity_level = ctx.order == ControlOrder::kVelocity;
  // A Context without the state between steps (one a caller builds) reads as an arm at rest.
  const Eigen::VectorXd* state = velocity_level ? ctx.theta_dot_prev : ctx.theta_dot;
  const Eigen::VectorXd& v = state != nullptr ? *state : d.zero;
  const double tau = ctx.tau, scale = config_.scale;
  // The time the joint moves on at v' before it brakes, and the distance the step covers at v on top (the
  // acceleration level's step moves at (v + v') / 2).
  const double c = velocity_level ? tau : 0.5 * tau;
  for (int j = 0; j < n_; ++j) {
    const double a_lo = scale * (*acc_lo)(j), a_hi = scale * (*acc_hi)(j);
    double lo = v(j) + tau * a_lo, hi = v(j) + tau * a_hi;
    if (config_.braking) {
      const double carry = velocity_level ? 0.0 : 0.5 * tau * v(j);
      const double up = robot.upper_limits()(j) - theta(j) - carry;
      const double down = theta(j) - robot.lower_limits()(j) + carry;
      const double ramp_up = jerk_ ? -a_lo / (*jerk_hi)(j) : 0.0, ramp_down = jerk_ ? a_hi / -(*jerk_lo)(j) : 0.0;
      hi = std::max(std::min(hi, stopping_speed(up, -a_lo, c + ramp_up)), lo);  // never more than a^- to brake
      lo = std::min(std::max(lo, -stopping_speed(down, a_hi, c + ramp_down)), hi);
    }
    d.lo(j) = ctx.velocity_to_x(lo, j);
    d.hi(j) = ctx.velocity_to_x(hi, j);
  }
  builder.intersect_bounds(d.lo, d.hi);
}

namespace {
const bool kJointAccelerationLimitsRegistered = constraint_registry().add_plugin<JointAccelerationLimits>(
    "v + tau a^- <= theta_dot <= v + tau a^+ from the previous command v, and each joint able to stop before its "
    "position limits (the robot file's acceleration_limit; both levels)");
}  // namespace

}  // namespace redres

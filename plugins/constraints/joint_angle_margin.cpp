#include "redres/constraints/joint_angle_margin.hpp"

#include <algorithm>

#include "redres/common/hot.hpp"
#include "redres/run/trajectory.hpp"

namespace redres {

const Schema<JointAngleMarginConfig>& JointAngleMarginConfig::schema() {
  using C = JointAngleMarginConfig;
  static const Schema<C> s{
      {field("kappa", &C::kappa, "1/s", "gain", greater(0.0)),
       field("margin", &C::margin, "rad or m", "safety region: one number or one per joint", at_least<PerJoint>(0.0))}};
  return s;
}

JointAngleMargin::JointAngleMargin(const Config& config, const RobotModel& robot)
    : Configured(kType, config), margin_(config_.margin.resolve(robot.dof(), "margin")) {
  for (int j = 0; j < robot.dof(); ++j) {
    const double range = robot.upper_limits()(j) - robot.lower_limits()(j);
    if (2.0 * margin_(j) >= range) {
      throw FieldError("margin", "expected 0 <= margin < half the range of joint '" + robot.joint(j).name + "' (" +
                                     std::to_string(range / 2.0) + "), got " + std::to_string(margin_(j)));
    }
  }
}

std::unique_ptr<PluginData> JointAngleMargin::make_data() const {
  return std::make_unique<Workspace>(static_cast<int>(margin_.size()), 2);
}

REDRES_HOT void JointAngleMargin::add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const {
  REDRES_REQUIRE(data != nullptr, kType, "the controller made this plugin's data");
  Workspace& w = static_cast<Workspace&>(*data);
  Eigen::VectorXd& lo = w[0];
  Eigen::VectorXd& hi = w[1];
  const RobotModel& robot = *ctx.robot;
  const Eigen::VectorXd& theta = ctx.theta();
  const double kappa = config_.kappa;
  lo = kappa * ((robot.lower_limits() + margin_) - theta);
  hi = kappa * ((robot.upper_limits() - margin_) - theta);
  if (ctx.order == ControlOrder::kAcceleration) {  // the velocity after the step keeps them
    for (int j = 0; j < robot.dof(); ++j) {
      lo(j) = ctx.velocity_to_x(lo(j), j);
      hi(j) = ctx.velocity_to_x(hi(j), j);
    }
  }
  builder.intersect_bounds(lo, hi);
}

void JointAngleMargin::summarise(const RobotModel& robot, const Trajectory& run, const PluginData* /*data*/,
                                 std::vector<Metric>& out) const {
  double entry = 0.0;
  for (int j = 0; j < robot.dof(); ++j) {
    const std::size_t c = run.column("theta_" + std::to_string(j + 1));
    const double lo = robot.lower_limits()(j) + margin_(j), hi = robot.upper_limits()(j) - margin_(j);
    for (std::size_t r = 0; r < run.size(); ++r) entry = std::max({entry, run(r, c) - hi, lo - run(r, c)});
  }
  out.push_back({"max_safety_region_entry", {entry}, "rad or m"});
  out.push_back(
      {"safety_margin", std::vector<double>(margin_.data(), margin_.data() + margin_.size()), "rad or m", true});
}

namespace {
const bool kJointAngleMarginRegistered = constraint_registry().add_plugin<JointAngleMargin>(
    "kappa((theta^- + margin) - theta) <= x <= kappa((theta^+ - margin) - theta) (eq. 9 with a safety region)");
}  // namespace

}  // namespace redres

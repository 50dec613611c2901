// `range_centering`: an objective that keeps every joint near the middle of its range,
//   P(theta) = lambda/2 sum_j ((theta_j - m_j) / h_j)^2,   m_j = (theta_j^+ + theta_j^-)/2, h_j = (theta_j^+ -
//   theta_j^-)/2,
// added as zeta += weight * grad P = weight * lambda (theta_j - m_j) / h_j^2. Unlike joint_centering it scales each
// joint by its own range, so a narrow joint is pulled as hard as a wide one.

#include <redres/control/plugin.hpp>

namespace {

struct RangeCenteringConfig {
  double lambda = 0.5;  // 1/s
  static const redres::Schema<RangeCenteringConfig>& schema() {
    static const redres::Schema<RangeCenteringConfig> s{
        {redres::field("lambda", &RangeCenteringConfig::lambda, "1/s", "pull towards the middle of each range",
                       redres::at_least(0.0))}};
    return s;
  }
};

class RangeCentering final : public redres::Configured<redres::Objective, RangeCenteringConfig> {
 public:
  static constexpr const char* kType = "range_centering";

  RangeCentering(const Config& config, const redres::RobotModel& robot)
      : Configured(kType, config),
        mid_((robot.upper_limits() + robot.lower_limits()) / 2.0),
        inv_half_sq_(((robot.upper_limits() - robot.lower_limits()) / 2.0).array().square().inverse().matrix()) {}

  // One n-vector of workspace per controller (made at setup): no allocation on the per-step path.
  [[nodiscard]] std::unique_ptr<redres::PluginData> make_data() const override {
    return std::make_unique<redres::Workspace>(static_cast<int>(mid_.size()), 1);
  }

  // The potential whose gradient zeta is; `redres plugins --check` compares the two by central differences.
  std::optional<double> potential(const redres::Context& ctx) const override {
    return 0.5 * config_.lambda * ((ctx.theta() - mid_).array().square() * inv_half_sq_.array()).sum();
  }

 private:
  void add_to(const redres::Context& ctx, redres::QpBuilder& builder, redres::PluginData* data) const override {
    Eigen::VectorXd& z = static_cast<redres::Workspace&>(*data)[0];
    z = config_.lambda * (ctx.theta() - mid_).cwiseProduct(inv_half_sq_);
    builder.add_linear(z);
  }

  Eigen::VectorXd mid_, inv_half_sq_;
};

const bool kRangeCenteringRegistered =
    redres::objective_registry().add_plugin<RangeCentering>("zeta += lambda (theta - mid) / half_range^2");

}  // namespace

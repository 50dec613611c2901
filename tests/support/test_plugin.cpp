// A plugin library for the loader tests: loaded at run time with dlopen, it registers one objective and one
// constraint exactly as a user's library would (tests/cli/plugin_loader_test.cpp).

#include <redres/control/plugin.hpp>

namespace {

struct DampingConfig {
  double gain = 0.5;  // 1/s
  static const redres::Schema<DampingConfig>& schema() {
    static const redres::Schema<DampingConfig> s{
        {redres::field("gain", &DampingConfig::gain, "1/s", "adds gain * I to W", redres::greater(0.0))}};
    return s;
  }
};

// W += gain * I: a heavier minimum-velocity-norm term; the gradient of the zero potential is the zero zeta.
class TestDamping final : public redres::Configured<redres::Objective, DampingConfig> {
 public:
  static constexpr const char* kType = "test_damping";
  TestDamping(const Config& c, const redres::RobotModel& /*robot*/) : Configured(kType, c) {}
  std::optional<double> potential(const redres::Context& /*ctx*/) const override { return 0.0; }

 private:
  void add_to(const redres::Context& /*ctx*/, redres::QpBuilder& b, redres::PluginData* /*data*/) const override {
    b.add_identity(config_.gain);
  }
};

struct CapConfig {
  double cap = 0.3;  // rad/s
  static const redres::Schema<CapConfig>& schema() {
    static const redres::Schema<CapConfig> s{
        {redres::field("cap", &CapConfig::cap, "rad/s", "|theta_dot_j| <= cap for every joint", redres::greater(0.0))}};
    return s;
  }
};

// -cap <= x_j <= cap as bounds.
class TestCap final : public redres::Configured<redres::Constraint, CapConfig> {
 public:
  static constexpr const char* kType = "test_cap";
  TestCap(const Config& c, const redres::RobotModel& /*robot*/) : Configured(kType, c) {}

 private:
  void add_to(const redres::Context& ctx, redres::QpBuilder& b, redres::PluginData* /*data*/) const override {
    for (int j = 0; j < ctx.robot->dof(); ++j) b.intersect_bound(j, -config_.cap, config_.cap);
  }
};

const bool kObjective = redres::objective_registry().add_plugin<TestDamping>("test: W += gain I");
const bool kConstraint = redres::constraint_registry().add_plugin<TestCap>("test: |x_j| <= cap");

}  // namespace

// `joint_speed_cap`: a constraint that keeps chosen joints within +-cap as inequality rows (2 per joint),
//   x_j <= cap  and  -x_j <= cap.
// (Bounds would do the same job faster; rows show how a constraint writes A x <= b.)

#include <redres/control/plugin.hpp>

namespace {

struct JointSpeedCapConfig {
  std::vector<int> joints = {1};  // 1-based joint numbers
  double cap = 0.05;              // rad/s
  static const redres::Schema<JointSpeedCapConfig>& schema() {
    using C = JointSpeedCapConfig;
    static const redres::Schema<C> s{
        {redres::field("joints", &C::joints, "", "1-based joint numbers", redres::at_least<std::vector<int>>(1)),
         redres::field("cap", &C::cap, "rad/s", "speed cap", redres::greater(0.0))}};
    return s;
  }
};

class JointSpeedCap final : public redres::Configured<redres::Constraint, JointSpeedCapConfig> {
 public:
  static constexpr const char* kType = "joint_speed_cap";

  JointSpeedCap(const Config& config, const redres::RobotModel& robot) : Configured(kType, config) {
    for (int j : config_.joints) {
      // Checks that need the robot throw FieldError: from TOML it becomes file:line:col at the key.
      if (j > robot.dof()) {
        throw redres::FieldError(
            "joints", "expected joint numbers from 1 to " + std::to_string(robot.dof()) + ", got " + std::to_string(j));
      }
    }
  }

  int inequality_rows(const redres::RobotModel& /*robot*/) const override {
    return 2 * static_cast<int>(config_.joints.size());
  }

 private:
  void add_to(const redres::Context& /*ctx*/, redres::QpBuilder& builder, redres::PluginData* /*data*/) const override {
    auto A = builder.inequality_matrix();
    A.setZero();
    for (std::size_t k = 0; k < config_.joints.size(); ++k) {
      A(static_cast<Eigen::Index>(2 * k), config_.joints[k] - 1) = 1.0;
      A(static_cast<Eigen::Index>(2 * k + 1), config_.joints[k] - 1) = -1.0;
    }
    builder.inequality_rhs().setConstant(config_.cap);
  }
};

const bool kJointSpeedCapRegistered =
    redres::constraint_registry().add_plugin<JointSpeedCap>("|x_j| <= cap for chosen joints (inequality rows)");

}  // namespace

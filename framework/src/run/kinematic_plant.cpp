// The kinematic plant (docs/plant.md): theta <- theta + tau theta_dot, redres's own integration (Euler's or Heun's
// method; at the acceleration level the step's constant acceleration exactly). The default plant.

#include <algorithm>

#include "redres/control/controller.hpp"
#include "redres/run/scenario.hpp"
#include "run/builtin_plants.hpp"

namespace redres {

namespace {

class KinematicPlant final : public Plant {
 public:
  explicit KinematicPlant(const Scenario& s)
      : s_(s), theta_(s.theta0), theta_pred_(s.robot->dof()), velocity_(Eigen::VectorXd::Zero(s.robot->dof())) {}

  [[nodiscard]] const Eigen::VectorXd& theta() const override { return theta_; }
  [[nodiscard]] const Eigen::VectorXd* theta_dot() const override { return nullptr; }

  // A held step moves nothing; a braked step moves with its braking command (Euler's step: no second stage).
  // velocity_ is the command applied over the previous step on entry and this step's on return.
  bool advance(const StepOutput& out, double t, PlantStep& step, Eigen::VectorXd& applied,
               std::string& /*failure*/) override {
    if (!moves(out.info.status)) {  // theta_dot = 0 (the controller never hands out an unconverged iterate)
      velocity_.setZero();
      applied = velocity_;
      return true;
    }
    const double tau = s_.tau;
    if (s_.scheme->order() == ControlOrder::kAcceleration) {
      theta_ += (0.5 * tau) * (velocity_ + out.theta_dot);  // (v + v') / 2 over the step: exact for its acceleration
      velocity_ = out.theta_dot;
      applied = velocity_;
      return true;
    }
    velocity_ = out.theta_dot;  // the command applied over the step (Heun's average below replaces it)
    if (s_.integrator == Integrator::kEuler || out.info.status == SolverStatus::kBraked) {
      theta_ += tau * out.theta_dot;
      applied = velocity_;
      return true;
    }
    // Heun: average the slopes at theta and at the Euler prediction (one more QP per step).
    theta_pred_ = theta_ + tau * out.theta_dot;
    const StepOutput* out2 = step.solve_again(theta_pred_, std::min(s_.duration, t + tau));
    if (out2 == nullptr) return false;
    if (usable(out2->info.status)) {  // a braked second stage is not averaged in
      theta_ += 0.5 * tau * (out.theta_dot + out2->theta_dot);
      velocity_ = 0.5 * (out.theta_dot + out2->theta_dot);  // the command applied: the next step's theta_dot_prev
      step.set_applied(velocity_);
    } else {
      theta_ += tau * out.theta_dot;  // the second stage failed: Euler's step with the first, which solved
    }
    applied = velocity_;
    return true;
  }

 private:
  const Scenario& s_;
  Eigen::VectorXd theta_, theta_pred_, velocity_;
};

}  // namespace

PlantType kinematic_plant_type() {
  PlantType t;
  t.name = "kinematic";
  t.description = "theta <- theta + tau theta_dot: redres's own integration (Euler or Heun), the default";
  t.check = [](const TableReader& r, Scenario& /*s*/) {
    for (const char* key : {"timestep", "integrator", "actuator", "gravity_compensation", "kv", "kp", "kd", "delay",
                            "gravity", "kinematic_comparison"}) {
      if (r.has(key)) r.fail(key, "is used only with kind = \"mujoco\" (kind is \"kinematic\")");
    }
  };
  t.make = [](const Scenario& s) -> std::unique_ptr<Plant> { return std::make_unique<KinematicPlant>(s); };
  return t;
}

}  // namespace redres

// Controller::from_scenario: declared with the controller (control/), defined here, beside the scenario it reads.
#include "redres/control/controller.hpp"
#include "redres/run/scenario.hpp"

namespace redres {

std::unique_ptr<Controller> Controller::from_scenario(const Scenario& s) {
  REDRES_REQUIRE(s.robot && s.scheme, "Controller::from_scenario",
                 "the scenario has a robot and a scheme (as load_scenario makes it)");
  auto ctrl = std::make_unique<Controller>(*s.robot, *s.scheme, s.engine.make(), s.path.get(), s.duration, s.tau);
  ctrl->set_orientation_turn(s.orientation_turn);
  ctrl->set_kinematics_level(KinematicsLevel::kMeasure);
  ctrl->set_failure_policy(s.on_infeasible, s.relax_weight, s.recover_error);
  return ctrl;
}

}  // namespace redres

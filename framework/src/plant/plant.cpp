// The [plant] table of a scenario (redres/plant/plant.hpp).

#include "redres/plant/plant.hpp"

namespace redres {

const Schema<PlantConfig>& PlantConfig::schema() {
  using C = PlantConfig;
  static const Schema<C> s{{
      field("kind", &C::kind, "",
            "what the commands drive: \"kinematic\" (theta <- theta + tau theta_dot) or \"mujoco\" (a physics plant)"),
      field("timestep", &C::timestep, "s",
            "MuJoCo's time step; the scenario's `step` (the control period) must be a whole number of them (0: the "
            "smaller of 1 ms and `step`)",
            between(0.0, 1.0)),
      field("integrator", &C::integrator, "", "MuJoCo's integrator"),
      field("actuator", &C::actuator, "",
            "how a joint velocity command becomes a torque: a velocity servo, a joint impedance controller, or an "
            "ideal velocity source"),
      field("gravity_compensation", &C::gravity_compensation, "",
            "the servo and the impedance controller add the torques that hold the arm against gravity, g(q)"),
      field("kv", &C::kv, "N m s/rad or N s/m", "velocity servo gain: one number or one per joint",
            greater<PerJoint>(0.0)),
      field("kp", &C::kp, "N m/rad or N/m", "impedance stiffness: one number or one per joint",
            at_least<PerJoint>(0.0)),
      field("kd", &C::kd, "N m s/rad or N s/m", "impedance damping: one number or one per joint",
            at_least<PerJoint>(0.0)),
      field(
          "delay", &C::delay, "s",
          "the measurement's delay, a whole number of MuJoCo time steps: the controller reads the state this long ago",
          between(0.0, 1.0)),
      field("gravity", &C::gravity, "", "scale of MuJoCo's gravity (1: 9.81 m/s^2 along the world's -z)",
            between(0.0, 10.0)),
  }};
  return s;
}

}  // namespace redres

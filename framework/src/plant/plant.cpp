// The [plant] table of a scenario (redres/plant/plant.hpp).

#include "redres/plant/plant.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace redres {

namespace {

// The whole number of `unit`s in `span` (to 1e-9 relative), or -1 when it is not one.
long whole_multiple(double span, double unit) {
  const double ratio = span / unit;
  const long k = std::lround(ratio);
  return std::abs(ratio - static_cast<double>(k)) <= 1e-9 * std::max(1.0, ratio) ? k : -1;
}

}  // namespace

PlantTiming plant_timing(const PlantConfig& config, double control_period) {
  PlantTiming t;
  t.timestep = config.timestep > 0.0 ? config.timestep : std::min(1e-3, control_period);
  const long k = whole_multiple(control_period, t.timestep);
  if (k < 1 || k > 100000) {
    std::ostringstream m;
    m << "the control period (the scenario's `step` = " << control_period
      << " s) must be a whole number of MuJoCo time steps (at most 100000), and " << t.timestep
      << " s is not a divisor of it";
    throw FieldError("timestep", m.str());
  }
  t.substeps = static_cast<int>(k);
  const long delay = config.delay > 0.0 ? whole_multiple(config.delay, t.timestep) : 0;
  if (delay < 0) {
    std::ostringstream m;
    m << "expected a whole number of MuJoCo time steps (timestep = " << t.timestep << " s), got " << config.delay
      << " s";
    throw FieldError("delay", m.str());
  }
  t.delay_steps = static_cast<int>(delay);
  return t;
}

const Schema<PlantConfig>& PlantConfig::schema() {
  using C = PlantConfig;
  static const Schema<C> s{{
      field("kind", &C::kind, "",
            "what the commands drive: \"kinematic\" (theta <- theta + tau theta_dot) or \"mujoco\" (a physics plant)"),
      field("kinematic_comparison", &C::kinematic_comparison, "",
            "also run the scenario on the kinematic plant first, for `plant.kinematic_max_position_error` in the "
            "summary (kind = \"mujoco\")"),
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

#pragma once
/// @file
/// What a scenario's commands drive ([plant] in a scenario file; docs/plant.md): the kinematic plant (theta <- theta
/// + tau theta_dot, redres's own integration, the default) or a MuJoCo physics plant, where the controller reads the
/// measured joint angles and velocities of a simulated arm with mass, actuators and contacts.

#include <array>
#include <string>
#include <string_view>
#include <utility>

#include "redres/config/config.hpp"

namespace redres {

/// How the MuJoCo plant turns the controller's joint velocity command into joint torques (docs/plant.md, "Actuators"):
/// - kVelocityServo ("velocity_servo", the default): tau = Kv (theta_dot_cmd - qdot) + g(q);
/// - kImpedance ("impedance"): tau = Kp (q_ref - q) + Kd (theta_dot_cmd - qdot) + g(q), q_ref integrating the
///   commands from the start;
/// - kIdealVelocity ("ideal_velocity"): the joints move exactly with the command (no dynamics); the torques recorded
///   are those the motion takes (inverse dynamics), not clamped.
/// g(q) is the gravity compensation (off with gravity_compensation = false); the servo's and the impedance's torques
/// are clamped at the robot's effort limits (the total, gravity compensation included).
enum class PlantActuator { kVelocityServo, kImpedance, kIdealVelocity };
inline auto enum_names(PlantActuator) {
  return std::array{std::pair{PlantActuator::kVelocityServo, std::string_view("velocity_servo")},
                    std::pair{PlantActuator::kImpedance, std::string_view("impedance")},
                    std::pair{PlantActuator::kIdealVelocity, std::string_view("ideal_velocity")}};
}

/// MuJoCo's integrator: implicit in velocity (the actuators' velocity gains and the joints' damping are integrated
/// implicitly, so a stiff servo on a light link stays stable) or semi-implicit Euler. (RK4 is not offered: the torques
/// are set between MuJoCo's two stages of a step, which RK4 does not have.)
enum class PlantIntegrator { kImplicit, kEuler };
inline auto enum_names(PlantIntegrator) {
  return std::array{std::pair{PlantIntegrator::kImplicit, std::string_view("implicit")},
                    std::pair{PlantIntegrator::kEuler, std::string_view("euler")}};
}

/// A scenario's [plant] table.
struct PlantConfig {
  /// Which plant a run drives, by its name in the plant registry (run/plants.hpp): "kinematic" or "mujoco".
  std::string kind = "kinematic";
  /// A run on another plant than the kinematic one also runs on the kinematic plant first, for the comparison of
  /// their position errors (RunResult::plant's kinematic_max_position_error); off by default.
  bool kinematic_comparison = false;
  /// MuJoCo's time step (s); the control period (the scenario's `step`) must be a whole number of them. 0: the
  /// smaller of 1 ms and the control period.
  double timestep = 0.0;
  PlantIntegrator integrator = PlantIntegrator::kImplicit;
  PlantActuator actuator = PlantActuator::kVelocityServo;
  bool gravity_compensation = true;
  PerJoint kv{100.0};  //!< velocity servo gain (N m s/rad or N s/m), one or one per joint
  PerJoint kp{600.0};  //!< impedance stiffness (N m/rad or N/m)
  PerJoint kd{50.0};   //!< impedance damping (N m s/rad or N s/m)
  /// The measurement's delay (s), a whole number of MuJoCo time steps: the controller reads the state this long ago.
  double delay = 0.0;
  /// Scale of MuJoCo's gravity (1: -9.81 m/s^2 along the world's z; 0: none).
  double gravity = 1.0;

  static const Schema<PlantConfig>& schema();
};

/// The MuJoCo time steps of a run: the step (the config's `timestep`, or when 0 the smaller of 1 ms and the control
/// period), how many make one control period, and how many the measurement's delay is.
struct PlantTiming {
  double timestep = 0.0;
  int substeps = 1;
  int delay_steps = 0;
};

/// The timing of `config` for control periods of `control_period` s. FieldError at key "timestep" when the period is
/// not a whole number of time steps (or more than 100000 of them), at "delay" when the delay is not.
[[nodiscard]] PlantTiming plant_timing(const PlantConfig& config, double control_period);

}  // namespace redres

#pragma once
/// @file
/// The MuJoCo physics plant (docs/plant.md, "The plant"): the robot as mjcf_from_robot() writes it, with actuators
/// and the scenario's obstacles, stepped by MuJoCo while the controller's joint velocity command is held over each
/// control period (zero-order hold). The controller reads the measured joint angles and velocities (delayed, when
/// asked), and the plant records what a kinematic run cannot: joint torques against the effort limits, their rate,
/// and the contacts MuJoCo finds. Needs MuJoCo (mujoco_available()); the constructor throws without it.
///
/// After construction nothing allocates: advance() runs MuJoCo's steps on preallocated data (a contact pair seen
/// for the first time is noted in storage reserved up front).

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/model/collision.hpp"
#include "redres/model/robot.hpp"
#include "redres/plant/plant.hpp"

namespace redres {

/// A pair of bodies in contact (a robot body's name, or "obstacle<k>"), over a run.
struct PlantContactPair {
  std::string a, b;
  double first_time = 0.0;  //!< the first MuJoCo step they touched (s)
  double deepest = 0.0;     //!< the deepest penetration between them (m, >= 0)
  long steps = 0;           //!< MuJoCo steps they touched
};

class MujocoPlant {
 public:
  /// The plant of `robot` at theta0 (at rest), run with `config` (its timestep 0: the smaller of 1 ms and the control
  /// period) for control periods of `control_period` s, with the world-frame `obstacles`. Throws
  /// std::invalid_argument when the control period is not a whole number of time steps, the delay not a whole
  /// number of time steps, a gain is not one or one per joint, or the robot lacks mass properties (naming the links);
  /// std::runtime_error when MuJoCo is not built in (naming the Debian package) or refuses the model.
  MujocoPlant(const RobotModel& robot, const PlantConfig& config, double control_period,
              std::vector<ShapeSpec> obstacles, const Eigen::VectorXd& theta0);
  MujocoPlant(const MujocoPlant&) = delete;
  MujocoPlant& operator=(const MujocoPlant&) = delete;
  ~MujocoPlant();

  /// The model MuJoCo runs (MJCF text): what `--write-mjcf` writes.
  [[nodiscard]] const std::string& mjcf() const;
  [[nodiscard]] double timestep() const;  //!< MuJoCo's time step (s)
  [[nodiscard]] int substeps() const;     //!< MuJoCo steps per control period
  /// The measured joint angles and velocities the controller reads now (`delay` ago).
  [[nodiscard]] const Eigen::VectorXd& theta() const;
  [[nodiscard]] const Eigen::VectorXd& theta_dot() const;

  /// One control period from time t with `command` (joint velocities) held.
  void advance(const Eigen::Ref<const Eigen::VectorXd>& command, double t);

  /// Over the last advance() (before the first: at the start): the joint torques of its last MuJoCo step (actuator
  /// and gravity compensation; the ideal velocity source: the inverse dynamics' torques), the most contacts of any
  /// of its MuJoCo steps (pairs that involve the robot), and the deepest penetration (m, >= 0).
  [[nodiscard]] const Eigen::VectorXd& torque() const;
  [[nodiscard]] int contacts() const;
  [[nodiscard]] double penetration() const;

  /// Over the whole run, every MuJoCo step: the largest |torque| per joint, the largest |torque rate| per joint
  /// (N m/s or N/s, between consecutive MuJoCo steps), the contact pairs, the MuJoCo steps taken and the wall time
  /// they took (s).
  [[nodiscard]] const Eigen::VectorXd& max_torque() const;
  [[nodiscard]] const Eigen::VectorXd& max_torque_rate() const;
  [[nodiscard]] std::vector<PlantContactPair> contact_pairs() const;
  [[nodiscard]] long mujoco_steps() const;
  [[nodiscard]] double mujoco_seconds() const;
  /// The positions of the moving obstacles (mocap bodies, 3 x their number) at time t, for a film.
  [[nodiscard]] Eigen::Matrix3Xd mocap_positions(double t) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace redres

#pragma once
/// @file
/// A MuJoCo model of a RobotModel (docs/plant.md, "The MuJoCo model redres generates"): mjcf_from_robot() writes the
/// robot as MJCF (MuJoCo's XML), and MujocoModel loads such a model with MuJoCo when redres is built with it
/// (REDRES_WITH_MUJOCO). This header includes no MuJoCo header: the generator is plain text, and the loader keeps
/// MuJoCo's structures behind a pointer.
///
/// The MJCF has one body per joint, nested as the chain is: body j's frame is redres's link frame of joint j (the
/// frame after the joint's motion M_j), placed in its parent at B_{j-1} A_j (the first at P A_1), with a hinge or slide
/// joint at its origin along u_j, so that MuJoCo's body poses are RobotModel's link frames at every configuration. The
/// end effector E is a site "end_effector" in the last body.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "redres/model/collision.hpp"
#include "redres/model/robot.hpp"
#include "redres/plant/plant.hpp"

namespace redres {

/// How mjcf_from_robot() writes the model.
struct MjcfOptions {
  /// The model's name (empty: the robot's).
  std::string model_name;
  /// Links without mass properties (JointSpec::inertia empty, or too small for MuJoCo: a mass or principal moment not
  /// above 1e-15) get a placeholder body instead of an error: a small mass at the link frame's origin. For kinematics
  /// only: such a model's dynamics mean nothing.
  bool placeholder_inertia = false;
  double placeholder_mass = 1e-3;    //!< kg
  double placeholder_moment = 1e-6;  //!< kg m^2, each principal moment
  /// Links whose mass properties no rigid body has (Inertia::invalid(): a maker's tensor whose principal moments fail
  /// the triangle inequality, which redres keeps with a warning) are written as given with MuJoCo's
  /// `balanceinertia`, which raises the largest moment to the sum of the others; otherwise they are an error.
  bool balance_inertia = false;
  /// The name of the end effector's site.
  std::string end_effector_site = "end_effector";
  /// The simulation of a physics plant (docs/plant.md, "The plant"): when given, <option> gets its time step
  /// (`timestep`, which must then be > 0), integrator and gravity, and every joint an actuator of its kind: a velocity
  /// servo (general, gain kv, bias -kv qdot) or an impedance controller (general, gain 1, bias -kp q - kd qdot), each
  /// force-limited at the joint's effort limit when it has one; an ideal velocity source has none.
  std::optional<PlantConfig> plant;
  /// Obstacles, world-frame shapes (as the scenario's collision constraints give them, PluginOutput::
  /// scene_obstacles()): a still one is a geom of the world body ("obstacle<k>"), a moving one (`velocity`) a mocap
  /// body of that name holding its geom, at its pose at t = 0. They collide with the robot, not with each other.
  std::vector<ShapeSpec> obstacles;
};

/// The MJCF of `robot` (a complete <mujoco> document; angles in radians). Throws std::invalid_argument naming every
/// joint whose link has no usable mass properties (unless options.placeholder_inertia) or impossible ones (unless
/// options.balance_inertia); and for a robot shape MuJoCo cannot hold (an octree or point cloud).
///
/// Contents: joint limits as `range` (limited); mass, centre of mass and the full inertia tensor of each link
/// (`fullinertia`); the collision shapes (RobotModel::link_shapes()) in their link's body: spheres, capsules (by
/// `fromto`), boxes, cylinders, and convex hulls as <mesh> assets made from the hull's vertices; a <contact><exclude>
/// for every pair of bodies whose shapes redres never checks against each other (RobotModel::self_collision_bodies()
/// false for every pair of their redres bodies), adjacent ones included. Numbers are printed with 17 significant
/// digits, so they read back as the same doubles.
[[nodiscard]] std::string mjcf_from_robot(const RobotModel& robot, const MjcfOptions& options = {});

/// Whether mjcf_from_robot() makes this obstacle a mocap body (it has a non-zero `velocity`).
[[nodiscard]] bool mjcf_moving_obstacle(const ShapeSpec& obstacle);
/// The positions at time t of the mocap bodies mjcf_from_robot() makes of `obstacles` (the moving ones, in their
/// order: MuJoCo's mocap order), 3 x their number: each obstacle's position at t = 0 plus t times its velocity.
[[nodiscard]] Eigen::Matrix3Xd mjcf_mocap_positions(const std::vector<ShapeSpec>& obstacles, double t);

/// The body name mjcf_from_robot() gives joint j's link: the redres body's name (a URDF's link name, or the joint's).
[[nodiscard]] std::string mjcf_body_name(const RobotModel& robot, int j);

/// Whether this build of redres can load MuJoCo models (MujocoModel).
[[nodiscard]] bool mujoco_available() noexcept;
/// What a build without MuJoCo says when asked for it: which Debian package to install.
[[nodiscard]] std::string mujoco_missing();

/// A MuJoCo model and its data, loaded from MJCF text. Without MuJoCo (mujoco_available() false) from_xml() throws.
class MujocoModel {
 public:
  /// Loads `xml` (through MuJoCo's virtual file system, no file is written). Throws std::runtime_error with MuJoCo's
  /// message when MuJoCo refuses it.
  [[nodiscard]] static MujocoModel from_xml(const std::string& xml);
  MujocoModel(MujocoModel&&) noexcept;
  MujocoModel& operator=(MujocoModel&&) noexcept;
  ~MujocoModel();

  [[nodiscard]] int nq() const;        //!< the number of position coordinates
  [[nodiscard]] int nbody() const;     //!< the number of bodies, the world's included
  [[nodiscard]] int ngeom() const;     //!< the number of geoms
  [[nodiscard]] int nmesh() const;     //!< the number of mesh assets
  [[nodiscard]] int nexclude() const;  //!< the number of excluded body pairs
  /// The id of the body, joint or site named `name`, or -1.
  [[nodiscard]] int body(const std::string& name) const;
  [[nodiscard]] int joint(const std::string& name) const;
  [[nodiscard]] int site(const std::string& name) const;
  [[nodiscard]] int geom(const std::string& name) const;
  [[nodiscard]] double body_mass(int body) const;
  /// The centre of mass in the body frame (MuJoCo's body_ipos).
  [[nodiscard]] Eigen::Vector3d body_com(int body) const;
  /// The inertia tensor about the centre of mass in the body frame, from MuJoCo's principal moments (body_inertia)
  /// and axes (body_iquat).
  [[nodiscard]] Eigen::Matrix3d body_inertia(int body) const;
  /// The joint's range (lower, upper) and whether it is limited.
  [[nodiscard]] Eigen::Vector2d joint_range(int joint) const;
  [[nodiscard]] bool joint_limited(int joint) const;
  /// Whether the pair of bodies is excluded from contacts (a <contact><exclude>).
  [[nodiscard]] bool excluded(int body1, int body2) const;

  /// Sets qpos = q (size nq()) and runs mj_kinematics.
  void kinematics(const Eigen::Ref<const Eigen::VectorXd>& q);
  /// After kinematics(): the world pose of a site or a body.
  [[nodiscard]] Eigen::Isometry3d site_pose(int site) const;
  [[nodiscard]] Eigen::Isometry3d body_pose(int body) const;
  [[nodiscard]] Eigen::Isometry3d geom_pose(int geom) const;
  /// After kinematics(): the world positions of a mesh geom's vertices (3 x their number; MuJoCo keeps them as
  /// floats), none for another geom.
  [[nodiscard]] Eigen::Matrix3Xd mesh_vertices(int geom) const;

 private:
  struct Impl;
  explicit MujocoModel(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace redres

#pragma once
/// @file
/// The robot model: an immutable serial chain with per-joint position limits and velocity-limit laws.
///
/// Notation (as in the paper): n joints, theta in R^n joint positions (rad for revolute, m for prismatic),
/// m task rows, f(theta) in R^m the end-effector task coordinates, J = df/dtheta in R^{m x n}.
///
/// Geometry. The chain starts at the base pose P (the robot's base in the world; identity by default). Every joint j
/// is a fixed transform A_j, then the joint motion M_j (a rotation by theta_j about the joint's unit axis u_j for a
/// revolute joint, a translation by theta_j u_j for a prismatic one), then a fixed transform B_j; the end effector
/// is a fixed transform E after the last joint:
///   T(theta) = P A_1 M_1(theta_1) B_1 ... A_n M_n(theta_n) B_n E.
/// Every description below is converted into these transforms at load, so there is one kinematics code path. u_j is
/// the z axis (0, 0, 1) for planar chains and both DH conventions.
/// - planar chains (relative joint angles, docs/letter_r.md): A_j = I, B_j = Tx(l_j);
///   so x = sum_i l_i cos(theta_1 + ... + theta_i) and y likewise with sin.
/// - spatial, standard DH (`convention = "dh"`): A_j = Rz(theta_offset_j) [Tz(d_j) if prismatic],
///   B_j = [Tz(d_j) if revolute] Tx(a_j) Rx(alpha_j). Joint j moves about/along the z axis of frame j-1.
/// - spatial, modified DH (`convention = "modified_dh"`, Craig): A_j = Rx(alpha_j) Tx(a_j) Rz(theta_offset_j)
///   [Tz(d_j) if prismatic], B_j = [Tz(d_j) if revolute]; alpha_j and a_j are those of the link before joint j
///   (Craig's alpha_{j-1}, a_{j-1}). Joint j moves about/along the z axis of frame j.
/// - spatial, joint frames (`convention = "joints"`, as in URDF): A_j = the joint's origin (xyz, then roll-pitch-yaw
///   about the fixed x, y, z axes), B_j = I; u_j = the joint's `axis` in the frame after A_j (normalised).
///
/// Task rows (`task`): planar "position" = (x, y), planar "pose" = (x, y, phi) with phi the end-effector angle;
/// spatial "position" = (x, y, z), spatial "pose" = (x, y, z, wx, wy, wz) where the last three rows of J are the
/// geometric angular velocity in the world frame (so they are not the derivative of f's rotation-vector entries).
/// `task` may also name a subset of these rows, in this order, e.g. ["x", "y", "z", "wz"]: the reference (f, r_d)
/// keeps every row of the position or pose task it belongs to, while J, the task constraint and w = det(J J') use
/// the named rows only (a selection matrix S: S J x = S (r_d_dot + K e)).

#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "redres/config/toml_reader.hpp"
#include "redres/model/collision.hpp"
#include "redres/model/velocity_limit.hpp"

namespace redres {

/// Planar chains move in the x-y plane; spatial chains in 3-D.
enum class ChainKind { kPlanar, kSpatial };
/// Joint type.
enum class JointType { kRevolute, kPrismatic };
/// How a spatial chain is described: Denavit-Hartenberg (standard or modified) or joint frames (origin and axis).
enum class DhConvention { kStandard, kModified, kJointFrames };
/// Which task-space rows the chain exposes.
enum class TaskRows { kPosition, kPose };

/// One joint as described in the robot file.
/// The mass properties of a rigid body: mass, centre of mass and inertia tensor about the centre of mass, both in the
/// body's (link's) frame.
struct Inertia {
  double mass = 0.0;                                 //!< kg, > 0
  Eigen::Vector3d com = Eigen::Vector3d::Zero();     //!< centre of mass (m)
  Eigen::Matrix3d tensor = Eigen::Matrix3d::Zero();  //!< about the centre of mass (kg m^2), symmetric, PSD
  /// The same body seen from a frame in which its frame is `pose`.
  [[nodiscard]] Inertia moved(const Eigen::Isometry3d& pose) const;
  /// This body and `other` (in the same frame) as one: masses add, the tensors meet at the common centre of mass
  /// (parallel-axis theorem).
  [[nodiscard]] Inertia combined(const Inertia& other) const;
  /// Why it is not a physical body ("" when it is): mass > 0 and finite, the tensor symmetric, positive
  /// semi-definite and meeting the triangle inequalities of its principal moments.
  [[nodiscard]] std::string invalid() const;
};

struct JointSpec {
  std::string name;                                          //!< unique joint name
  JointType type = JointType::kRevolute;                     //!< revolute (rad) or prismatic (m; spatial chains only)
  double length = 0.0;                                       //!< planar link length l_j after the joint (m, > 0)
  double a = 0.0;                                            //!< DH link length (m)
  double alpha = 0.0;                                        //!< DH link twist (rad)
  double d = 0.0;                                            //!< DH link offset (m)
  double theta_offset = 0.0;                                 //!< DH joint-angle offset (rad)
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  //!< joint frames: A_j, in the previous link frame
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();           //!< joint frames: the axis u_j (other chains: z)
  double lower = 0.0;                                        //!< position limit theta^- (rad or m)
  double upper = 0.0;                                        //!< position limit theta^+ (rad or m)
  std::shared_ptr<const VelocityLimitLaw> velocity_limit;    //!< theta_dot^-(theta), theta_dot^+(theta)
  std::string velocity_limit_source;  //!< "file:line:col" of the law's table, for diagnoses (empty: built in code)
  /// theta_ddot^-(theta), theta_ddot^+(theta) (rad/s^2 or m/s^2), a law as the velocity limit is; null: not given.
  std::shared_ptr<const VelocityLimitLaw> acceleration_limit;
  std::string acceleration_limit_source;  //!< where the acceleration law was given ("file:line:col")
  /// Bounds on the rate of change of acceleration (rad/s^3 or m/s^3), a law; null: not given.
  std::shared_ptr<const VelocityLimitLaw> jerk_limit;
  std::string jerk_limit_source;       //!< where the jerk law was given ("file:line:col")
  std::optional<double> effort_limit;  //!< the largest torque or force (N m or N), > 0; from the URDF's `effort`
  /// The joint's viscous damping (N m s/rad or N s/m, >= 0) and its armature, the drive's reflected rotor inertia
  /// (kg m^2 or kg, >= 0): what a physics plant adds to the link's own dynamics (docs/plant.md). Empty: not given (a
  /// plant takes 0); damping also comes from a URDF's <dynamics damping>.
  std::optional<double> damping;
  std::optional<double> armature;
  /// The mass properties of the link this joint moves (with everything riding on it), in the link frame; from the
  /// URDF's <inertial> elements or the robot file's `inertia`. Empty when not given.
  std::optional<Inertia> inertia;
  std::string inertia_source;   //!< "file:line:col" of the robot file's `inertia` (empty: from the URDF or none)
  std::string inertia_warning;  //!< what is wrong with a URDF's <inertial> kept as given (empty: nothing)
  /// The name of the link joint j moves (a URDF's link after the joint); empty: the joint's name stands for it.
  std::string link_name;
  /// Links riding on this joint below a held joint of a side branch (a URDF's head or fingers): bodies of their own,
  /// which self-collision checks against the neighbouring joints' links (RobotModel::Body::branch).
  std::vector<std::string> branch_links;
  /// Named frames riding on this joint's link: a URDF's links after the joint (the chain's, those fixed to them,
  /// side branches), each with its pose in the joint's link frame. Frame tasks name them (RobotModel::frames()).
  std::vector<std::pair<std::string, Eigen::Isometry3d>> frames;
  /// Collision shapes of the link that joint j moves, in the link frame (the joint's frame after its motion, before
  /// the fixed transform to the next joint). A capsule with neither `length` nor `from`/`to` runs along the link:
  /// from the joint's origin to the next joint's origin (the end effector's, for the last joint).
  std::vector<ShapeSpec> collision;
};

/// Everything needed to build a RobotModel; filled by the TOML loader or by code (tests, generators).
/// The most joints a chain may have. Every step works on n x n matrices, so a chain past this (a generated 12,000-joint
/// URDF, say) would need gigabytes; robots are refused beyond it at load.
inline constexpr std::size_t kMaxJoints = 1000;

/// A visual element of a URDF robot: what a viewer draws (`redres view`, docs/viewer.md); nothing is computed from it.
/// A mesh (the file found for the URDF's name), a box, a cylinder (along z) or a sphere, posed in the frame of the
/// joint it rides on (the frame frames.csv records), or for the base's links in the base pose P's frame.
struct VisualSpec {
  enum class Kind { kMesh, kBox, kCylinder, kSphere };
  Kind kind = Kind::kMesh;
  int joint = -1;                                          //!< the joint it rides on (0-based); -1: the base
  std::string link;                                        //!< the URDF link it belongs to
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  //!< in that joint's frame (the base: in P's frame)
  std::string uri;                                         //!< a mesh: the name the URDF gives
  std::filesystem::path file;                              //!< a mesh: the file found (empty: not found)
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();         //!< a mesh: its scale
  std::array<double, 3> size{0.0, 0.0, 0.0};               //!< a box: its sides (m)
  double radius = 0.0, length = 0.0;                       //!< a cylinder's or a sphere's (m)
  std::optional<std::array<double, 4>> rgba;               //!< the URDF material's colour, if it gives one
  std::string problem;  //!< why a mesh is not drawn (its file was not found); empty when it is
};

struct RobotSpec {
  std::string name;                                   //!< robot name
  ChainKind kind = ChainKind::kPlanar;                //!< planar or spatial
  DhConvention convention = DhConvention::kStandard;  //!< spatial only
  TaskRows task = TaskRows::kPosition;                //!< task rows
  /// A subset of the task's rows by name, in row order (empty: every row of `task`). When given it decides `task`:
  /// pose when it names an orientation row (phi, wx, wy or wz), position otherwise.
  std::vector<std::string> task_axes;
  std::vector<JointSpec> joints;                                   //!< the chain, base to tip
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();          //!< P, the base in the world (planar: in-plane)
  Eigen::Isometry3d end_effector = Eigen::Isometry3d::Identity();  //!< E, in the last joint's frame
  Eigen::VectorXd home;                                            //!< home configuration (size n; empty = zeros)
  std::string source;                                              //!< file the spec came from (may be empty)
  /// Link pairs (joint indices, 0-based) never checked against each other, besides adjacent links, which never are.
  std::vector<std::pair<int, int>> collision_exclude;
  /// The joints of a URDF's side branches, and mimic joints off the chain, with the positions they are held at (for
  /// reports; the shapes are placed with them already).
  std::vector<std::pair<std::string, double>> held_joints;
  /// Body pairs, by name (RobotModel::bodies(): a URDF's links), never checked against each other.
  std::vector<std::pair<std::string, std::string>> collision_exclude_bodies;
  /// A URDF robot's visual elements (drawn by the viewer only).
  std::vector<VisualSpec> visuals;
};

/// An immutable robot model. Construction validates the spec and throws std::invalid_argument on misuse.
class RobotModel {
 public:
  /// Validates and precomputes the fixed transforms.
  explicit RobotModel(RobotSpec spec);

  /// Robot name.
  [[nodiscard]] const std::string& name() const noexcept { return spec_.name; }
  /// Planar or spatial.
  [[nodiscard]] ChainKind kind() const noexcept { return spec_.kind; }
  /// DH convention (spatial chains).
  [[nodiscard]] DhConvention convention() const noexcept { return spec_.convention; }
  /// Which reference the task follows: position, or position and orientation (pose).
  [[nodiscard]] TaskRows task() const noexcept { return spec_.task; }
  /// Number of joints n.
  [[nodiscard]] int dof() const noexcept { return static_cast<int>(spec_.joints.size()); }
  /// Number of task rows m: the rows of J and of the task constraint (2 or 3 planar, 3 or 6 spatial, fewer when
  /// `task_axes` names a subset).
  [[nodiscard]] int task_dim() const noexcept { return static_cast<int>(task_rows_.size()); }
  /// Number of reference rows: the size of f, r_d and r_d_dot (position rows, then orientation rows for a pose).
  [[nodiscard]] int reference_dim() const noexcept { return static_cast<int>(reference_names_.size()); }
  /// Number of position rows of the reference: 2 (planar) or 3 (spatial); its first rows.
  [[nodiscard]] int position_rows() const noexcept { return spec_.kind == ChainKind::kPlanar ? 2 : 3; }
  /// Whether the reference has orientation rows after the position rows (a pose task, or a subset of one).
  [[nodiscard]] bool has_orientation_rows() const noexcept { return spec_.task == TaskRows::kPose; }
  /// Names of the task rows, e.g. {"x", "y"}.
  [[nodiscard]] const std::vector<std::string>& task_names() const noexcept { return task_names_; }
  /// Names of the reference rows (every task row, and the rows a subset leaves free).
  [[nodiscard]] const std::vector<std::string>& reference_names() const noexcept { return reference_names_; }
  /// The reference row of each task row (size task_dim(); 0, 1, ..., m-1 unless `task_axes` names a subset).
  [[nodiscard]] const std::vector<int>& task_rows() const noexcept { return task_rows_; }
  /// Whether reference row r is a task row (false for the rows a subset leaves free).
  [[nodiscard]] bool tracks(int r) const noexcept { return (tracked_ >> r) & 1U; }
  /// The row of the spatial 6-vector (linear velocity; angular velocity) that task row i takes (planar phi: 5).
  [[nodiscard]] int twist_row(int i) const { return twist_rows_[static_cast<std::size_t>(i)]; }
  /// Joint j (0-based).
  [[nodiscard]] const JointSpec& joint(int j) const { return spec_.joints.at(static_cast<std::size_t>(j)); }
  /// All joints.
  [[nodiscard]] const std::vector<JointSpec>& joints() const noexcept { return spec_.joints; }
  /// Home configuration.
  [[nodiscard]] const Eigen::VectorXd& home() const noexcept { return spec_.home; }
  /// Position limits theta^- and theta^+.
  [[nodiscard]] const Eigen::VectorXd& lower_limits() const noexcept { return lower_; }
  [[nodiscard]] const Eigen::VectorXd& upper_limits() const noexcept { return upper_; }
  /// Base pose P in the world.
  [[nodiscard]] const Eigen::Isometry3d& base() const noexcept { return spec_.base; }
  /// Planar chains: the base's rotation about z (rad), which starts the end-effector angle phi.
  [[nodiscard]] double base_angle() const noexcept { return base_angle_; }
  /// Planar chains: the end effector's fixed rotation about z (rad), which ends the end-effector angle phi.
  [[nodiscard]] double end_effector_angle() const noexcept { return end_effector_angle_; }
  /// Unit axis u_j of joint j, in the frame after A_j.
  [[nodiscard]] const Eigen::Vector3d& axis(int j) const { return axes_[static_cast<std::size_t>(j)]; }
  /// End-effector transform E in the last joint's frame.
  [[nodiscard]] const Eigen::Isometry3d& end_effector() const noexcept { return spec_.end_effector; }
  /// Fixed transforms before and after joint j's motion.
  [[nodiscard]] const Eigen::Isometry3d& before(int j) const { return before_[static_cast<std::size_t>(j)]; }
  [[nodiscard]] const Eigen::Isometry3d& after(int j) const { return after_[static_cast<std::size_t>(j)]; }
  /// The shape of joint j's fixed transforms and axis, for the kinematics' short cuts (which compute the products
  /// they stand for exactly): before(j) is the identity, after(j) a pure translation, the axis exactly z.
  struct FrameShape {
    bool before_identity = false;
    bool after_translation = false;
    bool z_axis = false;
  };
  [[nodiscard]] const FrameShape& frame_shape(int j) const { return shapes_[static_cast<std::size_t>(j)]; }
  /// Whether every joint is revolute.
  [[nodiscard]] bool all_revolute() const noexcept { return all_revolute_; }
  /// File the model was loaded from (empty when built in code).
  [[nodiscard]] const std::string& source() const noexcept { return spec_.source; }
  /// The spec the model was built from.
  [[nodiscard]] const RobotSpec& spec() const noexcept { return spec_; }

  /// A rigid body the shapes belong to: the link a joint moves, or a link riding on it (a URDF's links each, by name:
  /// the links fixed after the joint, and the links of side branches hanging from them).
  struct Body {
    std::string name;     //!< the URDF link's name (the joint's link_name, or the joint's name, for other robots)
    int link = 0;         //!< the joint it rides on (0-based)
    bool branch = false;  //!< below a held joint of a side branch (JointSpec::branch_links)
  };
  /// Every body, in joint order; the first body of each joint is the link the joint moves (body_of_joint()).
  [[nodiscard]] const std::vector<Body>& bodies() const noexcept { return bodies_; }
  /// The body the joint's link is.
  [[nodiscard]] int body_of_joint(int j) const { return joint_body_[static_cast<std::size_t>(j)]; }
  /// The body named `name`, or -1.
  [[nodiscard]] int find_body(const std::string& name) const;

  /// A frame a task can name: a link's frame, or the end effector's, fixed in the frame of the joint it rides on.
  struct Frame {
    std::string name;  //!< the link's name (URDF), or the joint's; "end_effector"
    int joint = 0;     //!< the joint whose link frame it rides in (0-based)
    Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();  //!< its pose in that link frame
  };
  /// Every named frame: each joint's link (by its URDF link name, else the joint's name), the other URDF links
  /// riding on the joints (JointSpec::frames), and "end_effector" (the task's frame, E).
  [[nodiscard]] const std::vector<Frame>& frames() const noexcept { return frames_; }
  /// The frame named `name`, or -1.
  [[nodiscard]] int find_frame(const std::string& name) const;

  /// One collision shape of a link: the link (joint index), its body and the shape, with its pose in the link frame
  /// resolved (a capsule along the link gets its end points here).
  struct LinkShape {
    int link = 0;            //!< joint index j (0-based)
    int body = 0;            //!< index into bodies()
    ShapeSpec spec;          //!< the shape as FCL will see it (from/to filled in for capsules along the link)
    Eigen::Isometry3d pose;  //!< pose of the shape in the link frame
  };
  /// Every collision shape of every link, in joint order.
  [[nodiscard]] const std::vector<LinkShape>& link_shapes() const noexcept { return link_shapes_; }
  /// A URDF robot's visual elements (empty for other robots): what a viewer draws.
  [[nodiscard]] const std::vector<VisualSpec>& visuals() const noexcept { return spec_.visuals; }
  /// Whether links i and j are checked against each other for self-collision (not equal, not adjacent, not
  /// excluded by the robot file).
  [[nodiscard]] bool self_collision_pair(int i, int j) const;
  /// Whether bodies a and b are checked against each other: not on the same joint; not on neighbouring joints unless
  /// one of them is a side-branch body (Body::branch); their joints not excluded; the bodies not excluded by name.
  [[nodiscard]] bool self_collision_bodies(int a, int b) const;

  /// Velocity limits of every joint at theta; writes into lower/upper (size n). Allocation-free.
  void velocity_limits(const Eigen::Ref<const Eigen::VectorXd>& theta, Eigen::Ref<Eigen::VectorXd> lower,
                       Eigen::Ref<Eigen::VectorXd> upper) const;
  /// Whether every joint has an acceleration limit (a jerk limit).
  [[nodiscard]] bool has_acceleration_limits() const noexcept { return first_without_acceleration_limit() < 0; }
  [[nodiscard]] bool has_jerk_limits() const noexcept { return first_without_jerk_limit() < 0; }
  /// The first joint (0-based) without an acceleration (jerk) limit, or -1 when every joint has one: for messages.
  [[nodiscard]] int first_without_acceleration_limit() const noexcept;
  [[nodiscard]] int first_without_jerk_limit() const noexcept;
  /// Acceleration (jerk) limits of every joint at theta, into lower/upper (size n); a joint without a law gets
  /// -inf, +inf. Allocation-free.
  void acceleration_limits(const Eigen::Ref<const Eigen::VectorXd>& theta, Eigen::Ref<Eigen::VectorXd> lower,
                           Eigen::Ref<Eigen::VectorXd> upper) const;
  void jerk_limits(const Eigen::Ref<const Eigen::VectorXd>& theta, Eigen::Ref<Eigen::VectorXd> lower,
                   Eigen::Ref<Eigen::VectorXd> upper) const;

 private:
  RobotSpec spec_;
  std::vector<std::string> task_names_, reference_names_;
  std::vector<int> task_rows_, twist_rows_;
  unsigned tracked_ = 0;  // bit r: reference row r is a task row
  Eigen::VectorXd lower_, upper_;
  std::vector<Eigen::Isometry3d> before_, after_;
  std::vector<Frame> frames_;
  std::vector<Eigen::Vector3d> axes_;
  std::vector<FrameShape> shapes_;
  bool all_revolute_ = true;
  double base_angle_ = 0.0;
  double end_effector_angle_ = 0.0;
  std::vector<LinkShape> link_shapes_;
  std::vector<Body> bodies_;
  std::vector<int> joint_body_;
  std::vector<std::pair<int, int>> excluded_bodies_;
};

/// The rows of a pose task, in order ("x", "y", "phi" planar; "x", "y", "z", "wx", "wy", "wz" spatial); a position
/// task has the first two (planar) or three (spatial).
[[nodiscard]] const std::vector<std::string>& pose_row_names(ChainKind kind);

/// Text name of an enum value ("planar", "revolute", "dh", "position", ...).
[[nodiscard]] const char* to_string(ChainKind kind);
[[nodiscard]] const char* to_string(JointType type);
[[nodiscard]] const char* to_string(DhConvention convention);
[[nodiscard]] const char* to_string(TaskRows rows);

}  // namespace redres

#pragma once
/// @file
/// `frame`: a task on any named frame of the chain (RobotModel::frames(): a link by its name, or "end_effector"),
/// at a point fixed in that frame (`point`), with the rows the user picks:
/// - "x", "y", "z": the point's world position; J = the rows of its velocity Jacobian, d = p_d_dot + K (p_d - p);
/// - "wx", "wy", "wz": the frame's orientation; J = the rows of its angular velocity Jacobian, d = K e with e the
///   rotation vector of R_d R';
/// - "axis": a direction fixed in the frame (`axis`) turned towards a world direction (`axis_target`, default the
///   direction at the start); two rows: u' omega = K u' (a x a_d) and v' omega = K v' (a x a_d), with u, v an
///   orthonormal basis of the plane normal to a.
/// The reference (`reference`): "start" (the frame's pose at the first step of a run), "fixed" (`position`, `rpy`)
/// or "path" (the position rows follow the scenario's path and its velocity; orientation rows and the axis hold their
/// start).
///
/// The end-effector task. On the frame "end_effector" at its origin with reference "path", a row the robot tracks
/// (its task rows: x, y, z, and with a pose task the orientation rows, a planar robot's "phi" being "wz") is the
/// robot's task row itself: J is that row of the kinematics' task Jacobian, the error r_d - f(theta) (a spatial
/// orientation's is the rotation vector of R_d R', R_d the path's orientation), and d = r_d_dot + K e. Such a task
/// works at the acceleration level too (when every row is a task row and the mode is not "inequality"): its rows are
/// those of the error dynamics e_ddot + 2K e_dot + K^2 e = 0,
///   J x = r_d_ddot - J_dot theta_dot + 2K (r_d_dot - J theta_dot) + K^2 e,
/// with J_dot theta_dot = sum_i theta_dot_i (dJ/dtheta_i) theta_dot. The constraint `task_tracking` (eq. 6) is this
/// task on every task row, held as a hard constraint at every priority level (constraints/task_tracking.hpp).
///
/// In mode "inequality" the position rows are kept within `lower` <= p <= `upper` (world coordinates, m; one entry per
/// row, +-inf where open): K (lower - p) <= J x <= K (upper - p).
/// `damping` (soft mode): the Levenberg-Marquardt term lambda^2 = damping^2 (1 - (sigma / damping_threshold)^2) that
/// the task's level adds to W while the rows' smallest singular value sigma is below the threshold.
/// Records `<name>_error` (m: the norm of the position rows' error; inequality: how far outside its bounds) and, with
/// orientation rows, `<name>_orientation_error` (rad); the summary has their maxima.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "redres/control/task.hpp"
#include "redres/run/plugin_output.hpp"

namespace redres {

/// The configuration of `frame`.
struct FrameTaskConfig {
  std::string frame = "end_effector";                  //!< a name of RobotModel::frames()
  std::array<double, 3> point{0.0, 0.0, 0.0};          //!< the point in the frame (m)
  std::vector<std::string> rows{};                     //!< subset of x, y, z, wx, wy, wz, axis (default: position)
  std::optional<std::array<double, 3>> axis{};         //!< for "axis": the direction in the frame
  std::optional<std::array<double, 3>> axis_target{};  //!< for "axis": the world direction (default: at the start)
  std::string reference = "start";                     //!< "start", "fixed" or "path"
  std::optional<std::array<double, 3>> position{};     //!< reference = "fixed": the world position (m)
  std::optional<std::array<double, 3>> rpy{};          //!< reference = "fixed": roll, pitch, yaw (rad)
  PerJoint gain = 1.0;                                 //!< K (1/s): one number or one per row
  std::optional<std::vector<double>> lower{};          //!< inequality: per row (m)
  std::optional<std::vector<double>> upper{};          //!< inequality: per row (m)
  double damping = 0.0;                                //!< lambda_max (soft mode); 0: none
  double damping_threshold = 0.05;                     //!< sigma below which damping grows

  static const Schema<FrameTaskConfig>& schema();
};

class FrameTaskData;

/// A task on a frame.
class FrameTask final : public Configured<Task, FrameTaskConfig>, public PluginOutput {
 public:
  static constexpr const char* kType = "frame";
  FrameTask(const Config& config, const RobotModel& robot);

  [[nodiscard]] int rows() const override { return static_cast<int>(kinds_.size()); }
  [[nodiscard]] std::string row_name(int r) const override;
  [[nodiscard]] std::string row_unit(int r) const override;
  [[nodiscard]] bool has_lower(int r) const override;
  [[nodiscard]] bool has_upper(int r) const override;
  void check_mode() const override;
  [[nodiscard]] std::unique_ptr<PluginData> make_data() const override;
  void start(PluginData* data) const override;
  /// The frame's index in RobotModel::frames().
  [[nodiscard]] int frame() const noexcept { return frame_; }
  /// The velocity level always; the acceleration level when every row is one of the robot's task rows (above) and
  /// the mode is not "inequality".
  [[nodiscard]] bool supports(ControlOrder order) const override;
  /// The kinematics' task Jacobian when a row is a task row (at the acceleration level the scheme asks for its
  /// derivative too); else the link frames.
  [[nodiscard]] KinematicsLevel kinematics_level() const override;

  /// The end-effector task's rows written straight into the builder's equality rows, when they are the robot's task
  /// rows in their order at the velocity level in mode "equality" (the paper's task): J from the kinematics,
  /// d = r_d_dot + K e, each row's error kept in `data` (which make_data() made), but not the errors' norms, which
  /// only a recorded task's columns read (a constraint's rows are not recorded). Returns false, writing nothing, for
  /// any other task; its rows then come from evaluate() and write_task_terms(). The same rows either way.
  bool write_rows_in_order(const Context& ctx, PluginData* data, QpBuilder& builder) const;

  [[nodiscard]] std::vector<std::string> recorded_columns() const override;
  void record(const PluginData* data, double* values) const override;
  void summarise(const RobotModel& robot, const Trajectory& run, const PluginData* data,
                 std::vector<Metric>& out) const override;

 private:
  enum class Row { kX, kY, kZ, kWx, kWy, kWz, kAxisU, kAxisV };
  void compute(const Context& ctx, TaskData& data) const override;
  // Writes row r as the robot's task row `task_row` (J, error, d; e_path: the orientation error of a spatial pose
  // task's rows); returns its error.
  double write_task_row(const Context& ctx, int r, int task_row, const Eigen::Vector3d& e_path, TaskTerms& t) const;
  // compute() for the rows of in_order_ at the velocity level, equality or soft, undamped (the paper's task): J into
  // J_out (column-major, leading dimension ld), d into d_out, the errors into own (with norms: their norms too).
  void velocity_rows_in_order(const Context& ctx, FrameTaskData& own, double* J_out, Eigen::Index ld, double* d_out,
                              bool norms) const;
  [[nodiscard]] bool has_position_rows() const;
  [[nodiscard]] bool has_orientation_rows() const;

  enum class Reference { kStart, kFixed, kPath };
  int frame_ = -1;
  Reference reference_ = Reference::kStart;  // config_.reference, read once
  std::vector<Row> kinds_;
  // For each row: the robot's task row it is (the index into the kinematics' J, and its reference row), or -1.
  std::vector<int> task_row_, reference_row_;
  bool all_task_rows_ = false;  // every row is a task row: the frame's own pose and Jacobian are not needed
  bool any_task_rows_ = false;
  bool in_order_ = false;      // row r is the robot's task row r, for every task row (the end-effector task's J whole)
  bool spatial_pose_ = false;  // the robot's reference has a spatial orientation (a rotation vector in rows 3 to 5)
  Eigen::VectorXd gain_;
  Eigen::Vector3d point_, axis_;
  std::optional<Eigen::Vector3d> axis_target_;
  Eigen::Vector3d position_;
  Eigen::Matrix3d rotation_;
};

}  // namespace redres

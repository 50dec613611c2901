#include "redres/tasks/frame_task.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "redres/common/hot.hpp"
#include "redres/model/frames.hpp"
#include "redres/run/trajectory.hpp"

namespace redres {

/// A frame task's rows, with its pose at the first step and its errors.
class FrameTaskData final : public TaskData {
 public:
  Eigen::Matrix<double, 6, Eigen::Dynamic> J6;   // the frame's [v; omega] Jacobian
  bool captured = false;                         // the start pose is known
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero();  // the start position
  Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();
  Eigen::Vector3d a0 = Eigen::Vector3d::UnitZ();  // the axis's world direction at the start
  double position_error = 0.0, orientation_error = 0.0;
};

namespace {

constexpr const char* kRowNames[] = {"x", "y", "z", "wx", "wy", "wz", "axis_u", "axis_v"};

Eigen::Vector3d vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

}  // namespace

const Schema<FrameTaskConfig>& FrameTaskConfig::schema() {
  using C = FrameTaskConfig;
  static const Schema<C> s{
      {field("frame", &C::frame, "", "the frame: a link's name or \"end_effector\" (redres robot lists them)"),
       field("point", &C::point, "m", "a point fixed in the frame, in its axes (default its origin)"),
       field("rows", &C::rows, "",
             "the rows: a subset of \"x\", \"y\", \"z\" (position), \"wx\", \"wy\", \"wz\" (orientation), \"axis\" "
             "(default: the position rows)"),
       field("axis", &C::axis, "", "for the \"axis\" rows: a direction fixed in the frame"),
       field("axis_target", &C::axis_target, "", "for the \"axis\" rows: the world direction (default: at the start)"),
       field("reference", &C::reference, "",
             "\"start\" (the pose at the first step), \"fixed\" (position, rpy) or \"path\" (the position rows follow "
             "the scenario's path)",
             rule<std::string>("one of 'start', 'fixed', 'path'",
                               [](const std::string& r) { return r == "start" || r == "fixed" || r == "path"; })),
       field("position", &C::position, "m", "reference = \"fixed\": the world position"),
       field("rpy", &C::rpy, "rad", "reference = \"fixed\": roll, pitch, yaw of the orientation (default 0)"),
       field("gain", &C::gain, "1/s", "feedback gain K: one number or one per row", at_least<PerJoint>(0.0)),
       field("lower", &C::lower, "m", "mode = \"inequality\": a lower bound per row (-inf: none)"),
       field("upper", &C::upper, "m", "mode = \"inequality\": an upper bound per row (inf: none)"),
       field("damping", &C::damping, "1/s",
             "soft mode: the largest Levenberg-Marquardt damping lambda, reached as the rows lose rank",
             between(0.0, 1e3)),
       field("damping_threshold", &C::damping_threshold, "",
             "the smallest singular value of the rows below which the damping grows", greater(0.0))}};
  return s;
}

FrameTask::FrameTask(const Config& config, const RobotModel& robot)
    : Configured(kType, config), point_(vec(config_.point)), axis_(Eigen::Vector3d::UnitZ()) {
  set_dof(robot.dof());
  frame_ = robot.find_frame(config_.frame);
  if (frame_ < 0) {
    std::string names;
    for (const auto& f : robot.frames()) names += (names.empty() ? "'" : ", '") + f.name + "'";
    throw FieldError("frame",
                     "no frame '" + config_.frame + "' on robot '" + robot.name() + "'; its frames are " + names);
  }
  std::vector<std::string> names = config_.rows;
  if (names.empty()) {
    names = robot.kind() == ChainKind::kPlanar ? std::vector<std::string>{"x", "y"}
                                               : std::vector<std::string>{"x", "y", "z"};
  }
  for (const std::string& r : names) {
    if (r == "axis") {
      if (!config_.axis) throw FieldError("rows", "the \"axis\" rows need `axis` (a direction in the frame)");
      kinds_.push_back(Row::kAxisU);
      kinds_.push_back(Row::kAxisV);
      continue;
    }
    const auto* it =
        std::find_if(std::begin(kRowNames), std::begin(kRowNames) + 6, [&r](const char* name) { return r == name; });
    if (it == std::begin(kRowNames) + 6) {
      throw FieldError("rows",
                       "unknown row '" + r + "'; expected \"x\", \"y\", \"z\", \"wx\", \"wy\", \"wz\" or \"axis\"");
    }
    const Row kind = static_cast<Row>(it - std::begin(kRowNames));
    if (std::find(kinds_.begin(), kinds_.end(), kind) != kinds_.end()) {
      throw FieldError("rows", "row '" + r + "' is listed twice");
    }
    kinds_.push_back(kind);
  }
  const bool axis = std::find(kinds_.begin(), kinds_.end(), Row::kAxisU) != kinds_.end();
  const bool rotation =
      std::any_of(kinds_.begin(), kinds_.end(), [](Row k) { return k == Row::kWx || k == Row::kWy || k == Row::kWz; });
  if (axis && rotation)
    throw FieldError("rows", "\"axis\" and the orientation rows \"wx\", \"wy\", \"wz\" exclude each other");
  if (config_.axis) {
    axis_ = vec(*config_.axis);
    if (!(axis_.norm() > 1e-9) || !axis_.allFinite()) throw FieldError("axis", "expected a non-zero direction");
    axis_.normalize();
  }
  if (config_.axis_target) {
    Eigen::Vector3d a = vec(*config_.axis_target);
    if (!(a.norm() > 1e-9) || !a.allFinite()) throw FieldError("axis_target", "expected a non-zero direction");
    axis_target_ = a.normalized();
  }
  gain_ = config_.gain.resolve(rows(), "gain", "row");
  reference_ = config_.reference == "fixed"  ? Reference::kFixed
               : config_.reference == "path" ? Reference::kPath
                                             : Reference::kStart;
  if (reference_ == Reference::kFixed) {
    if (has_position_rows() && !config_.position) {
      throw FieldError("position", "reference = \"fixed\" with position rows needs `position` (m, world)");
    }
    position_ = config_.position ? vec(*config_.position) : Eigen::Vector3d::Zero();
    const Eigen::Vector3d rpy = config_.rpy ? vec(*config_.rpy) : Eigen::Vector3d::Zero();
    rotation_ =
        (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
  } else {
    if (config_.position) throw FieldError("position", "is read only with reference = \"fixed\"");
    if (config_.rpy) throw FieldError("rpy", "is read only with reference = \"fixed\"");
    position_.setZero();
    rotation_.setIdentity();
  }
  if (reference_ == Reference::kPath && robot.kind() == ChainKind::kPlanar) {
    for (Row k : kinds_) {
      if (k == Row::kZ) throw FieldError("rows", "a planar robot's path has no z row");
    }
  }
  // The rows that are the robot's own task rows (the end-effector task; see the header).
  task_row_.assign(kinds_.size(), -1);
  reference_row_.assign(kinds_.size(), -1);
  if (reference_ == Reference::kPath && frame_ == robot.find_frame("end_effector") && point_.isZero(0.0)) {
    const std::vector<std::string>& tracked = robot.task_names();
    for (std::size_t r = 0; r < kinds_.size(); ++r) {
      const int kind = static_cast<int>(kinds_[r]);
      if (kind >= 6) continue;  // the axis rows
      const std::string name = robot.kind() == ChainKind::kPlanar && kinds_[r] == Row::kWz ? "phi" : kRowNames[kind];
      const auto it = std::find(tracked.begin(), tracked.end(), name);
      if (it == tracked.end()) continue;
      task_row_[r] = static_cast<int>(it - tracked.begin());
      reference_row_[r] = robot.task_rows()[static_cast<std::size_t>(task_row_[r])];
    }
  }
  all_task_rows_ = std::all_of(task_row_.begin(), task_row_.end(), [](int i) { return i >= 0; });
  any_task_rows_ = std::any_of(task_row_.begin(), task_row_.end(), [](int i) { return i >= 0; });
  in_order_ = all_task_rows_ && rows() == robot.task_dim();
  for (int r = 0; r < rows() && in_order_; ++r) in_order_ = task_row_[static_cast<std::size_t>(r)] == r;
  spatial_pose_ = robot.kind() == ChainKind::kSpatial && robot.has_orientation_rows();
  for (const auto* bounds : {&config_.lower, &config_.upper}) {
    if (*bounds && static_cast<int>((*bounds)->size()) != rows()) {
      throw FieldError(
          bounds == &config_.lower ? "lower" : "upper",
          "expected one bound per row (" + std::to_string(rows()) + "), got " + std::to_string((*bounds)->size()));
    }
  }
}

void FrameTask::check_mode() const {
  if (mode() == TaskMode::kInequality) {
    if (!config_.lower && !config_.upper) {
      throw FieldError("mode", "mode = \"inequality\" needs `lower` or `upper` (one bound per row, m)");
    }
    if (has_orientation_rows()) {
      throw FieldError("rows", "mode = \"inequality\" bounds position rows only (\"x\", \"y\", \"z\")");
    }
    bool any = false;
    for (int r = 0; r < rows(); ++r) any = any || has_lower(r) || has_upper(r);
    if (!any) throw FieldError("lower", "every bound is infinite: the task would bound nothing");
    for (int r = 0; r < rows(); ++r) {
      if (has_lower(r) && has_upper(r) &&
          (*config_.lower)[static_cast<std::size_t>(r)] > (*config_.upper)[static_cast<std::size_t>(r)]) {
        throw FieldError("lower", "row '" + row_name(r) + "': lower > upper");
      }
    }
  } else {
    if (config_.lower) throw FieldError("lower", "is read only with mode = \"inequality\"");
    if (config_.upper) throw FieldError("upper", "is read only with mode = \"inequality\"");
  }
  if (config_.damping > 0.0 && mode() != TaskMode::kSoft) {
    throw FieldError("damping", "damping softens the rows into a damped least squares: use mode = \"soft\"");
  }
}

bool FrameTask::supports(ControlOrder order) const {
  return order == ControlOrder::kVelocity || (all_task_rows_ && mode() != TaskMode::kInequality);
}

KinematicsLevel FrameTask::kinematics_level() const {
  return any_task_rows_ ? KinematicsLevel::kJacobian : KinematicsLevel::kPosition;
}

std::string FrameTask::row_name(int r) const {
  return kRowNames[static_cast<int>(kinds_[static_cast<std::size_t>(r)])];
}

std::string FrameTask::row_unit(int r) const {
  return static_cast<int>(kinds_[static_cast<std::size_t>(r)]) < 3 ? "m" : "rad";
}

bool FrameTask::has_lower(int r) const {
  return config_.lower && std::isfinite((*config_.lower)[static_cast<std::size_t>(r)]);
}

bool FrameTask::has_upper(int r) const {
  return config_.upper && std::isfinite((*config_.upper)[static_cast<std::size_t>(r)]);
}

bool FrameTask::has_position_rows() const {
  return std::any_of(kinds_.begin(), kinds_.end(), [](Row k) { return static_cast<int>(k) < 3; });
}

bool FrameTask::has_orientation_rows() const {
  return std::any_of(kinds_.begin(), kinds_.end(), [](Row k) { return static_cast<int>(k) >= 3; });
}

std::unique_ptr<PluginData> FrameTask::make_data() const {
  auto data = std::make_unique<FrameTaskData>();
  size_rows(data->rows, dof());
  data->J6 = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, dof());
  return data;
}

void FrameTask::start(PluginData* data) const {
  auto& own = static_cast<FrameTaskData&>(*data);
  own.captured = false;
  own.position_error = own.orientation_error = 0.0;
}

REDRES_HOT double FrameTask::write_task_row(const Context& ctx, int r, int task_row, const Eigen::Vector3d& e_path,
                                            TaskTerms& t) const {
  // The robot's task row: J's row, e = r_d - f(theta) (a spatial orientation's: the rotation vector of R_d R'), the
  // path's velocity (and at the acceleration level its acceleration).
  const KinematicsData& kin = *ctx.kinematics;
  const Eigen::Index n = kin.J.cols(), m = kin.J.rows();
  const int ref = reference_row_[static_cast<std::size_t>(r)];
  for (Eigen::Index c = 0; c < n; ++c) t.J(r, c) = kin.J(task_row, c);
  const Eigen::VectorXd& r_d = *ctx.r_d;
  const double e = spatial_pose_ && ref >= 3 ? e_path(ref - 3) : r_d(ref) - kin.f(ref);
  t.error(r) = e;
  const double k = gain_(r);
  const double r_d_dot = (*ctx.r_d_dot)(ref);
  if (ctx.order == ControlOrder::kVelocity) {
    t.d(r) = r_d_dot + k * e;
    return e;
  }
  // d = r_d_ddot - J_dot theta_dot + 2K (r_d_dot - J theta_dot) + K^2 e, with J_dot theta_dot summed as
  // sum_j theta_dot_j (dJ/dtheta_j theta_dot).
  const double* vel = ctx.theta_dot->data();
  double jv = 0.0, jdv = 0.0;
  for (Eigen::Index c = 0; c < n; ++c) jv += kin.J(task_row, c) * vel[c];
  const double* dj = kin.dJ.data();
  for (Eigen::Index j = 0; j < n; ++j) {
    if (vel[j] == 0.0) continue;
    for (Eigen::Index c = 0; c < n; ++c) jdv += dj[(j * n + c) * m + task_row] * (vel[j] * vel[c]);
  }
  const Eigen::VectorXd& r_d_ddot = *ctx.r_d_ddot;
  t.d(r) = r_d_ddot(ref) - jdv + 2.0 * k * (r_d_dot - jv) + k * k * e;
  return e;
}

REDRES_HOT void FrameTask::velocity_rows_in_order(const Context& ctx, FrameTaskData& own, double* J_out,
                                                  Eigen::Index ld, double* d_out, bool norms) const {
  // The end-effector task at the velocity level, its rows the robot's task rows in their order (the paper's): J
  // whole (into J_out, column-major with leading dimension ld), then each row's e = r_d - f(theta) (a spatial
  // orientation's: the rotation vector of R_d R') and d = r_d_dot + K e (into d_out).
  TaskTerms& t = own.rows;
  const KinematicsData& kin = *ctx.kinematics;
  const Eigen::Index reference = ctx.robot->reference_dim();
  REDRES_REQUIRE(ctx.r_d != nullptr && ctx.r_d_dot != nullptr && ctx.r_d->size() == reference &&
                     ctx.r_d_dot->size() == reference && kin.J.rows() == t.J.rows() && kin.J.cols() == t.J.cols(),
                 "frame task",
                 "the context carries the path's r_d and r_d_dot, one entry per reference row, and the robot's "
                 "kinematics");
  const int k = rows();
  const Eigen::Index n = kin.J.cols();
  const double* __restrict from = kin.J.data();
  double* __restrict to = J_out;
  if (ld == k) {
    for (Eigen::Index i = 0; i < k * n; ++i) to[i] = from[i];
  } else {
    for (Eigen::Index c = 0; c < n; ++c) {
      for (int r = 0; r < k; ++r) to[c * ld + r] = from[c * k + r];
    }
  }
  const double* r_d = ctx.r_d->data();
  const double* r_d_dot = ctx.r_d_dot->data();
  const double* f = kin.f.data();
  Eigen::Vector3d e_path = Eigen::Vector3d::Zero();
  if (spatial_pose_) e_path = orientation_error_vector(rotation_from_vector(ctx.r_d->tail<3>()), kin.ee_pose.linear());
  double pos2 = 0.0, rot2 = 0.0;
  for (int r = 0; r < k; ++r) {
    const auto i = static_cast<std::size_t>(r);
    const int ref = reference_row_[i];
    const double e = spatial_pose_ && ref >= 3 ? e_path(ref - 3) : r_d[ref] - f[ref];
    t.error(r) = e;
    d_out[r] = r_d_dot[ref] + gain_(r) * e;
    (static_cast<int>(kinds_[i]) < 3 ? pos2 : rot2) += e * e;
  }
  if (!norms) return;
  own.position_error = std::sqrt(pos2);
  own.orientation_error = std::sqrt(rot2);
}

REDRES_HOT bool FrameTask::write_rows_in_order(const Context& ctx, PluginData* data, QpBuilder& builder) const {
  if (!(in_order_ && ctx.order == ControlOrder::kVelocity && mode() == TaskMode::kEquality)) return false;
  auto& own = static_cast<FrameTaskData&>(*data);
  auto J = builder.equality_matrix();
  REDRES_REQUIRE(J.rows() == rows() && J.cols() == own.rows.J.cols(), "frame task",
                 "the builder holds one equality row per task row");
  velocity_rows_in_order(ctx, own, J.data(), J.outerStride(), builder.equality_rhs().data(), false);
  return true;
}

REDRES_HOT void FrameTask::compute(const Context& ctx, TaskData& data) const {
  auto& own = static_cast<FrameTaskData&>(data);
  if (in_order_ && ctx.order == ControlOrder::kVelocity && mode() != TaskMode::kInequality &&
      !(config_.damping > 0.0)) {
    velocity_rows_in_order(ctx, own, own.rows.J.data(), own.rows.J.rows(), own.rows.d.data(), true);
    return;
  }
  TaskTerms& t = own.rows;
  const RobotModel& robot = *ctx.robot;
  const KinematicsData& kin = *ctx.kinematics;
  // Rows that are the robot's task rows read the kinematics and the path (bounds are on the frame's own position).
  const bool task_rows = any_task_rows_ && mode() != TaskMode::kInequality;
  const bool own_frame = !(task_rows && all_task_rows_);
  // A task row's orientation error: the rotation vector of R_d R', R_d the path's orientation.
  Eigen::Vector3d e_path = Eigen::Vector3d::Zero();
  if (task_rows) {
    REDRES_REQUIRE(ctx.r_d != nullptr && ctx.r_d_dot != nullptr && ctx.r_d->size() == robot.reference_dim() &&
                       ctx.r_d_dot->size() == robot.reference_dim(),
                   "frame task", "the context carries the path's r_d and r_d_dot, one entry per reference row");
    if (spatial_pose_) {
      e_path = orientation_error_vector(rotation_from_vector(ctx.r_d->tail<3>()), kin.ee_pose.linear());
    }
  }
  if (ctx.order == ControlOrder::kAcceleration) {
    REDRES_REQUIRE(task_rows && all_task_rows_ && ctx.r_d_ddot != nullptr &&
                       ctx.r_d_ddot->size() == robot.reference_dim() && ctx.theta_dot != nullptr &&
                       ctx.theta_dot->size() == kin.J.cols() && kin.dJ.cols() == kin.J.cols() * kin.J.cols(),
                   "frame task", "at the acceleration level the context carries r_d_ddot, theta_dot and dJ");
  }
  if (!own_frame) {
    // The end-effector task: every row is one of the robot's task rows.
    double pos2 = 0.0, rot2 = 0.0;
    for (int r = 0; r < rows(); ++r) {
      const double e = write_task_row(ctx, r, task_row_[static_cast<std::size_t>(r)], e_path, t);
      (static_cast<int>(kinds_[static_cast<std::size_t>(r)]) < 3 ? pos2 : rot2) += e * e;
    }
    own.position_error = std::sqrt(pos2);
    own.orientation_error = std::sqrt(rot2);
    if (config_.damping > 0.0) {
      t.sigma_min = smallest_singular_value(t.J);
      t.damping = damping_term(t.sigma_min, config_.damping, config_.damping_threshold);
    }
    return;
  }
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (own_frame) {
    const Eigen::Isometry3d pose = frame_pose(robot, kin, frame_);
    p = pose * point_;
    R = pose.linear();
    frame_jacobian(robot, kin, frame_, point_, own.J6);
    if (!own.captured) {
      own.p0 = p;
      own.R0 = R;
      own.a0 = R * axis_;
      own.captured = true;
    }
  }
  // The reference position and velocity, orientation and axis.
  Eigen::Vector3d p_d = position_, v_d = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_d = rotation_;
  if (reference_ == Reference::kStart) {
    p_d = own.p0;
    R_d = own.R0;
  } else if (reference_ == Reference::kPath) {
    REDRES_REQUIRE(ctx.r_d != nullptr && ctx.r_d_dot != nullptr, "frame task",
                   "the context carries the path's r_d and r_d_dot (reference = \"path\")");
    const int rows_p = robot.position_rows();
    p_d.setZero();
    for (int i = 0; i < rows_p; ++i) {
      p_d(i) = (*ctx.r_d)(i);
      v_d(i) = (*ctx.r_d_dot)(i);
    }
    if (rows_p == 2) p_d.z() = p.z();
    R_d = own.R0;
  }
  const Eigen::Vector3d a = R * axis_;
  const Eigen::Vector3d a_d = axis_target_ ? *axis_target_ : own.a0;
  Eigen::Vector3d e_rot = Eigen::Vector3d::Zero();
  if (own_frame && has_orientation_rows()) e_rot = orientation_error_vector(R_d, R);
  // u, v: an orthonormal basis of the plane normal to a.
  Eigen::Vector3d u = a.unitOrthogonal();
  Eigen::Vector3d v = a.cross(u);
  const Eigen::Vector3d e_axis = a.cross(a_d);
  double pos2 = 0.0, rot2 = 0.0, violation = 0.0;
  for (int r = 0; r < rows(); ++r) {
    const Row kind = kinds_[static_cast<std::size_t>(r)];
    const double k = gain_(r);
    const int i = static_cast<int>(kind);
    const int task_row = task_rows ? task_row_[static_cast<std::size_t>(r)] : -1;
    if (task_row >= 0) {
      const double e = write_task_row(ctx, r, task_row, e_path, t);
      (i < 3 ? pos2 : rot2) += e * e;
      continue;
    }
    double e = 0.0, feedforward = 0.0;
    if (i < 3) {
      t.J.row(r) = own.J6.row(i);
      e = p_d(i) - p(i);
      feedforward = v_d(i);
      if (mode() == TaskMode::kInequality) {
        constexpr double kInf = std::numeric_limits<double>::infinity();
        const double lo = has_lower(r) ? (*config_.lower)[static_cast<std::size_t>(r)] : -kInf;
        const double hi = has_upper(r) ? (*config_.upper)[static_cast<std::size_t>(r)] : kInf;
        t.lo(r) = has_lower(r) ? k * (lo - p(i)) : -kInf;
        t.hi(r) = has_upper(r) ? k * (hi - p(i)) : kInf;
        e = std::max({0.0, lo - p(i), p(i) - hi});
        violation = std::max(violation, e);
      } else {
        pos2 += e * e;
      }
    } else if (i < 6) {
      t.J.row(r) = own.J6.row(i);
      e = e_rot(i - 3);
      rot2 += e * e;
    } else {
      const Eigen::Vector3d& n = kind == Row::kAxisU ? u : v;
      t.J.row(r) = n.transpose() * own.J6.bottomRows<3>();
      e = n.dot(e_axis);
      rot2 += e * e;
    }
    t.error(r) = e;
    if (mode() != TaskMode::kInequality) t.d(r) = feedforward + k * e;
  }
  own.position_error = mode() == TaskMode::kInequality ? violation : std::sqrt(pos2);
  own.orientation_error = std::sqrt(rot2);
  if (std::find(kinds_.begin(), kinds_.end(), Row::kAxisU) != kinds_.end()) {
    // The axis's error is the angle between a and a_d.
    own.orientation_error = std::atan2(e_axis.norm(), a.dot(a_d));
  }
  if (config_.damping > 0.0) {
    t.sigma_min = smallest_singular_value(t.J);
    t.damping = damping_term(t.sigma_min, config_.damping, config_.damping_threshold);
  }
}

std::vector<std::string> FrameTask::recorded_columns() const {
  std::vector<std::string> out;
  if (has_position_rows()) out.push_back(name() + "_error");
  if (has_orientation_rows()) out.push_back(name() + "_orientation_error");
  return out;
}

void FrameTask::record(const PluginData* data, double* values) const {
  const auto& own = static_cast<const FrameTaskData&>(*data);
  int c = 0;
  if (has_position_rows()) values[c++] = own.position_error;
  if (has_orientation_rows()) values[c++] = own.orientation_error;
}

void FrameTask::summarise(const RobotModel& /*robot*/, const Trajectory& run, const PluginData* /*data*/,
                          std::vector<Metric>& out) const {
  const auto worst = [&run, this](const std::string& column) {
    const std::size_t c = own_column(run, name(), column);
    double w = 0.0;
    for (std::size_t row = 0; row < run.size(); ++row) w = std::max(w, run(row, c));
    return w;
  };
  if (has_position_rows()) {
    out.push_back({mode() == TaskMode::kInequality ? "max_violation" : "max_error", {worst(name() + "_error")}, "m"});
  }
  if (has_orientation_rows()) out.push_back({"max_orientation_error", {worst(name() + "_orientation_error")}, "rad"});
}

namespace {
const bool kFrameTaskRegistered = task_registry().add_plugin<FrameTask>(
    "rows of a frame's position, orientation or axis towards a reference (start, fixed, the path)");
}  // namespace

}  // namespace redres

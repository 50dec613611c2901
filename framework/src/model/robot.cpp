#include "redres/model/robot.hpp"

#include "common/text.hpp"
#include "model/transforms.hpp"
#include "redres/common/hot.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>

#include <Eigen/Eigenvalues>
#include <sstream>

namespace redres {

const std::vector<std::string>& pose_row_names(ChainKind kind) {
  static const std::vector<std::string> planar{"x", "y", "phi"}, spatial{"x", "y", "z", "wx", "wy", "wz"};
  return kind == ChainKind::kPlanar ? planar : spatial;
}

const char* to_string(ChainKind kind) { return kind == ChainKind::kPlanar ? "planar" : "spatial"; }
const char* to_string(JointType type) { return type == JointType::kRevolute ? "revolute" : "prismatic"; }
const char* to_string(DhConvention convention) {
  switch (convention) {
    case DhConvention::kStandard: return "dh";
    case DhConvention::kModified: return "modified_dh";
    case DhConvention::kJointFrames: return "joints";
  }
  return "?";
}
const char* to_string(TaskRows rows) { return rows == TaskRows::kPosition ? "position" : "pose"; }

namespace {

using Eigen::AngleAxisd;
using Eigen::Isometry3d;
using Eigen::Vector3d;

void validate(const RobotSpec& spec) {
  const char* fn = "RobotModel";
  REDRES_REQUIRE(!spec.name.empty(), fn, "name is not empty");
  REDRES_REQUIRE(is_printable_name(spec.name), fn,
                 "the name is UTF-8 without control characters (got '" + printable(spec.name) + "')");
  REDRES_REQUIRE(!spec.joints.empty(), fn, "the chain has at least one joint");
  REDRES_REQUIRE(spec.joints.size() <= kMaxJoints, fn,
                 "the chain has at most " + std::to_string(kMaxJoints) + " joints (got " +
                     std::to_string(spec.joints.size()) + ")");
  REDRES_REQUIRE(spec.end_effector.matrix().allFinite(), fn, "end_effector is finite");
  REDRES_REQUIRE(spec.base.matrix().allFinite(), fn, "base is finite");
  if (spec.kind == ChainKind::kPlanar) {
    const Eigen::Matrix3d& R = spec.base.linear();
    REDRES_REQUIRE(spec.base.translation().z() == 0.0 && std::abs(R(2, 2) - 1.0) <= 1e-12 &&
                       std::abs(R(0, 2)) <= 1e-12 && std::abs(R(1, 2)) <= 1e-12,
                   fn, "a planar chain's base stays in the plane z = 0 (a translation in x, y and a rotation about z)");
  }
  std::set<std::string> names;
  for (std::size_t j = 0; j < spec.joints.size(); ++j) {
    const JointSpec& jt = spec.joints[j];
    const std::string who = "joint " + std::to_string(j + 1) + " ('" + jt.name + "')";
    REDRES_REQUIRE(!jt.name.empty(), fn, "joint " + std::to_string(j + 1) + " has a name");
    REDRES_REQUIRE(is_printable_name(jt.name), fn,
                   "joint " + std::to_string(j + 1) + "'s name is UTF-8 without control characters (got '" +
                       printable(jt.name) + "')");
    REDRES_REQUIRE(names.insert(jt.name).second, fn, who + " has a unique name");
    REDRES_REQUIRE(std::isfinite(jt.lower) && std::isfinite(jt.upper), fn, who + " limits are finite");
    REDRES_REQUIRE(jt.lower < jt.upper, fn,
                   who + " lower limit < upper limit (" + num(jt.lower) + " vs " + num(jt.upper) + ")");
    REDRES_REQUIRE(jt.velocity_limit != nullptr, fn, who + " has a velocity-limit law");
    REDRES_REQUIRE(!jt.effort_limit || (std::isfinite(*jt.effort_limit) && *jt.effort_limit > 0.0), fn,
                   who + " has an effort limit > 0 when it has one");
    REDRES_REQUIRE(
        std::isfinite(jt.a) && std::isfinite(jt.alpha) && std::isfinite(jt.d) && std::isfinite(jt.theta_offset), fn,
        who + " DH parameters are finite");
    REDRES_REQUIRE(jt.origin.matrix().allFinite(), fn, who + " origin is finite");
    REDRES_REQUIRE(jt.axis.allFinite() && jt.axis.norm() > 1e-9, fn,
                   who + " axis is a finite, non-zero vector (got [" + num(jt.axis.x()) + ", " + num(jt.axis.y()) +
                       ", " + num(jt.axis.z()) + "])");
    const bool frames = spec.kind == ChainKind::kSpatial && spec.convention == DhConvention::kJointFrames;
    if (!frames) {
      REDRES_REQUIRE(jt.axis == Eigen::Vector3d::UnitZ() && jt.origin.matrix().isIdentity(0.0), fn,
                     who + " uses the z axis and no origin (only `convention = \"joints\"` gives them)");
    }
    if (spec.kind == ChainKind::kPlanar) {
      REDRES_REQUIRE(jt.type == JointType::kRevolute, fn,
                     who + " is revolute (planar chains have revolute joints only)");
      REDRES_REQUIRE(std::isfinite(jt.length) && jt.length > 0.0, fn, who + " length > 0 (got " + num(jt.length) + ")");
    }
  }
  if (spec.home.size() != 0) {
    REDRES_REQUIRE(spec.home.size() == static_cast<Eigen::Index>(spec.joints.size()), fn,
                   "home.size() == number of joints");
    REDRES_REQUIRE(spec.home.allFinite(), fn, "home is finite");
  }
}

}  // namespace

RobotModel::RobotModel(RobotSpec spec) : spec_(std::move(spec)) {
  validate(spec_);
  const int n = dof();
  if (spec_.home.size() == 0) spec_.home = Eigen::VectorXd::Zero(n);
  lower_.resize(n);
  upper_.resize(n);
  before_.reserve(static_cast<std::size_t>(n));
  after_.reserve(static_cast<std::size_t>(n));
  axes_.reserve(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) {
    const JointSpec& jt = joint(j);
    lower_(j) = jt.lower;
    upper_(j) = jt.upper;
    const bool revolute = jt.type == JointType::kRevolute;
    if (spec_.kind == ChainKind::kPlanar) {
      before_.push_back(Isometry3d::Identity());
      after_.push_back(trans(jt.length, 0.0, 0.0));
    } else if (spec_.convention == DhConvention::kStandard) {
      before_.push_back(revolute ? rot_z(jt.theta_offset) : rot_z(jt.theta_offset) * trans(0.0, 0.0, jt.d));
      after_.push_back((revolute ? trans(0.0, 0.0, jt.d) : Isometry3d::Identity()) * trans(jt.a, 0.0, 0.0) *
                       rot_x(jt.alpha));
    } else if (spec_.convention == DhConvention::kModified) {
      const Isometry3d link = rot_x(jt.alpha) * trans(jt.a, 0.0, 0.0) * rot_z(jt.theta_offset);
      before_.push_back(revolute ? link : link * trans(0.0, 0.0, jt.d));
      after_.push_back(revolute ? trans(0.0, 0.0, jt.d) : Isometry3d::Identity());
    } else {
      before_.push_back(jt.origin);
      after_.push_back(Isometry3d::Identity());
    }
    // z stays exactly (0, 0, 1) (normalising it changes nothing), so the DH chains compute as before.
    axes_.push_back(jt.axis.normalized());
  }
  for (int j = 0; j < n; ++j) {
    const auto J = static_cast<std::size_t>(j);
    all_revolute_ = all_revolute_ && joint(j).type == JointType::kRevolute;
    shapes_.push_back({before_[J].matrix() == Eigen::Matrix4d::Identity(),
                       after_[J].linear() == Eigen::Matrix3d::Identity(), axes_[J] == Vector3d::UnitZ()});
  }
  const Eigen::Matrix3d& R = spec_.base.linear();
  base_angle_ = spec_.kind == ChainKind::kPlanar ? std::atan2(R(1, 0), R(0, 0)) : 0.0;
  const Eigen::Matrix3d& E = spec_.end_effector.linear();
  end_effector_angle_ = spec_.kind == ChainKind::kPlanar ? std::atan2(E(1, 0), E(0, 0)) : 0.0;
  // The bodies: each joint's link, then the links riding on it that have shapes (by name, in the order met).
  std::unordered_map<std::string, int> by_name;  // a URDF's side branch may have thousands of links
  const auto body_index = [&by_name](const std::string& name) {
    const auto it = by_name.find(name);
    return it == by_name.end() ? -1 : it->second;
  };
  for (int j = 0; j < n; ++j) {
    const std::string& name = joint(j).link_name.empty() ? joint(j).name : joint(j).link_name;
    REDRES_REQUIRE(body_index(name) < 0, "RobotModel",
                   "link names are unique (joint " + std::to_string(j + 1) + "'s link '" + name + "' is named twice)");
    joint_body_.push_back(static_cast<int>(bodies_.size()));
    by_name.emplace(name, static_cast<int>(bodies_.size()));
    bodies_.push_back({name, j, false});
  }
  for (int j = 0; j < n; ++j) {
    // The link frame of joint j is the joint's frame after its motion; the next joint's origin (or the end
    // effector's) is after(j) * before(j + 1) in it.
    const Isometry3d next = after_[static_cast<std::size_t>(j)] *
                            (j + 1 < n ? before_[static_cast<std::size_t>(j + 1)] : spec_.end_effector);
    for (std::size_t k = 0; k < joint(j).collision.size(); ++k) {
      ShapeSpec shape = joint(j).collision[k];
      const std::string who =
          "joint " + std::to_string(j + 1) + " ('" + joint(j).name + "') collision shape " + std::to_string(k + 1);
      REDRES_REQUIRE(!shape.velocity, "RobotModel", who + " has no velocity (only obstacles move)");
      REDRES_REQUIRE(
          !shape.is_cloud(), "RobotModel",
          who + " is a sphere, capsule, cylinder, box or convex hull (octrees and point clouds are obstacles)");
      if (shape.shape == ShapeSpec::Kind::kCapsule && !shape.from && !shape.length) {
        const Vector3d end = next.translation();
        shape.from = std::array<double, 3>{0.0, 0.0, 0.0};
        shape.to = std::array<double, 3>{end.x(), end.y(), end.z()};
      }
      try {
        check_config(shape, ShapeSpec::schema());
      } catch (const FieldError& e) {
        throw std::invalid_argument("RobotModel: " + who + ": " + e.what());
      }
      int body = joint_body_[static_cast<std::size_t>(j)];
      if (!shape.body.empty() && shape.body != bodies_[static_cast<std::size_t>(body)].name) {
        body = body_index(shape.body);
        if (body < 0) {
          body = static_cast<int>(bodies_.size());
          by_name.emplace(shape.body, body);
          const auto& branch = joint(j).branch_links;
          bodies_.push_back({shape.body, j, std::find(branch.begin(), branch.end(), shape.body) != branch.end()});
        }
        REDRES_REQUIRE(bodies_[static_cast<std::size_t>(body)].link == j, "RobotModel",
                       who + ": body '" + shape.body + "' rides on joint " +
                           std::to_string(bodies_[static_cast<std::size_t>(body)].link + 1) + ", not this one");
      }
      link_shapes_.push_back({j, body, shape, shape.pose()});
    }
  }
  // The named frames: each joint's link, the URDF links riding on it, and the end effector.
  for (int j = 0; j < n; ++j) {
    const std::string& link = joint(j).link_name.empty() ? joint(j).name : joint(j).link_name;
    frames_.push_back({link, j, Isometry3d::Identity()});
    for (const auto& [name, pose] : joint(j).frames) {
      if (name == link) continue;
      REDRES_REQUIRE(pose.matrix().allFinite(), "RobotModel",
                     "joint " + std::to_string(j + 1) + "'s frame '" + name + "' has a finite pose");
      frames_.push_back({name, j, pose});
    }
  }
  {
    std::unordered_map<std::string, int> seen;
    for (std::size_t f = 0; f < frames_.size(); ++f) {
      REDRES_REQUIRE(seen.emplace(frames_[f].name, static_cast<int>(f)).second, "RobotModel",
                     "frame names are unique ('" + frames_[f].name + "' is named twice)");
    }
    // The task's frame, unless a link of the robot has taken its name.
    if (seen.count("end_effector") == 0) {
      frames_.push_back({"end_effector", n - 1, after_[static_cast<std::size_t>(n - 1)] * spec_.end_effector});
    }
  }
  for (const auto& [a, b] : spec_.collision_exclude_bodies) {
    const int ia = body_index(a), ib = body_index(b);
    REDRES_REQUIRE(ia >= 0 && ib >= 0 && ia != ib, "RobotModel",
                   "collision_exclude_bodies name two different bodies of the robot (got '" + a + "' and '" + b + "')");
    excluded_bodies_.emplace_back(ia, ib);
  }
  for (const auto& [a, b] : spec_.collision_exclude) {
    REDRES_REQUIRE(a >= 0 && a < n && b >= 0 && b < n && a != b, "RobotModel",
                   "collision_exclude pairs name two different joints of the chain");
  }
  // The pose's rows; a position task is their first position_rows(). A subset picks rows of them, in order.
  const std::vector<std::string>& all = pose_row_names(spec_.kind);
  if (!spec_.task_axes.empty()) {
    int previous = -1;
    bool orientation = false;
    for (const std::string& name : spec_.task_axes) {
      const auto it = std::find(all.begin(), all.end(), name);
      REDRES_REQUIRE(it != all.end(), "RobotModel",
                     "task_axes name rows of the " + std::string(to_string(spec_.kind)) + " pose (got '" + name + "')");
      const int r = static_cast<int>(it - all.begin());
      REDRES_REQUIRE(
          r > previous, "RobotModel",
          "task_axes name each row once, in the pose's order (" + join(all) + "): '" + name + "' is out of place");
      previous = r;
      orientation = orientation || r >= position_rows();
    }
    spec_.task = orientation ? TaskRows::kPose : TaskRows::kPosition;
  }
  const std::size_t rows = spec_.task == TaskRows::kPose ? all.size() : static_cast<std::size_t>(position_rows());
  reference_names_.assign(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(rows));
  for (std::size_t r = 0; r < rows; ++r) {
    const bool selected = spec_.task_axes.empty() || std::find(spec_.task_axes.begin(), spec_.task_axes.end(),
                                                               reference_names_[r]) != spec_.task_axes.end();
    if (!selected) continue;
    task_names_.push_back(reference_names_[r]);
    task_rows_.push_back(static_cast<int>(r));
    twist_rows_.push_back(spec_.kind == ChainKind::kPlanar && r == 2 ? 5 : static_cast<int>(r));
    tracked_ |= 1U << r;
  }
}

REDRES_HOT void RobotModel::velocity_limits(const Eigen::Ref<const Eigen::VectorXd>& theta,
                                            Eigen::Ref<Eigen::VectorXd> lower,
                                            Eigen::Ref<Eigen::VectorXd> upper) const {
  const int n = dof();
  REDRES_REQUIRE(theta.size() == n && lower.size() == n && upper.size() == n, "RobotModel::velocity_limits",
                 "theta, lower and upper have size dof() = " + std::to_string(n));
  const JointSpec* joints = spec_.joints.data();
  const double* q = theta.data();
  double* lo = lower.data();
  double* hi = upper.data();
  for (int j = 0; j < n; ++j) {
    const VelocityBounds b = joints[j].velocity_limit->bounds(q[j]);
    lo[j] = b.lower;
    hi[j] = b.upper;
  }
}

Inertia Inertia::moved(const Eigen::Isometry3d& pose) const {
  Inertia out;
  out.mass = mass;
  out.com = pose * com;
  out.tensor = pose.linear() * tensor * pose.linear().transpose();
  return out;
}

Inertia Inertia::combined(const Inertia& other) const {
  Inertia out;
  out.mass = mass + other.mass;
  if (!(out.mass > 0.0)) return out;
  out.com = (mass * com + other.mass * other.com) / out.mass;
  const auto shifted = [&out](const Inertia& b) {
    const Eigen::Vector3d d = b.com - out.com;
    return Eigen::Matrix3d(b.tensor + b.mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose()));
  };
  out.tensor = shifted(*this) + shifted(other);
  return out;
}

std::string Inertia::invalid() const {
  if (!(std::isfinite(mass) && mass > 0.0)) return "expected a mass > 0, got " + std::to_string(mass);
  if (!com.allFinite() || !tensor.allFinite()) return "expected a finite centre of mass and inertia";
  const double scale = tensor.cwiseAbs().maxCoeff();
  if ((tensor - tensor.transpose()).cwiseAbs().maxCoeff() > 1e-12 * (1.0 + scale)) return "expected a symmetric tensor";
  const Eigen::Vector3d p = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(tensor).eigenvalues();
  const double tol = 1e-9 * (1.0 + scale);
  if (p.minCoeff() < -tol) return "expected a positive semi-definite inertia tensor (a principal moment is negative)";
  if (p(0) + p(1) < p(2) - tol) {
    return "expected principal moments that meet the triangle inequality (I1 + I2 >= I3), as every body's do";
  }
  return "";
}

namespace {
// A law per joint at theta (unbounded where a joint has none), as velocity_limits() does.
void law_bounds(const std::vector<JointSpec>& joints, std::shared_ptr<const VelocityLimitLaw> JointSpec::*law,
                const Eigen::Ref<const Eigen::VectorXd>& theta, Eigen::Ref<Eigen::VectorXd> lower,
                Eigen::Ref<Eigen::VectorXd> upper, const char* fn) {
  const auto n = static_cast<Eigen::Index>(joints.size());
  REDRES_REQUIRE(theta.size() == n && lower.size() == n && upper.size() == n, fn,
                 "theta, lower and upper have size dof() = " + std::to_string(n));
  for (Eigen::Index j = 0; j < n; ++j) {
    const auto& l = joints[static_cast<std::size_t>(j)].*law;
    if (!l) {
      lower(j) = -std::numeric_limits<double>::infinity();
      upper(j) = std::numeric_limits<double>::infinity();
      continue;
    }
    const VelocityBounds b = l->bounds(theta(j));
    lower(j) = b.lower;
    upper(j) = b.upper;
  }
}
}  // namespace

namespace {
int first_without(const std::vector<JointSpec>& joints, std::shared_ptr<const VelocityLimitLaw> JointSpec::*law) {
  const auto it = std::find_if(joints.begin(), joints.end(), [law](const JointSpec& j) { return !(j.*law); });
  return it == joints.end() ? -1 : static_cast<int>(it - joints.begin());
}
}  // namespace

int RobotModel::first_without_acceleration_limit() const noexcept {
  return first_without(spec_.joints, &JointSpec::acceleration_limit);
}

int RobotModel::first_without_jerk_limit() const noexcept {
  return first_without(spec_.joints, &JointSpec::jerk_limit);
}

void RobotModel::acceleration_limits(const Eigen::Ref<const Eigen::VectorXd>& theta, Eigen::Ref<Eigen::VectorXd> lower,
                                     Eigen::Ref<Eigen::VectorXd> upper) const {
  law_bounds(spec_.joints, &JointSpec::acceleration_limit, theta, lower, upper, "RobotModel::acceleration_limits");
}

void RobotModel::jerk_limits(const Eigen::Ref<const Eigen::VectorXd>& theta, Eigen::Ref<Eigen::VectorXd> lower,
                             Eigen::Ref<Eigen::VectorXd> upper) const {
  law_bounds(spec_.joints, &JointSpec::jerk_limit, theta, lower, upper, "RobotModel::jerk_limits");
}

int RobotModel::find_frame(const std::string& name) const {
  for (std::size_t f = 0; f < frames_.size(); ++f) {
    if (frames_[f].name == name) return static_cast<int>(f);
  }
  return -1;
}

int RobotModel::find_body(const std::string& name) const {
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    if (bodies_[b].name == name) return static_cast<int>(b);
  }
  return -1;
}

bool RobotModel::self_collision_bodies(int a, int b) const {
  const Body& A = bodies_.at(static_cast<std::size_t>(a));
  const Body& B = bodies_.at(static_cast<std::size_t>(b));
  if (A.link == B.link) return false;
  if (std::abs(A.link - B.link) == 1 && !A.branch && !B.branch) return false;
  for (const auto& [i, j] : spec_.collision_exclude) {
    if ((i == A.link && j == B.link) || (i == B.link && j == A.link)) return false;
  }
  for (const auto& [i, j] : excluded_bodies_) {
    if ((i == a && j == b) || (i == b && j == a)) return false;
  }
  return true;
}

bool RobotModel::self_collision_pair(int i, int j) const {
  if (i == j || std::abs(i - j) == 1) return false;
  for (const auto& [a, b] : spec_.collision_exclude) {
    if ((a == i && b == j) || (a == j && b == i)) return false;
  }
  return true;
}

}  // namespace redres

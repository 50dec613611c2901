#include "redres/control/path.hpp"
#include "redres/common/hot.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include <Eigen/Geometry>

namespace redres {

namespace {
using std::numbers::pi;
}  // namespace

PathSegment PathSegment::line(const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  PathSegment s;
  s.kind = Kind::kLine;
  s.a = p;
  s.b = q;
  s.length = (q - p).norm();
  return s;
}

PathSegment PathSegment::arc(const Eigen::Vector3d& centre, double radius, double start_angle, double sweep,
                             const Eigen::Vector3d& e1, const Eigen::Vector3d& e2) {
  PathSegment s;
  s.kind = Kind::kArc;
  s.a = centre;
  s.radius = radius;
  s.start_angle = start_angle;
  s.sweep = sweep;
  s.e1 = e1;
  s.e2 = e2;
  s.length = std::abs(radius * sweep);
  return s;
}

namespace {

// PathSegment::at with an optional second derivative; point and tangent do not depend on whether it is asked for.
REDRES_HOT void segment_at(const PathSegment& seg, double s, Eigen::Vector3d& point, Eigen::Vector3d& tangent,
                           Eigen::Vector3d* d2point) {
  const double length = seg.length;
  if (seg.kind == PathSegment::Kind::kLine) {
    const Eigen::Vector3d dir = length > 0.0 ? Eigen::Vector3d((seg.b - seg.a) / length) : Eigen::Vector3d::Zero();
    point = seg.a + s * dir;
    tangent = dir;
    if (d2point != nullptr) d2point->setZero();
    return;
  }
  // Arc or helix: angle advances linearly with arc length.
  const double frac = length > 0.0 ? s / length : 0.0;
  const double angle = seg.start_angle + frac * seg.sweep;
  const double c = std::cos(angle), sn = std::sin(angle);
  point = seg.a + seg.radius * (c * seg.e1 + sn * seg.e2) + frac * seg.rise * seg.axis;
  // d point / d s = (dangle/ds) radius (-sin e1 + cos e2) + (rise / length) axis.
  const double dangle = length > 0.0 ? seg.sweep / length : 0.0;
  tangent = dangle * seg.radius * (-sn * seg.e1 + c * seg.e2) + (length > 0.0 ? seg.rise / length : 0.0) * seg.axis;
  // d^2 point / d s^2 = -(dangle/ds)^2 radius (cos e1 + sin e2): the rise is linear in s.
  if (d2point != nullptr) *d2point = -(dangle * dangle * seg.radius) * (c * seg.e1 + sn * seg.e2);
}

}  // namespace

void PathSegment::at(double s, Eigen::Vector3d& point, Eigen::Vector3d& tangent) const {
  segment_at(*this, s, point, tangent, nullptr);
}

void PathSegment::at(double s, Eigen::Vector3d& point, Eigen::Vector3d& tangent, Eigen::Vector3d& d2point) const {
  segment_at(*this, s, point, tangent, &d2point);
}

Eigen::Vector3d PathSegment::start() const {
  Eigen::Vector3d p, t;
  at(0.0, p, t);
  return p;
}

Eigen::Vector3d PathSegment::end() const {
  Eigen::Vector3d p, t;
  at(length, p, t);
  return p;
}

void plane_axes(const Eigen::Vector3d& n, Eigen::Vector3d& e1, Eigen::Vector3d& e2) {
  const Eigen::Vector3d helper = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  e1 = (helper - helper.dot(n) * n).normalized();
  e2 = n.cross(e1);
}

PathGeometry strokes_from(std::vector<PathSegment> segments, bool stroke_each) {
  PathGeometry g;
  if (stroke_each) {
    for (auto& seg : segments) g.strokes.push_back({seg});
  } else {
    g.strokes.push_back(std::move(segments));
  }
  return g;
}

namespace {

// timing() with an optional second derivative; sigma and dsigma do not depend on whether it is asked for.
REDRES_HOT void timing_impl(TimingLaw law, double u, double& sigma, double& dsigma, double* d2sigma) {
  u = std::clamp(u, 0.0, 1.0);
  switch (law) {
    case TimingLaw::kCycloidal:
      sigma = u - std::sin(2.0 * pi * u) / (2.0 * pi);
      dsigma = 1.0 - std::cos(2.0 * pi * u);
      if (d2sigma != nullptr) *d2sigma = 2.0 * pi * std::sin(2.0 * pi * u);
      return;
    case TimingLaw::kSin2: {
      const double s = std::sin(0.5 * pi * u);
      sigma = s * s;
      dsigma = 0.5 * pi * std::sin(pi * u);
      if (d2sigma != nullptr) *d2sigma = 0.5 * pi * pi * std::cos(pi * u);
      return;
    }
    case TimingLaw::kQuintic:
      sigma = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
      dsigma = 30.0 * u * u * (1.0 - u) * (1.0 - u);
      // d/du 30 u^2 (1 - u)^2 = 60 u (1 - u) (1 - 2u).
      if (d2sigma != nullptr) *d2sigma = 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u);
      return;
  }
}

}  // namespace

void timing(TimingLaw law, double u, double& sigma, double& dsigma) { timing_impl(law, u, sigma, dsigma, nullptr); }

void timing(TimingLaw law, double u, double& sigma, double& dsigma, double& d2sigma) {
  timing_impl(law, u, sigma, dsigma, &d2sigma);
}

Path::Path(PathGeometry geometry, int dim, double duration, TimingLaw law, TimingScope scope,
           const Eigen::Matrix3d& rotation, const Eigen::Vector3d& origin, std::string description)
    : dim_(dim),
      duration_(duration),
      law_(law),
      scope_(scope),
      rotation_(rotation),
      origin_(origin),
      description_(std::move(description)) {
  REDRES_REQUIRE(dim == 2 || dim == 3, "Path", "dim is 2 or 3");
  REDRES_REQUIRE(duration > 0.0, "Path", "duration > 0");
  for (const auto& stroke : geometry.strokes) {
    double len = 0.0;
    for (const auto& seg : stroke) len += seg.length;
    if (stroke.empty() || !(len > 0.0)) continue;  // nothing to draw
    stroke_first_.push_back(static_cast<int>(segments_.size()));
    stroke_start_.push_back(total_);
    stroke_length_.push_back(len);
    for (const auto& seg : stroke) {
      seg_start_.push_back(total_);
      segments_.push_back(seg);
      total_ += seg.length;
    }
  }
  REDRES_REQUIRE(!segments_.empty() && total_ > 0.0, "Path", "the geometry has a positive length");
  double t0 = 0.0;
  for (double len : stroke_length_) {
    stroke_t0_.push_back(t0);
    stroke_T_.push_back(duration * len / total_);
    t0 += duration * len / total_;
  }
}

REDRES_HOT void Path::evaluate_3d(double t, Eigen::Vector3d& point, Eigen::Vector3d& velocity,
                                  Eigen::Vector3d* acceleration) const {
  const bool outside = t < 0.0 || t > duration_;
  t = std::clamp(t, 0.0, duration_);
  double s = 0.0, speed = 0.0;  // arc length from the path start, and ds/dt
  double s_ddot = 0.0;          // d^2 s / dt^2 (computed only when `acceleration` is asked for)
  if (scope_ == TimingScope::kWhole) {
    double sigma = 0.0, dsigma = 0.0, d2sigma = 0.0;
    if (acceleration != nullptr) {
      timing(law_, t / duration_, sigma, dsigma, d2sigma);
      s_ddot = total_ * d2sigma / (duration_ * duration_);
    } else {
      timing(law_, t / duration_, sigma, dsigma);
    }
    s = total_ * sigma;
    speed = total_ * dsigma / duration_;
  } else {
    // The stroke running at t (the last one whose start time is <= t).
    const auto it = std::upper_bound(stroke_t0_.begin(), stroke_t0_.end(), t);
    const auto k = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, (it - stroke_t0_.begin()) - 1));
    double sigma = 0.0, dsigma = 0.0, d2sigma = 0.0;
    if (acceleration != nullptr) {
      timing(law_, (t - stroke_t0_[k]) / stroke_T_[k], sigma, dsigma, d2sigma);
      s_ddot = stroke_length_[k] * d2sigma / (stroke_T_[k] * stroke_T_[k]);
    } else {
      timing(law_, (t - stroke_t0_[k]) / stroke_T_[k], sigma, dsigma);
    }
    s = stroke_start_[k] + stroke_length_[k] * sigma;
    speed = stroke_length_[k] * dsigma / stroke_T_[k];
  }
  s = std::clamp(s, 0.0, total_);
  const auto it = std::upper_bound(seg_start_.begin(), seg_start_.end(), s);
  const auto j = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, (it - seg_start_.begin()) - 1));
  Eigen::Vector3d p, tangent, d2p;
  segments_[j].at(std::min(s - seg_start_[j], segments_[j].length), p, tangent, d2p);
  point = origin_ + rotation_ * p;
  velocity = rotation_ * tangent * speed;
  if (acceleration != nullptr) {
    // d/dt (tangent(s) s') = tangent s'' + d^2p/ds^2 s'^2; held at an end point outside [0, T].
    *acceleration =
        outside ? Eigen::Vector3d::Zero() : Eigen::Vector3d(rotation_ * (tangent * s_ddot + d2p * (speed * speed)));
  }
}

REDRES_HOT void Path::evaluate(double t, Eigen::Ref<Eigen::VectorXd> r, Eigen::Ref<Eigen::VectorXd> r_dot) const {
  REDRES_REQUIRE(r.size() == dim_ && r_dot.size() == dim_, "Path::evaluate", "r and r_dot have dim() entries");
  Eigen::Vector3d world, velocity;
  evaluate_3d(t, world, velocity, nullptr);
  for (int i = 0; i < dim_; ++i) {
    r(i) = world(i);
    r_dot(i) = velocity(i);
  }
}

REDRES_HOT void Path::evaluate(double t, Eigen::Ref<Eigen::VectorXd> r, Eigen::Ref<Eigen::VectorXd> r_dot,
                               Eigen::Ref<Eigen::VectorXd> r_ddot) const {
  REDRES_REQUIRE(r.size() == dim_ && r_dot.size() == dim_ && r_ddot.size() == dim_, "Path::evaluate",
                 "r, r_dot and r_ddot have dim() entries");
  Eigen::Vector3d world, velocity, acceleration;
  evaluate_3d(t, world, velocity, &acceleration);
  for (int i = 0; i < dim_; ++i) {
    r(i) = world(i);
    r_dot(i) = velocity(i);
    r_ddot(i) = acceleration(i);
  }
}

PathRegistry& path_registry() {
  static PathRegistry registry("path");
  return registry;
}

const Schema<PathPlacement>& PathPlacement::schema() {
  using C = PathPlacement;
  static const Schema<C> s{
      {field("placement", &C::placement, "", "origin absolute, or relative to the end effector's f(theta(0))"),
       field("origin", &C::origin, "m", "path origin: [x, y] or [x, y, z] (required with placement = \"absolute\")"),
       field("rotation_deg", &C::rotation_deg, "deg", "planar: rotation of the shape about z (default: the shape's)"),
       field("rpy_deg", &C::rpy_deg, "deg", "spatial: roll, pitch, yaw of the shape"),
       field("timing", &C::timing, "", "timing law sigma(u)"),
       field("timing_scope", &C::timing_scope, "", "law per stroke or over the whole path (default: the shape's)")},
      [](const C& c) {
        if (c.placement == Placement::kAbsolute && !c.origin) {
          throw FieldError("origin",
                           "expected `origin` (the path origin in base coordinates, m) with placement = "
                           "\"absolute\"");
        }
      },
      {}};
  return s;
}

namespace {

std::unique_ptr<Path> place(const std::string& type, PathGeometry geometry, const PathPlacement& pl,
                            const PathContext& context, const char* zero_length_key = "type") {
  const double deg = std::numbers::pi / 180.0;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  if (pl.origin) {
    if (static_cast<int>(pl.origin->size()) != context.dim) {
      throw FieldError(
          "origin", "expected " + std::to_string(context.dim) + " numbers, got " + std::to_string(pl.origin->size()));
    }
    for (int k = 0; k < context.dim; ++k) origin(k) = (*pl.origin)[static_cast<std::size_t>(k)];
  }
  if (pl.placement == Placement::kRelative) origin += context.start;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  if (context.dim == 2) {
    if (pl.rpy_deg) throw FieldError("rpy_deg", "is for spatial tasks; a planar path turns by `rotation_deg`");
    const double angle = pl.rotation_deg.value_or(geometry.rotation_deg) * deg;
    rotation = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  } else {
    if (pl.rotation_deg) throw FieldError("rotation_deg", "is for planar tasks; a spatial path turns by `rpy_deg`");
    if (pl.rpy_deg) {
      const auto& rpy = *pl.rpy_deg;
      rotation = (Eigen::AngleAxisd(rpy[2] * deg, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(rpy[1] * deg, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(rpy[0] * deg, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    }
  }
  const TimingScope scope = pl.timing_scope.value_or(geometry.scope);
  if (context.dim == 2) {
    for (const auto& stroke : geometry.strokes) {
      for (const auto& seg : stroke) {
        if (seg.kind == PathSegment::Kind::kHelix || seg.a.z() != 0.0 || seg.b.z() != 0.0) {
          throw FieldError("type", "this path is spatial, but the robot's task is planar");
        }
      }
    }
  }
  std::size_t strokes = 0;
  double length = 0.0;
  for (const auto& stroke : geometry.strokes) {
    strokes += stroke.empty() ? 0 : 1;
    for (const auto& seg : stroke) length += seg.length;
  }
  if (!(length > 0.0)) throw FieldError(zero_length_key, "the path has zero length");
  std::ostringstream d;
  d.precision(4);
  d << type << " (" << strokes << (strokes == 1 ? " stroke, " : " strokes, ") << length << " m, "
    << config_io::enum_name(pl.timing) << " "
    << (scope == TimingScope::kPerStroke ? "per stroke" : "over the whole path") << ")";
  return std::make_unique<Path>(std::move(geometry), context.dim, context.duration, pl.timing, scope, rotation, origin,
                                d.str());
}

}  // namespace

std::unique_ptr<Path> make_path(const TableReader& table, const PathContext& context) {
  PathPlacement placement;
  read_config(table, PathPlacement::schema(), placement);
  std::unique_ptr<PathGeometry> geometry = path_registry().create(table, context);
  table.finish();
  try {
    // A polyline of zero length is its segments' fault; any other path's, its type's settings.
    return place(table.string("type"), std::move(*geometry), placement, context,
                 table.has("segments") ? "segments" : "type");
  } catch (const FieldError& e) {
    rethrow_at(table, e);
  }
}

std::unique_ptr<Path> make_path(const std::string& type, const std::any& config, const PathPlacement& placement,
                                const PathContext& context) {
  try {
    require_valid(placement, PathPlacement::schema(), "path placement");
    std::unique_ptr<PathGeometry> geometry = path_registry().create(type, config, context);
    return place(type, std::move(*geometry), placement, context);
  } catch (const FieldError& e) {
    throw std::invalid_argument("path '" + type + "': " + e.what());
  }
}

}  // namespace redres

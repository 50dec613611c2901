// The only translation unit that includes FCL (its headers cost seconds and hundreds of MB to compile).

#include "redres/collision.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>
#include <fcl/narrowphase/distance_request.h>
#include <fcl/narrowphase/distance_result.h>

namespace redres {

namespace {

bool positive(double v) { return std::isfinite(v) && v > 0.0; }

Eigen::Matrix3d rpy_matrix(const std::array<double, 3>& rpy) {
  return (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

}  // namespace

const Schema<ShapeSpec>& ShapeSpec::schema() {
  using S = ShapeSpec;
  static const Schema<S> s{
      {field("shape", &S::shape, "", "the primitive"),
       field("radius", &S::radius, "m", "sphere, capsule, cylinder: radius"),
       field("length", &S::length, "m", "capsule, cylinder: axis length (along the local z axis)"),
       field("size", &S::size, "m", "box: full side lengths [x, y, z]"),
       field("xyz", &S::xyz, "m", "position in the owner's frame"),
       field("rpy", &S::rpy, "rad", "roll, pitch, yaw in the owner's frame"),
       field("from", &S::from, "m", "capsule: one end of the axis (instead of xyz, rpy and length)"),
       field("to", &S::to, "m", "capsule: the other end of the axis"),
       field("velocity", &S::velocity, "m/s", "obstacles only: constant linear velocity")},
      [](const S& spec) {
        const bool round = spec.shape != Kind::kBox;
        const std::string name(config_io::enum_name(spec.shape));
        if (round && !spec.radius) throw FieldError("radius", "is required for a " + name);
        if (round && !positive(*spec.radius)) throw FieldError("radius", "expected a radius > 0 m");
        if (!round && spec.radius) throw FieldError("radius", "is not used by a box (give `size`)");
        if (spec.shape == Kind::kBox) {
          if (!spec.size) throw FieldError("size", "is required for a box ([x, y, z] full side lengths, m)");
          for (double v : *spec.size) {
            if (!positive(v)) throw FieldError("size", "expected side lengths > 0 m");
          }
        } else if (spec.size) {
          throw FieldError("size", "is only used by a box");
        }
        if (spec.from.has_value() != spec.to.has_value()) {
          throw FieldError(spec.from ? "to" : "from", "give both `from` and `to`");
        }
        if (spec.from && spec.shape != Kind::kCapsule) throw FieldError("from", "`from`/`to` describe a capsule only");
        if (spec.from &&
            (spec.length || spec.xyz != std::array<double, 3>{0, 0, 0} || spec.rpy != std::array<double, 3>{0, 0, 0})) {
          throw FieldError("from", "a capsule is given either by `from`/`to` or by `xyz`, `rpy` and `length`");
        }
        const bool axial = spec.shape == Kind::kCapsule || spec.shape == Kind::kCylinder;
        if (!axial && spec.length) throw FieldError("length", "is only used by a capsule or a cylinder");
        if (spec.shape == Kind::kCylinder && !spec.length) throw FieldError("length", "is required for a cylinder");
        if (spec.length && !positive(*spec.length)) throw FieldError("length", "expected an axis length > 0 m");
      },
      {}};
  return s;
}

Eigen::Isometry3d ShapeSpec::pose() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (from && to) {
    const Eigen::Vector3d a = vec(*from), b = vec(*to);
    T.translation() = 0.5 * (a + b);
    const Eigen::Vector3d axis = b - a;
    if (axis.norm() > 0.0)
      T.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis).toRotationMatrix();
    return T;
  }
  T.translation() = vec(xyz);
  T.linear() = rpy_matrix(rpy);
  return T;
}

double ShapeSpec::axis_length() const {
  if (from && to) return (vec(*to) - vec(*from)).norm();
  return length.value_or(0.0);
}

std::string ShapeSpec::describe() const {
  std::ostringstream s;
  s.precision(4);
  s << config_io::enum_name(shape) << "(";
  switch (shape) {
    case Kind::kSphere: s << "r = " << radius.value_or(0.0) << " m"; break;
    case Kind::kCapsule:
    case Kind::kCylinder: s << "r = " << radius.value_or(0.0) << " m, l = " << axis_length() << " m"; break;
    case Kind::kBox: s << "size = " << (*size)[0] << " x " << (*size)[1] << " x " << (*size)[2] << " m"; break;
  }
  s << ")";
  return s.str();
}

namespace {

// Closest points of segments [p0, p1] and [q0, q1] (a point is a segment of length zero): parameters s and t.
void closest_on_segments(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& q0,
                         const Eigen::Vector3d& q1, double& s, double& t) {
  const Eigen::Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  constexpr double tiny = 1e-24;
  if (a <= tiny && e <= tiny) {
    s = t = 0.0;
    return;
  }
  if (a <= tiny) {
    s = 0.0;
    t = std::clamp(f / e, 0.0, 1.0);
    return;
  }
  const double c = d1.dot(r);
  if (e <= tiny) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
    return;
  }
  const double b = d1.dot(d2), denom = a * e - b * b;
  s = denom > tiny ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
  t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
}

}  // namespace

struct DistanceQuery::Impl {
  struct Round {         // a sphere or capsule: a segment (local z axis) swept by a radius
    bool round = false;  // sphere or capsule
    double radius = 0.0;
    double half_length = 0.0;
  };
  std::vector<Round> round;
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> geometry;
  // One CollisionObject per shape: FCL's object overload of distance() allocates nothing for analytic pairs, while
  // its geometry-and-transform overload allocates once per call (measured: one per query).
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  fcl::DistanceRequestd unsigned_request;
  fcl::DistanceRequestd signed_request;
  mutable fcl::DistanceResultd result;
};

DistanceQuery::DistanceQuery(const std::vector<ShapeSpec>& shapes) : impl_(std::make_unique<Impl>()) {
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const ShapeSpec& s = shapes[i];
    try {
      check_config(s, ShapeSpec::schema());
    } catch (const FieldError& e) {
      throw std::invalid_argument("DistanceQuery: shape " + std::to_string(i) + ": " + e.what());
    }
    const bool round = s.shape == ShapeSpec::Kind::kSphere || s.shape == ShapeSpec::Kind::kCapsule;
    const double radius = s.radius.value_or(0.0);
    impl_->round.push_back(
        {round, round ? radius : 0.0, s.shape == ShapeSpec::Kind::kCapsule ? 0.5 * s.axis_length() : 0.0});
    switch (s.shape) {
      case ShapeSpec::Kind::kSphere: impl_->geometry.push_back(std::make_shared<fcl::Sphered>(radius)); break;
      case ShapeSpec::Kind::kCapsule:
        // A capsule of zero length is a sphere (FCL's capsule code divides by its length in places).
        if (s.axis_length() <= 1e-12) {
          impl_->geometry.push_back(std::make_shared<fcl::Sphered>(radius));
        } else {
          impl_->geometry.push_back(std::make_shared<fcl::Capsuled>(radius, s.axis_length()));
        }
        break;
      case ShapeSpec::Kind::kCylinder:
        impl_->geometry.push_back(std::make_shared<fcl::Cylinderd>(radius, *s.length));
        break;
      case ShapeSpec::Kind::kBox:
        impl_->geometry.push_back(std::make_shared<fcl::Boxd>((*s.size)[0], (*s.size)[1], (*s.size)[2]));
        break;
    }
  }
  for (const auto& g : impl_->geometry) impl_->objects.push_back(std::make_unique<fcl::CollisionObjectd>(g));
  // Both requests use the libccd solver: signed distance with the independent solver aborts on penetration.
  impl_->unsigned_request = fcl::DistanceRequestd(true, false, 0.0, 0.0, 1e-8, fcl::GST_LIBCCD);
  impl_->signed_request = fcl::DistanceRequestd(true, true, 0.0, 0.0, 1e-8, fcl::GST_LIBCCD);
}

DistanceQuery::~DistanceQuery() = default;

int DistanceQuery::size() const noexcept { return static_cast<int>(impl_->geometry.size()); }

ShapeDistance DistanceQuery::distance(int a, const Eigen::Isometry3d& Ta, int b, const Eigen::Isometry3d& Tb) const {
  ShapeDistance out;
  const auto n = static_cast<int>(impl_->geometry.size());
  if (a < 0 || a >= n || b < 0 || b >= n) {
    out.error = "shape index out of range";
    return out;
  }
  fcl::CollisionObjectd* oa = impl_->objects[static_cast<std::size_t>(a)].get();
  fcl::CollisionObjectd* ob = impl_->objects[static_cast<std::size_t>(b)].get();
  oa->setTransform(fcl::Transform3d(Ta.matrix()));
  ob->setTransform(fcl::Transform3d(Tb.matrix()));
  fcl::DistanceResultd& r = impl_->result;
  try {
    r.clear();  // a stale negative result would be kept: FCL only lowers min_distance
    fcl::distance(oa, ob, impl_->unsigned_request, r);
    if (!(r.min_distance > 0.0)) {
      const Impl::Round& ra = impl_->round[static_cast<std::size_t>(a)];
      const Impl::Round& rb = impl_->round[static_cast<std::size_t>(b)];
      if (ra.round && rb.round) {
        // Overlapping spheres and capsules: the penetration from their axes. FCL's unsigned query gives -1 for
        // sphere pairs, and its signed query (GJK/EPA) on penetrating capsules was seen to loop forever in 0.7.
        const Eigen::Vector3d za = Ta.linear().col(2) * ra.half_length, zb = Tb.linear().col(2) * rb.half_length;
        const Eigen::Vector3d a0 = Ta.translation() - za, a1 = Ta.translation() + za;
        const Eigen::Vector3d b0 = Tb.translation() - zb, b1 = Tb.translation() + zb;
        double sa = 0.0, sb = 0.0;
        closest_on_segments(a0, a1, b0, b1, sa, sb);
        const Eigen::Vector3d ca = a0 + sa * (a1 - a0), cb = b0 + sb * (b1 - b0);
        const double centres = (ca - cb).norm();
        const Eigen::Vector3d u = centres > 0.0 ? Eigen::Vector3d((ca - cb) / centres) : Eigen::Vector3d::Zero();
        out.ok = true;
        out.distance = centres - ra.radius - rb.radius;
        out.point_a = ca - ra.radius * u;
        out.point_b = cb + rb.radius * u;
        return out;
      }
      r.clear();
      fcl::distance(oa, ob, impl_->signed_request, r);
    }
  } catch (const std::exception&) {
    out.error = "FCL failed on this pair (GJK/EPA)";
    return out;
  }
  if (!std::isfinite(r.min_distance)) {
    out.error = "FCL returned a non-finite distance";
    return out;
  }
  out.ok = true;
  out.distance = r.min_distance;
  out.point_a = r.nearest_points[0];
  out.point_b = r.nearest_points[1];
  return out;
}

}  // namespace redres

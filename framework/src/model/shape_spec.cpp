// ShapeSpec: a collision shape as files and code describe it (its schema and rules, pose, placing and one-line
// description), and the roll-pitch-yaw convention it and the URDF share. No FCL here (collision.cpp measures shapes).

#include <array>
#include <cmath>
#include <string>
#include <string_view>

#include "redres/common/text_sink.hpp"
#include "redres/model/collision.hpp"
#include "redres/model/convex.hpp"

#include "model/occupancy.hpp"

namespace redres {

namespace {

bool positive(double v) { return std::isfinite(v) && v > 0.0; }

Eigen::Vector3d vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

}  // namespace

const Schema<ShapeSpec>& ShapeSpec::schema() {
  using S = ShapeSpec;
  static const Schema<S> s{
      {field("shape", &S::shape, "",
             "the primitive, or occupied space read from a file (octree, points: obstacles only); convex: made from a "
             "robot's meshes only (collision_model = \"hull\")"),
       field("radius", &S::radius, "m",
             "sphere, capsule, cylinder: radius; octree, points: how far the occupied cells are grown (default 0)"),
       field("length", &S::length, "m", "capsule, cylinder: axis length (along the local z axis)"),
       field("size", &S::size, "m", "box: full side lengths [x, y, z]"),
       field("xyz", &S::xyz, "m", "position in the owner's frame"),
       field("rpy", &S::rpy, "rad", "roll, pitch, yaw in the owner's frame"),
       field("from", &S::from, "m", "capsule: one end of the axis (instead of xyz, rpy and length)"),
       field("to", &S::to, "m", "capsule: the other end of the axis"),
       field("velocity", &S::velocity, "m/s", "obstacles only: constant linear velocity"),
       field("file", &S::file, "",
             "octree: an OctoMap .bt or .ot file; points: a .ply, .pcd or .xyz point cloud (relative to this file)"),
       field("resolution", &S::resolution, "m", "points: the edge of the cubic cells the points are put into")},
      [](const S& spec) {
        const std::string name(config_io::enum_name(spec.shape));
        if (spec.shape == Kind::kConvex) {
          if (!spec.hull) {
            throw FieldError("shape",
                             "\"convex\" is the convex hull of a robot's collision mesh, made by the robot file's "
                             "`collision_model = \"hull\"` (docs/robot_format.md, \"Meshes\"); it cannot be written "
                             "by hand");
          }
          if (spec.radius || spec.size || spec.length || spec.from || spec.to || spec.resolution) {
            throw FieldError(spec.radius   ? "radius"
                             : spec.size   ? "size"
                             : spec.length ? "length"
                             : spec.from   ? "from"
                             : spec.to     ? "to"
                                           : "resolution",
                             "is not used by a convex hull (its shape comes from its mesh)");
          }
          return;
        }
        if (spec.hull) throw FieldError("shape", "only a convex shape holds a hull");
        if (spec.is_cloud()) {
          if (!spec.file || spec.file->empty())
            throw FieldError("file", "is required for " + name + " (the file to read)");
          if (spec.radius && !(std::isfinite(*spec.radius) && *spec.radius >= 0.0)) {
            throw FieldError("radius", "expected a radius >= 0 m (how far the occupied cells are grown)");
          }
          if (spec.shape == Kind::kPoints && !spec.resolution) {
            throw FieldError("resolution", "is required for points (the cell edge, m; e.g. 0.01)");
          }
          if (spec.resolution && !(positive(*spec.resolution) && *spec.resolution >= 1e-4)) {
            throw FieldError("resolution", "expected a cell edge >= 1e-4 m");
          }
          if (spec.shape == Kind::kOctree && spec.resolution) {
            throw FieldError("resolution", "is not used by an octree (its cells come from the file)");
          }
          if (spec.size || spec.length || spec.from || spec.to) {
            throw FieldError(spec.size     ? "size"
                             : spec.length ? "length"
                             : spec.from   ? "from"
                                           : "to",
                             "is not used by " + name + " (its shape comes from the file)");
          }
          return;
        }
        if (spec.file) throw FieldError("file", "is only used by an octree or points obstacle");
        if (spec.resolution) throw FieldError("resolution", "is only used by a points obstacle");
        const bool round = spec.shape != Kind::kBox;
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

void ShapeSpec::describe(TextSink& s) const {
  s.precision(4);
  s << config_io::enum_name(shape) << "(";
  switch (shape) {
    case Kind::kSphere: s << "r = " << radius.value_or(0.0) << " m"; break;
    case Kind::kCapsule:
    case Kind::kCylinder: s << "r = " << radius.value_or(0.0) << " m, l = " << axis_length() << " m"; break;
    case Kind::kBox: s << "size = " << (*size)[0] << " x " << (*size)[1] << " x " << (*size)[2] << " m"; break;
    case Kind::kOctree:
    case Kind::kPoints: {
      const std::string_view whole =
          file ? std::string_view(file->native()) : std::string_view();  // its last component, without making a path
      const std::size_t slash = whole.find_last_of('/');
      s << (slash == std::string_view::npos ? whole : whole.substr(slash + 1));
    }
      if (cloud) {
        const OccupancyInfo& info = cloud->info();
        if (shape == Kind::kPoints) s << ": " << info.points << " points";
        s << (shape == Kind::kPoints ? " in " : ": ") << info.cells << " cells of " << info.resolution << " m";
      }
      if (radius.value_or(0.0) > 0.0) s << ", r = " << *radius << " m";
      break;
    case Kind::kConvex:
      if (hull) {
        s << hull->vertices.size() << " vertices, " << hull->faces.size() << " faces, from ";
        const std::string_view whole(hull->source.native());
        const std::size_t slash = whole.find_last_of('/');
        s << (slash == std::string_view::npos ? whole : whole.substr(slash + 1));
        if (hull->pieces > 1) s << " piece " << hull->piece + 1 << " of " << hull->pieces;
      }
      break;
  }
  s << ")";
}

std::string ShapeSpec::describe() const {
  return text_of([this](TextSink& s) { describe(s); });
}

Eigen::Matrix3d rpy_matrix(const std::array<double, 3>& rpy) {
  return (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

std::array<double, 3> rpy_of(const Eigen::Matrix3d& R) {
  // atan2 of the cosine's two parts keeps pitch accurate near +-pi/2, where asin(-R(2, 0)) loses digits.
  const double cos_pitch = std::hypot(R(2, 1), R(2, 2));
  const double pitch = std::atan2(-R(2, 0), cos_pitch);
  if (cos_pitch > 1e-12) return {std::atan2(R(2, 1), R(2, 2)), pitch, std::atan2(R(1, 0), R(0, 0))};
  return {0.0, pitch, std::atan2(-R(0, 1), R(1, 1))};
}

ShapeSpec ShapeSpec::placed(const Eigen::Isometry3d& at) const {
  ShapeSpec out = *this;
  if (from && to) {
    const Eigen::Vector3d a = at * vec(*from), b = at * vec(*to);
    out.from = std::array<double, 3>{a.x(), a.y(), a.z()};
    out.to = std::array<double, 3>{b.x(), b.y(), b.z()};
    return out;
  }
  const Eigen::Isometry3d t = at * pose();
  out.xyz = {t.translation().x(), t.translation().y(), t.translation().z()};
  out.rpy = rpy_of(t.linear());
  return out;
}

}  // namespace redres

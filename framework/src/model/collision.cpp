// The only translation unit that includes FCL (its headers cost seconds and hundreds of MB to compile).

#include "redres/model/collision.hpp"

#include "redres/common/error.hpp"
#include "redres/model/convex.hpp"

#include "model/convex_distance.hpp"
#include "model/occupancy.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
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

// Signed distance from point q (box frame) to the box with half sides h, and the nearest point on its surface with
// the outward unit direction u (from that point towards q when q is outside; the nearest face's normal inside).
double box_point(const Eigen::Vector3d& q, const Eigen::Vector3d& h, Eigen::Vector3d& on_box, Eigen::Vector3d& u) {
  const Eigen::Vector3d excess = q.cwiseAbs() - h;
  if ((excess.array() > 0.0).any()) {
    on_box = q.cwiseMax(-h).cwiseMin(h);
    const Eigen::Vector3d diff = q - on_box;
    const double d = diff.norm();
    u = diff / d;
    return d;
  }
  Eigen::Index k = 0;
  const double d = excess.maxCoeff(&k);  // <= 0: the nearest face is the one along axis k
  const double side = q(k) < 0.0 ? -1.0 : 1.0;
  on_box = q;
  on_box(k) = side * h(k);
  u = Eigen::Vector3d::Zero();
  u(k) = side;
  return d;
}

// Signed distance between a sphere or capsule (axis [p0, p1] in the world, radius r) and a box (pose Tb, half sides
// h): the minimum over the axis of the point-box signed distance, minus r, found exactly. Apart, this is the exact
// distance. Overlapping, it is the axis-based measure also used for two capsules: exact for a sphere and for a
// capsule whose axis stays outside the box; when the axis crosses the box it is the depth of the deepest axis point
// below its nearest face (less than the true penetration), with the normal of that face. Witness points: on the
// round shape and on the box, with round - box = d u.
//
// Along the axis q(s) = q0 + s dq (box frame, s in [0, 1]) the squared distance outside the box is
// g(s) = sum_k max(0, |q_k(s)| - h_k)^2: convex, and a quadratic between the (at most six) values of s where some
// q_k(s) crosses +-h_k, so its minimum is the least of the pieces' clamped vertices. Where g reaches 0 the axis
// touches or enters the box, and the signed distance there is max_k (|q_k(s)| - h_k): the largest of six linear
// functions, convex, whose minimum lies at an end or where two of them cross (at most fifteen candidates).
void round_box(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, double r, const Eigen::Isometry3d& Tb,
               const Eigen::Vector3d& h, double& d, Eigen::Vector3d& on_round, Eigen::Vector3d& on_box,
               Eigen::Vector3d* normal = nullptr) {
  const Eigen::Isometry3d to_box = Tb.inverse();
  const Eigen::Vector3d q0 = to_box * p0, dq = to_box * p1 - q0;
  double best_s = 0.0;
  if (dq.squaredNorm() > 0.0) {
    std::array<double, 8> cuts{};
    int count = 0;
    cuts[static_cast<std::size_t>(count++)] = 0.0;
    cuts[static_cast<std::size_t>(count++)] = 1.0;
    for (int k = 0; k < 3; ++k) {
      if (dq(k) == 0.0) continue;
      for (const double side : {-1.0, 1.0}) {
        const double s = (side * h(k) - q0(k)) / dq(k);
        if (s > 0.0 && s < 1.0) cuts[static_cast<std::size_t>(count++)] = s;
      }
    }
    for (int i = 1; i < count; ++i) {  // insertion sort of at most 8
      for (int j = i; j > 0 && cuts[static_cast<std::size_t>(j)] < cuts[static_cast<std::size_t>(j - 1)]; --j)
        std::swap(cuts[static_cast<std::size_t>(j)], cuts[static_cast<std::size_t>(j - 1)]);
    }
    const auto outside2 = [&](double s) {
      double g = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double e = std::abs(q0(k) + s * dq(k)) - h(k);
        if (e > 0.0) g += e * e;
      }
      return g;
    };
    double best_g = outside2(0.0);
    for (int c = 0; c + 1 < count; ++c) {
      const double a = cuts[static_cast<std::size_t>(c)], b = cuts[static_cast<std::size_t>(c + 1)];
      if (!(b > a)) continue;
      // The piece's quadratic sum_k (c_k + s dq_k)^2 over the axes outside the box at its middle.
      const double mid = 0.5 * (a + b);
      double a2 = 0.0, a1 = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double x = q0(k) + mid * dq(k);
        if (x > h(k) || x < -h(k)) {
          const double ck = q0(k) - (x > 0.0 ? h(k) : -h(k));
          a2 += dq(k) * dq(k);
          a1 += ck * dq(k);
        }
      }
      const double s = a2 > 0.0 ? std::clamp(-a1 / a2, a, b) : b;
      for (const double t : {s, b}) {
        const double g = outside2(t);
        if (g < best_g) {
          best_g = g;
          best_s = t;
        }
      }
    }
    // Where the axis enters the box, g is zero only in exact arithmetic (a rounding residue of 1e-34 was seen): the
    // axis reaches the box when g is below the square of a rounding-sized distance.
    const double touch = 1e-12 * (h.maxCoeff() + dq.norm());
    if (!(best_g > touch * touch)) {
      // The axis reaches the box: the deepest point, among the ends and the crossings of the six lines.
      std::array<double, 6> slope{}, offset{};  // line j: slope s + offset = +-q_k(s) - h_k
      for (int k = 0; k < 3; ++k) {
        slope[static_cast<std::size_t>(2 * k)] = dq(k);
        offset[static_cast<std::size_t>(2 * k)] = q0(k) - h(k);
        slope[static_cast<std::size_t>(2 * k + 1)] = -dq(k);
        offset[static_cast<std::size_t>(2 * k + 1)] = -q0(k) - h(k);
      }
      const auto inside = [&](double s) {
        double f = -std::numeric_limits<double>::infinity();
        for (std::size_t j = 0; j < 6; ++j) f = std::max(f, slope[j] * s + offset[j]);
        return f;
      };
      double best_f = inside(best_s);
      const auto consider = [&](double s) {
        if (!(s >= 0.0 && s <= 1.0)) return;
        const double f = inside(s);
        if (f < best_f) {
          best_f = f;
          best_s = s;
        }
      };
      consider(0.0);
      consider(1.0);
      for (std::size_t i = 0; i < 6; ++i) {
        for (std::size_t j = i + 1; j < 6; ++j) {
          if (slope[i] != slope[j]) consider((offset[j] - offset[i]) / (slope[i] - slope[j]));
        }
      }
    }
  }
  Eigen::Vector3d c, u;
  const Eigen::Vector3d q = q0 + best_s * dq;
  d = box_point(q, h, c, u) - r;
  const Eigen::Vector3d u_world = Tb.linear() * u;
  on_box = Tb * c;
  on_round = Tb * q - r * u_world;
  if (normal != nullptr) *normal = u_world;
}

// A sphere or capsule (axis [p0, p1], radius r, in the cloud's frame) against a cloud's cells grown by g, exactly (the
// cell is a box: round_box).
struct RoundMetric final : OccupancyMap::Metric {
  RoundMetric(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double radius, double grow)
      : p0(from), p1(to), mid(0.5 * (from + to)), reach(0.5 * (to - from).norm() + radius + grow), r(radius), g(grow) {}
  Eigen::Vector3d p0, p1, mid;
  double reach;  // the radius of the ball about mid that holds the shape grown by g
  double r, g;
  [[nodiscard]] double bound(const Eigen::Vector3d& c, double h, double best) const override {
    // First the ball's distance to the cube (a few flops); only a cube that ball does not rule out gets the exact
    // distance, which bounds the cells inside it.
    const double ball = ((mid - c).cwiseAbs().array() - h).max(0.0).matrix().norm() - reach;
    if (!(ball < best)) return ball;
    Eigen::Vector3d a, b;
    return cell(c, h, a, b);
  }
  double cell(const Eigen::Vector3d& c, double h, Eigen::Vector3d& on_query, Eigen::Vector3d& on_cloud) const override {
    Eigen::Isometry3d Tc = Eigen::Isometry3d::Identity();
    Tc.translation() = c;
    double d = 0.0;
    Eigen::Vector3d u;
    round_box(p0, p1, r, Tc, Eigen::Vector3d::Constant(h), d, on_query, on_cloud, &u);
    // on_query - on_cloud = d u, with u the cube's outward unit normal at the witness: the grown cube's point is g
    // further along it (u from round_box itself, so a near-zero d does not turn it into noise).
    on_cloud += g * u;
    return d - g;
  }
};

}  // namespace

struct DistanceQuery::Impl {
  struct Round {         // a sphere or capsule: a segment (local z axis) swept by a radius
    bool round = false;  // sphere or capsule
    double radius = 0.0;
    double half_length = 0.0;
  };
  std::vector<Round> round;
  std::vector<std::optional<Eigen::Vector3d>> box_half;  // a box's half sides
  std::vector<double> cylinder_radius;                   // a cylinder's radius (0 for other shapes)
  std::vector<double> cylinder_half;                     // a cylinder's half length
  std::vector<double> bound;                             // the radius of the ball about the centre that holds it
  // Clouds (octree, points): the occupied cells, and the bounding box of the grown cells in the cloud's frame.
  std::vector<std::shared_ptr<const OccupancyMap>> cloud;
  std::vector<Eigen::Vector3d> cloud_lo, cloud_hi;
  std::vector<Eigen::Isometry3d> object_offset;  // the FCL object's pose in the shape's frame (a cloud's box)
  // Convex hulls, and every primitive as a core for the convex distance (model/convex_distance.hpp): the core's
  // vertices (none for a cylinder, whose support is smooth) and a point inside it, in the shape's frame.
  std::vector<std::shared_ptr<const ConvexHull>> hull;
  std::vector<std::vector<Eigen::Vector3d>> core_vertices;
  std::vector<Eigen::Vector3d> core_centre;
  std::vector<std::vector<Eigen::Vector4d>> core_planes;  // a box's or hull's face planes (unit outward normal, offset)

  // Shape k at pose T as a core swept by its radius.
  [[nodiscard]] convex::Core core(std::size_t k, const Eigen::Isometry3d& T) const {
    convex::Core c;
    c.vertices = core_vertices[k].empty() ? nullptr : core_vertices[k].data();
    c.count = static_cast<int>(core_vertices[k].size());
    c.cylinder_radius = cylinder_radius[k];
    c.cylinder_half = cylinder_half[k];
    c.centre = core_centre[k];
    c.planes = core_planes[k].empty() ? nullptr : core_planes[k].data();
    c.plane_count = static_cast<int>(core_planes[k].size());
    if (hull[k]) {
      c.first_neighbour = hull[k]->first_neighbour.data();
      c.neighbours = hull[k]->neighbours.data();
    }
    c.radius = round[k].round ? round[k].radius : 0.0;
    c.R = T.linear();
    c.t = T.translation();
    return c;
  }
  // A pair with a convex hull (neither a cloud).
  [[nodiscard]] ShapeDistance convex_pair(std::size_t a, const Eigen::Isometry3d& Ta, std::size_t b,
                                          const Eigen::Isometry3d& Tb) const {
    ShapeDistance out;
    const convex::Result r = convex::distance(core(a, Ta), core(b, Tb));
    if (!(std::isfinite(r.distance) && r.point_a.allFinite() && r.point_b.allFinite())) {
      out.error = "the convex distance is not finite";
      return out;
    }
    out.ok = true;
    out.distance = r.distance;
    out.point_a = r.point_a;
    out.point_b = r.point_b;
    return out;
  }

  // A box or cylinder (shape k at T, in the cloud's frame) against a cloud's cells: each cell as its bounding ball
  // (grown by g), measured to the shape's nearest point in closed form (project).
  struct BallMetric final : OccupancyMap::Metric {
    BallMetric(const Impl& owner, std::size_t shape, const Eigen::Isometry3d& pose, double grow)
        : impl(owner), k(shape), T(pose), g(grow) {}
    const Impl& impl;
    std::size_t k;
    Eigen::Isometry3d T;
    double g;
    [[nodiscard]] double bound(const Eigen::Vector3d& c, double h, double /*best*/) const override {
      // A hull by its bounding ball (its exact projection is a GJK run; cell() makes it).
      if (impl.hull[k]) return (c - T.translation()).norm() - impl.bound[k] - std::sqrt(3.0) * h - g;
      return (c - impl.project(k, T, c)).norm() - std::sqrt(3.0) * h - g;
    }
    double cell(const Eigen::Vector3d& c, double h, Eigen::Vector3d& on_query,
                Eigen::Vector3d& on_cloud) const override {
      on_query = impl.project(k, T, c);
      const Eigen::Vector3d v = on_query - c;
      const double n = v.norm(), R = std::sqrt(3.0) * h + g;
      on_cloud = n > 0.0 ? Eigen::Vector3d(c + v * (R / n)) : c;
      return n - R;
    }
  };
  // A pair with a cloud (see DistanceQuery::distance).
  [[nodiscard]] ShapeDistance cloud_distance(int a, const Eigen::Isometry3d& Ta, int b, const Eigen::Isometry3d& Tb,
                                             double within) const {
    ShapeDistance out;
    const bool a_cloud = cloud[static_cast<std::size_t>(a)] != nullptr;
    const int k = a_cloud ? b : a;
    const auto ks = static_cast<std::size_t>(k);
    if (cloud[ks]) {
      out.error = "two clouds are not measured against each other";
      return out;
    }
    const OccupancyMap& map = *cloud[static_cast<std::size_t>(a_cloud ? a : b)];
    const Eigen::Isometry3d& Tc = a_cloud ? Ta : Tb;
    const Eigen::Isometry3d local = Tc.inverse() * (a_cloud ? Tb : Ta);  // the shape in the cloud's frame
    Eigen::Vector3d on_shape = Eigen::Vector3d::Zero(), on_cloud = Eigen::Vector3d::Zero();
    double d = 0.0;
    if (round[ks].round) {
      const Eigen::Vector3d z = local.linear().col(2) * round[ks].half_length;
      const RoundMetric m(local.translation() - z, local.translation() + z, round[ks].radius, map.grow());
      d = map.nearest(m, within, on_shape, on_cloud);
    } else {
      const BallMetric m(*this, ks, local, map.grow());
      d = map.nearest(m, within, on_shape, on_cloud);
    }
    out.ok = true;
    out.distance = d;
    if (std::isfinite(d)) {
      on_shape = Tc * on_shape;
      on_cloud = Tc * on_cloud;
    }
    out.point_a = a_cloud ? on_cloud : on_shape;
    out.point_b = a_cloud ? on_shape : on_cloud;
    return out;
  }

  // The point of shape k (at T) nearest to the world point `w`: exact, closed form, in the shape's frame.
  [[nodiscard]] Eigen::Vector3d project(std::size_t k, const Eigen::Isometry3d& T, const Eigen::Vector3d& w) const {
    const Eigen::Vector3d p = T.linear().transpose() * (w - T.translation());
    Eigen::Vector3d q = p;
    if (cloud[k]) {
      q = p.cwiseMax(cloud_lo[k]).cwiseMin(cloud_hi[k]);  // the bounding box: for lower bounds only
    } else if (hull[k]) {
      // GJK from the point (a core of one vertex) to the hull: exact; the point itself when inside.
      const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
      convex::Core point;
      point.vertices = &origin;
      point.count = 1;
      point.t = p;
      Eigen::Vector3d on_point, on_hull;
      if (convex::core_distance(point, core(k, Eigen::Isometry3d::Identity()), on_point, on_hull) > 0.0) q = on_hull;
    } else if (box_half[k]) {
      q = p.cwiseMax(-*box_half[k]).cwiseMin(*box_half[k]);
    } else if (cylinder_radius[k] > 0.0) {
      q.z() = std::clamp(p.z(), -cylinder_half[k], cylinder_half[k]);
      const double radial = std::hypot(p.x(), p.y());
      if (radial > cylinder_radius[k]) q.head<2>() *= cylinder_radius[k] / radial;
    } else {
      const Round& r = round[k];
      const Eigen::Vector3d c(0.0, 0.0, std::clamp(p.z(), -r.half_length, r.half_length));
      const Eigen::Vector3d d = p - c;
      const double norm = d.norm();
      if (norm > r.radius) q = c + d * (r.radius / norm);
    }
    return T.translation() + T.linear() * q;
  }
  // Polishes a pair apart from GJK's witness points by alternating exact projections (p <- P_a(q), q <- P_b(p),
  // which only ever shortens |p - q| and converges to a closest pair of two convex shapes): GJK stops within its
  // tolerance of the distance, the polish takes it to rounding (a few iterations from GJK's answer).
  void polish(std::size_t a, const Eigen::Isometry3d& Ta, std::size_t b, const Eigen::Isometry3d& Tb,
              ShapeDistance& out) const {
    Eigen::Vector3d pa = out.point_a, pb = out.point_b;
    double best = (pa - pb).norm();
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector3d qb = project(b, Tb, pa);
      const Eigen::Vector3d qa = project(a, Ta, qb);
      const double d = (qa - qb).norm();
      if (!(d < best)) break;
      const double gain = best - d;
      best = d;
      pa = qa;
      pb = qb;
      if (gain < 1e-15) break;
    }
    if (best < out.distance) {
      out.distance = best;
      out.point_a = pa;
      out.point_b = pb;
    }
  }
  // One CollisionObject per shape: FCL's object overload of distance() allocates nothing for analytic pairs, while
  // its geometry-and-transform overload allocates once per call (measured: one per query).
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  fcl::DistanceRequestd unsigned_request;
  mutable fcl::DistanceResultd result;
  // The broadphase over the group [group_first, group_first + group_count): its objects carry their shape index as
  // user data.
  std::unique_ptr<fcl::DynamicAABBTreeCollisionManagerd> tree;
  int group_first = 0, group_count = 0;
};

namespace {

// What near()'s callback collects: group objects whose bounding box is closer than `within` to the query's.
struct NearData {
  const fcl::AABBd* query = nullptr;
  double within = 0.0;
  int* out = nullptr;
  int count = 0;
};

// FCL's tree calls this for each leaf whose box is closer to the query's than `dist` (leaves reached before the
// first call are not filtered, hence the test here). Keeping dist just above `within` makes the tree return every
// leaf at most `within` away (as brute force keeps pairs with d <= d_i), rather than only the nearest (its own
// callbacks lower dist to the smallest distance found).
bool near_callback(fcl::CollisionObjectd* group_object, fcl::CollisionObjectd* /*query*/, void* data, double& dist) {
  auto& d = *static_cast<NearData*>(data);
  if (group_object->getAABB().distance(*d.query) <= d.within) {
    d.out[d.count++] = static_cast<int>(reinterpret_cast<std::intptr_t>(group_object->getUserData()));
  }
  dist = std::nextafter(d.within, std::numeric_limits<double>::infinity());  // the tree prunes boxes at >= dist
  return false;                                                              // never stop early
}

}  // namespace

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
    impl_->object_offset.push_back(Eigen::Isometry3d::Identity());
    if (s.is_cloud()) {
      std::shared_ptr<const OccupancyMap> cloud = s.cloud;
      if (!cloud) {
        ShapeSpec copy = s;
        load_cloud(copy);
        cloud = copy.cloud;
      }
      const OccupancyInfo& info = cloud->info();
      const Eigen::Vector3d grow = Eigen::Vector3d::Constant(cloud->grow());
      impl_->cloud.push_back(cloud);
      impl_->cloud_lo.push_back(info.min - grow);
      impl_->cloud_hi.push_back(info.max + grow);
      impl_->round.push_back({});
      impl_->box_half.push_back(std::nullopt);
      impl_->cylinder_radius.push_back(0.0);
      impl_->cylinder_half.push_back(0.0);
      impl_->hull.push_back(nullptr);
      impl_->core_vertices.emplace_back();
      impl_->core_centre.emplace_back(Eigen::Vector3d::Zero());
      impl_->core_planes.emplace_back();
      // The farthest corner of the grown cells' box from the cloud's origin.
      impl_->bound.push_back(impl_->cloud_lo.back().cwiseAbs().cwiseMax(impl_->cloud_hi.back().cwiseAbs()).norm() *
                             (1.0 + 1e-12));
      // In the broadphase a cloud is the box of its grown cells.
      const Eigen::Vector3d side = impl_->cloud_hi.back() - impl_->cloud_lo.back();
      impl_->object_offset.back().translation() = 0.5 * (impl_->cloud_lo.back() + impl_->cloud_hi.back());
      impl_->objects.push_back(
          std::make_unique<fcl::CollisionObjectd>(std::make_shared<fcl::Boxd>(side.x(), side.y(), side.z())));
      continue;
    }
    impl_->cloud.push_back(nullptr);
    impl_->cloud_lo.emplace_back(Eigen::Vector3d::Zero());
    impl_->cloud_hi.emplace_back(Eigen::Vector3d::Zero());
    impl_->hull.push_back(s.shape == ShapeSpec::Kind::kConvex ? s.hull : nullptr);
    // The core's vertices: a sphere's centre, a capsule's two ends, a box's corners, a hull's vertices.
    std::vector<Eigen::Vector3d> corners;
    Eigen::Vector3d inner = Eigen::Vector3d::Zero();
    switch (s.shape) {
      case ShapeSpec::Kind::kSphere: corners.emplace_back(Eigen::Vector3d::Zero()); break;
      case ShapeSpec::Kind::kCapsule:
        corners.emplace_back(0.0, 0.0, -0.5 * s.axis_length());
        if (s.axis_length() > 0.0) corners.emplace_back(0.0, 0.0, 0.5 * s.axis_length());
        break;
      case ShapeSpec::Kind::kBox:
        for (int c = 0; c < 8; ++c) {
          corners.emplace_back(((c & 1) ? 0.5 : -0.5) * (*s.size)[0], ((c & 2) ? 0.5 : -0.5) * (*s.size)[1],
                               ((c & 4) ? 0.5 : -0.5) * (*s.size)[2]);
        }
        break;
      case ShapeSpec::Kind::kConvex:
        corners = s.hull->vertices;
        for (const auto& v : corners) inner += v;
        inner /= static_cast<double>(corners.size());
        break;
      case ShapeSpec::Kind::kCylinder:
      case ShapeSpec::Kind::kOctree:
      case ShapeSpec::Kind::kPoints: break;  // a smooth support; clouds above
    }
    // Face planes: a box's six; a hull's distinct ones (qhull's triangles split a facet into several).
    std::vector<Eigen::Vector4d> planes;
    if (s.shape == ShapeSpec::Kind::kBox) {
      for (int k = 0; k < 3; ++k) {
        for (const double side : {-1.0, 1.0}) {
          Eigen::Vector4d p = Eigen::Vector4d::Zero();
          p(k) = side;
          p(3) = 0.5 * (*s.size)[static_cast<std::size_t>(k)];
          planes.push_back(p);
        }
      }
    } else if (s.hull) {
      for (const auto& f : s.hull->faces) {
        const Eigen::Vector3d& v0 = s.hull->vertices[static_cast<std::size_t>(f[0])];
        Eigen::Vector3d n = (s.hull->vertices[static_cast<std::size_t>(f[1])] - v0)
                                .cross(s.hull->vertices[static_cast<std::size_t>(f[2])] - v0);
        if (!(n.norm() > 1e-12 * s.hull->bound * s.hull->bound)) continue;  // a sliver
        n.normalize();
        if (n.dot(v0 - inner) < 0.0) n = -n;  // outward
        const double h = n.dot(v0);
        const bool seen = std::any_of(planes.begin(), planes.end(), [&](const Eigen::Vector4d& p) {
          return p.head<3>().dot(n) > 1.0 - 1e-12 && std::abs(p(3) - h) <= 1e-12 * s.hull->bound;
        });
        if (!seen) planes.emplace_back(n.x(), n.y(), n.z(), h);
      }
    }
    impl_->core_planes.push_back(std::move(planes));
    impl_->core_vertices.push_back(std::move(corners));
    impl_->core_centre.push_back(inner);
    impl_->round.push_back(
        {round, round ? radius : 0.0, s.shape == ShapeSpec::Kind::kCapsule ? 0.5 * s.axis_length() : 0.0});
    impl_->box_half.push_back(s.shape == ShapeSpec::Kind::kBox ? std::optional<Eigen::Vector3d>(0.5 * vec(*s.size))
                                                               : std::nullopt);
    const bool cyl = s.shape == ShapeSpec::Kind::kCylinder;
    impl_->cylinder_radius.push_back(cyl ? radius : 0.0);
    impl_->cylinder_half.push_back(cyl ? 0.5 * *s.length : 0.0);
    double bound = radius + impl_->round.back().half_length;  // a sphere or capsule
    if (impl_->box_half.back()) bound = impl_->box_half.back()->norm();
    if (cyl) bound = std::hypot(radius, 0.5 * *s.length);
    if (s.hull) bound = s.hull->bound;
    impl_->bound.push_back(bound * (1.0 + 1e-12));  // rounding never culls a pair within reach
    std::shared_ptr<fcl::CollisionGeometryd> geometry;
    switch (s.shape) {
      case ShapeSpec::Kind::kSphere: geometry = std::make_shared<fcl::Sphered>(radius); break;
      case ShapeSpec::Kind::kCapsule:
        // A capsule of zero length is a sphere (FCL's capsule code divides by its length in places).
        if (s.axis_length() <= 1e-12) {
          geometry = std::make_shared<fcl::Sphered>(radius);
        } else {
          geometry = std::make_shared<fcl::Capsuled>(radius, s.axis_length());
        }
        break;
      case ShapeSpec::Kind::kCylinder: geometry = std::make_shared<fcl::Cylinderd>(radius, *s.length); break;
      case ShapeSpec::Kind::kBox:
        geometry = std::make_shared<fcl::Boxd>((*s.size)[0], (*s.size)[1], (*s.size)[2]);
        break;
      case ShapeSpec::Kind::kConvex: {
        // In the broadphase a hull is the box of its vertices, centred on its frame's origin (convex_hull()).
        const Eigen::Vector3d side = 2.0 * s.hull->half_extent;
        geometry = std::make_shared<fcl::Boxd>(side.x(), side.y(), side.z());
        break;
      }
      case ShapeSpec::Kind::kOctree:
      case ShapeSpec::Kind::kPoints: break;  // above
    }
    impl_->objects.push_back(std::make_unique<fcl::CollisionObjectd>(geometry));  // it keeps the geometry
  }
  // The libccd solver (unsigned queries only: signed ones are never made, see collision.hpp).
  // GJK to 1e-12: at libccd's 1e-8 a cylinder's distance came out up to 1.9e-6 m too large; at 1e-12 every pair matches
  // an independent computation (alternating projections, tests/framework/model/collision_test.cpp) to 1e-9 m.
  impl_->unsigned_request = fcl::DistanceRequestd(true, false, 0.0, 0.0, 1e-12, fcl::GST_LIBCCD);
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

DistanceQuery::~DistanceQuery() = default;

int DistanceQuery::size() const noexcept { return static_cast<int>(impl_->objects.size()); }

ShapeDistance DistanceQuery::distance(int a, const Eigen::Isometry3d& Ta, int b, const Eigen::Isometry3d& Tb,
                                      double within) const {
  ShapeDistance out;
  const int n = size();
  if (a < 0 || a >= n || b < 0 || b >= n) {
    out.error = "shape index out of range";
    return out;
  }
  if (impl_->cloud[static_cast<std::size_t>(a)] || impl_->cloud[static_cast<std::size_t>(b)]) {
    return impl_->cloud_distance(a, Ta, b, Tb, within);
  }
  if (impl_->hull[static_cast<std::size_t>(a)] || impl_->hull[static_cast<std::size_t>(b)]) {
    // A convex hull against any shape: GJK/MPR on support functions (model/convex_distance.hpp), without FCL.
    return impl_->convex_pair(static_cast<std::size_t>(a), Ta, static_cast<std::size_t>(b), Tb);
  }
  {
    const Impl::Round& ra = impl_->round[static_cast<std::size_t>(a)];
    const Impl::Round& rb = impl_->round[static_cast<std::size_t>(b)];
    const bool box_a = impl_->box_half[static_cast<std::size_t>(a)].has_value();
    const bool box_b = impl_->box_half[static_cast<std::size_t>(b)].has_value();
    if ((ra.round && box_b) || (box_a && rb.round)) {
      // A sphere or capsule against a box (a link and a table, say), apart or overlapping, without FCL (see round_box),
      // whose GJK allocates on every such query and whose EPA (for an overlap) can abort the process in 0.7 (a live
      // assert in Debian's build).
      const bool a_round = ra.round;
      const Impl::Round& rr = a_round ? ra : rb;
      const Eigen::Isometry3d& Tr = a_round ? Ta : Tb;
      const Eigen::Vector3d z = Tr.linear().col(2) * rr.half_length;
      Eigen::Vector3d on_round, on_box;
      round_box(Tr.translation() - z, Tr.translation() + z, rr.radius, a_round ? Tb : Ta,
                *impl_->box_half[static_cast<std::size_t>(a_round ? b : a)], out.distance, on_round, on_box);
      out.ok = true;
      out.point_a = a_round ? on_round : on_box;
      out.point_b = a_round ? on_box : on_round;
      return out;
    }
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
      // Other overlapping pairs (a cylinder, or two boxes) would need FCL's EPA, which loops or aborts on such
      // pairs in 0.7: the pair is reported as not measured rather than risk the process.
      out.error = "the shapes overlap, and FCL 0.7 cannot measure the depth of a cylinder or box-box overlap reliably";
      return out;
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
  // Spheres and capsules are measured in closed form by FCL (exact to rounding); GJK's answers are polished.
  if (!impl_->round[static_cast<std::size_t>(a)].round || !impl_->round[static_cast<std::size_t>(b)].round)
    impl_->polish(static_cast<std::size_t>(a), Ta, static_cast<std::size_t>(b), Tb, out);
  return out;
}

Eigen::Vector3d DistanceQuery::nearest_point(int k, const Eigen::Isometry3d& T, const Eigen::Vector3d& w) const {
  REDRES_REQUIRE(k >= 0 && k < size(), "DistanceQuery::nearest_point", "0 <= shape < size()");
  if (const auto& cloud = impl_->cloud[static_cast<std::size_t>(k)]) {
    const Eigen::Vector3d local = T.inverse() * w;
    const RoundMetric m(local, local, 0.0, cloud->grow());
    Eigen::Vector3d on_query, on_cloud;
    const double d = cloud->nearest(m, std::numeric_limits<double>::infinity(), on_query, on_cloud);
    if (!(d > 0.0)) return w;  // inside the cloud (or an empty one): the point itself, as for any shape
    return T * on_cloud;
  }
  return impl_->project(static_cast<std::size_t>(k), T, w);
}

double DistanceQuery::lower_bound(int a, const Eigen::Isometry3d& Ta, int b, const Eigen::Isometry3d& Tb) const {
  const auto ka = static_cast<std::size_t>(a), kb = static_cast<std::size_t>(b);
  const double from_a = (Ta.translation() - impl_->project(kb, Tb, Ta.translation())).norm() - impl_->bound[ka];
  const double from_b = (Tb.translation() - impl_->project(ka, Ta, Tb.translation())).norm() - impl_->bound[kb];
  return std::max(from_a, from_b);
}

void DistanceQuery::build_broadphase(int first, int count) {
  if (first < 0 || count < 0 || first + count > size()) {
    throw std::invalid_argument("DistanceQuery::build_broadphase: shapes [" + std::to_string(first) + ", " +
                                std::to_string(first + count) + ") are not within the " + std::to_string(size()) +
                                " shapes");
  }
  impl_->tree = std::make_unique<fcl::DynamicAABBTreeCollisionManagerd>();
  impl_->group_first = first;
  impl_->group_count = count;
  std::vector<fcl::CollisionObjectd*> group;
  for (int k = 0; k < count; ++k) {
    fcl::CollisionObjectd* o = impl_->objects[static_cast<std::size_t>(first + k)].get();
    o->setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(first + k)));
    o->computeAABB();
    group.push_back(o);
  }
  impl_->tree->registerObjects(group);
  impl_->tree->setup();
}

void DistanceQuery::move_group(const Eigen::Isometry3d* poses) {
  if (!impl_->tree) return;
  for (int k = 0; k < impl_->group_count; ++k) {
    fcl::CollisionObjectd* o = impl_->objects[static_cast<std::size_t>(impl_->group_first + k)].get();
    const Eigen::Isometry3d T = poses[k] * impl_->object_offset[static_cast<std::size_t>(impl_->group_first + k)];
    o->setTransform(fcl::Transform3d(T.matrix()));
    o->computeAABB();
  }
  impl_->tree->update();
}

int DistanceQuery::near(int a, const Eigen::Isometry3d& Ta, double within, int* out) const {
  if (!impl_->tree || a < 0 || a >= size()) return 0;
  fcl::CollisionObjectd* q = impl_->objects[static_cast<std::size_t>(a)].get();
  q->setTransform(fcl::Transform3d(Ta.matrix()));
  q->computeAABB();
  NearData data{&q->getAABB(), within, out, 0};
  impl_->tree->distance(q, &data, near_callback);
  return data.count;
}

}  // namespace redres

// A URDF link's elements, read from urdfdom's model (with urdf.cpp, the translation units that include urdfdom).

#include "parsers/urdf_elements.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <urdf_model/link.h>
#include <urdf_model/pose.h>

#include "common/text.hpp"
#include "redres/config/config.hpp"
#include "redres/model/robot.hpp"

namespace redres {

Eigen::Isometry3d pose_of(const urdf::Pose& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  t.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).toRotationMatrix();
  return t;
}

void check_length(const std::string& who, const char* what, double value, bool positive) {
  const double bound = *physical_bound("m");
  if (!(std::abs(value) <= bound) || (positive && !(value > 0.0))) {
    throw UrdfError(who + ": " + what + " expected " + (positive ? "> 0 and " : "") + "|x| <= " + num(bound) +
                    " m (a physical range), got " + num(value));
  }
}

void check_pose(const std::string& who, const char* what, const urdf::Pose& p) {
  const std::string xyz = std::string(what) + " xyz";
  for (double v : {p.position.x, p.position.y, p.position.z}) check_length(who, xyz.c_str(), v, false);
  const double q[4] = {p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z};
  if (!std::all_of(std::begin(q), std::end(q), [](double v) { return std::isfinite(v); })) {
    throw UrdfError(who + ": " + what + " rpy is not finite");
  }
}

namespace {

// A <collision> or <visual> element's geometry (`element`: "" or "<visual> ", for messages), checked: lengths
// positive and physical, a mesh's scale positive.
ChainVisual read_geometry(const std::string& who, const std::string& element, const urdf::Geometry& geometry) {
  ChainVisual g;
  switch (geometry.type) {
    case urdf::Geometry::SPHERE:
      g.kind = ChainVisual::Kind::kSphere;
      g.radius = static_cast<const urdf::Sphere&>(geometry).radius;
      check_length(who, (element + "<sphere> radius").c_str(), g.radius, true);
      break;
    case urdf::Geometry::BOX: {
      const urdf::Vector3& d = static_cast<const urdf::Box&>(geometry).dim;
      g.kind = ChainVisual::Kind::kBox;
      g.size = {d.x, d.y, d.z};
      for (double v : g.size) check_length(who, (element + "<box> size").c_str(), v, true);
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cyl = static_cast<const urdf::Cylinder&>(geometry);
      g.kind = ChainVisual::Kind::kCylinder;
      g.radius = cyl.radius;
      g.length = cyl.length;
      check_length(who, (element + "<cylinder> radius").c_str(), cyl.radius, true);
      check_length(who, (element + "<cylinder> length").c_str(), cyl.length, true);
      break;
    }
    case urdf::Geometry::MESH: {
      const auto& mesh = static_cast<const urdf::Mesh&>(geometry);
      g.kind = ChainVisual::Kind::kMesh;
      g.filename = mesh.filename;
      g.scale = Eigen::Vector3d(mesh.scale.x, mesh.scale.y, mesh.scale.z);
      if (!g.scale.allFinite() || (g.scale.array() <= 0.0).any()) {
        throw UrdfError(who + ": " + element + "<mesh> scale expected > 0 on every axis");
      }
      break;
    }
  }
  return g;
}

}  // namespace

void add_shapes(const Namer& names, const urdf::Link& link, const Eigen::Isometry3d& at, const std::string& messages,
                ChainLink& out) {
  const std::string who = names.link(link.name);
  // The mass properties ride with the shapes; a massless <inertial> (a frame with no body) adds nothing.
  if (link.inertial && link.inertial->mass != 0.0) {
    const urdf::Inertial& in = *link.inertial;
    check_pose(who, "<inertial> <origin>", in.origin);
    Inertia body;
    body.mass = in.mass;
    body.tensor << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    const Eigen::Isometry3d frame = at * pose_of(in.origin);
    if (!(std::isfinite(in.mass) && in.mass > 0.0)) throw UrdfError(who + ": <inertial>: expected a mass >= 0");
    // A maker's tensor that no rigid body has (rounded figures break the triangle inequality) does not stop the
    // robot from loading: its kinematics do not need it. It is kept as given, with a warning.
    if (const std::string bad = body.invalid(); !bad.empty()) out.warnings.push_back(who + ": <inertial>: " + bad);
    const Inertia placed = body.moved(frame);  // com at the origin of the inertial frame
    out.inertia = out.inertia ? out.inertia->combined(placed) : placed;
  }
  for (const urdf::CollisionSharedPtr& c : link.collision_array) {
    if (!c) continue;
    if (!c->geometry) {
      throw UrdfError(who + " has a <collision> element whose geometry could not be read" +
                      (messages.empty() ? std::string() : " (" + printable(messages) + ")"));
    }
    check_pose(who, "<collision> <origin>", c->origin);
    const Eigen::Isometry3d pose = at * pose_of(c->origin);
    const ChainVisual g = read_geometry(who, "", *c->geometry);
    if (g.kind == ChainVisual::Kind::kMesh) {
      out.meshes.push_back({g.filename, g.scale, pose});
      continue;
    }
    ShapeSpec s;
    s.xyz = {pose.translation().x(), pose.translation().y(), pose.translation().z()};
    s.rpy = rpy_of(pose.linear());
    switch (g.kind) {
      case ChainVisual::Kind::kSphere:
        s.shape = ShapeSpec::Kind::kSphere;
        s.radius = g.radius;
        break;
      case ChainVisual::Kind::kBox:
        s.shape = ShapeSpec::Kind::kBox;
        s.size = g.size;
        break;
      default:
        s.shape = ShapeSpec::Kind::kCylinder;
        s.radius = g.radius;
        s.length = g.length;
        break;
    }
    out.shapes.push_back(s);
  }
}

void add_visuals(const Namer& names, const urdf::Link& link, const Eigen::Isometry3d& at,
                 std::vector<ChainVisual>& out) {
  const std::string who = names.link(link.name);
  for (const urdf::VisualSharedPtr& v : link.visual_array) {
    if (!v || !v->geometry) continue;  // urdfdom reports a visual it cannot read as it parses; nothing to draw
    check_pose(who, "<visual> <origin>", v->origin);
    ChainVisual u;
    u.link = link.name;
    u.pose = at * pose_of(v->origin);
    const ChainVisual g = read_geometry(who, "<visual> ", *v->geometry);
    u.kind = g.kind;
    u.filename = g.filename;
    u.scale = g.scale;
    u.size = g.size;
    u.radius = g.radius;
    u.length = g.length;
    if (v->material) {
      const urdf::Color& c = v->material->color;
      const std::array<double, 4> rgba{static_cast<double>(c.r), static_cast<double>(c.g), static_cast<double>(c.b),
                                       static_cast<double>(c.a)};
      if (std::all_of(rgba.begin(), rgba.end(), [](double x) { return std::isfinite(x) && x >= 0.0 && x <= 1.0; })) {
        u.rgba = rgba;
      }
    }
    out.push_back(std::move(u));
  }
}

void check_name(const std::string& who, const std::string& name) {
  if (!is_printable_name(name)) {
    throw UrdfError(who + ": the name is not UTF-8 without control characters (it reads '" + printable(name) + "')");
  }
}

}  // namespace redres

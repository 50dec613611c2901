// mjcf_from_robot(): a RobotModel as MuJoCo's XML (docs/plant.md). Plain text; MuJoCo itself is not needed here.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdio>
#include <initializer_list>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "common/xml_text.hpp"
#include "redres/model/convex.hpp"
#include "redres/plant/mujoco_model.hpp"
#include "redres/plant/plant.hpp"

namespace redres {
namespace {

// MuJoCo refuses a moving body whose mass or a principal moment is not above this (its mjMINVAL).
constexpr double kMinValue = 1e-15;

// A double with 17 significant digits: it reads back as the same double.
std::string num(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

std::string nums(std::initializer_list<double> xs) {
  std::string s;
  for (const double x : xs) {
    if (!s.empty()) s += ' ';
    s += num(x);
  }
  return s;
}

std::string vec3(const Eigen::Vector3d& v) { return nums({v.x(), v.y(), v.z()}); }

// MuJoCo's quaternions are w x y z.
std::string quat(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  return nums({q.w(), q.x(), q.y(), q.z()});
}

std::string pose_attributes(const Eigen::Isometry3d& T) {
  return "pos=\"" + vec3(T.translation()) + "\" quat=\"" + quat(T.linear()) + "\"";
}

// Why the link has no mass properties MuJoCo could take ("" when it has): none given, or a mass or principal moment
// not above MuJoCo's minimum.
std::string missing_inertia(const JointSpec& joint) {
  if (!joint.inertia) return "no inertia";
  const Inertia& in = *joint.inertia;
  if (!(in.mass > kMinValue)) return "mass " + num(in.mass) + " kg";
  const Eigen::Matrix3d sym = 0.5 * (in.tensor + in.tensor.transpose());
  const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(sym, Eigen::EigenvaluesOnly).eigenvalues()(0);
  if (!(smallest > kMinValue)) return "smallest principal moment " + num(smallest) + " kg m^2";
  return "";
}

// The attributes of a geom of `spec` placed at `pose` in its body (after `name="..." `); a convex hull adds its
// <mesh> asset to `assets`. `who` names the shape's owner in errors.
std::string shape_attributes(const ShapeSpec& spec, const Eigen::Isometry3d& pose, const std::string& name,
                             std::string& assets, const std::string& who) {
  std::string g;
  switch (spec.shape) {
    case ShapeSpec::Kind::kSphere:
      g += "type=\"sphere\" size=\"" + num(spec.radius.value_or(0.0)) + "\" " + pose_attributes(pose);
      break;
    case ShapeSpec::Kind::kCapsule: {
      // The capsule's axis is its pose's z axis, centred on its origin (ShapeSpec::pose()).
      const double half = 0.5 * spec.axis_length();
      if (half > 0.0) {
        const Eigen::Vector3d a = pose * Eigen::Vector3d(0, 0, -half), b = pose * Eigen::Vector3d(0, 0, half);
        g += "type=\"capsule\" size=\"" + num(spec.radius.value_or(0.0)) + "\" fromto=\"" + vec3(a) + " " + vec3(b) +
             "\"";
      } else {  // a capsule of no length is a sphere
        g += "type=\"sphere\" size=\"" + num(spec.radius.value_or(0.0)) + "\" " + pose_attributes(pose);
      }
      break;
    }
    case ShapeSpec::Kind::kCylinder:
      g += "type=\"cylinder\" size=\"" + nums({spec.radius.value_or(0.0), 0.5 * spec.length.value_or(0.0)}) + "\" " +
           pose_attributes(pose);
      break;
    case ShapeSpec::Kind::kBox: {
      const std::array<double, 3> size = spec.size.value_or(std::array<double, 3>{0, 0, 0});
      g += "type=\"box\" size=\"" + nums({0.5 * size[0], 0.5 * size[1], 0.5 * size[2]}) + "\" " + pose_attributes(pose);
      break;
    }
    case ShapeSpec::Kind::kConvex: {
      if (!spec.hull) throw std::invalid_argument(who + ": a convex shape without its hull");
      // MuJoCo makes the hull of the vertices itself; it moves the mesh to its centre of mass and principal axes
      // and moves the geom's pose the other way, so the shape stays where it is given.
      std::string vertices;
      for (const Eigen::Vector3d& v : spec.hull->vertices) vertices += (vertices.empty() ? "" : " ") + vec3(v);
      assets += "    <mesh name=\"" + name + "\" vertex=\"" + vertices + "\"/>\n";
      g += "type=\"mesh\" mesh=\"" + name + "\" " + pose_attributes(pose);
      break;
    }
    case ShapeSpec::Kind::kOctree:
    case ShapeSpec::Kind::kPoints:
      throw std::invalid_argument(who + " has a point cloud or octree shape, which a MuJoCo model cannot hold");
  }
  return g;
}

}  // namespace

bool mjcf_moving_obstacle(const ShapeSpec& o) {
  return o.velocity && (o.velocity->at(0) != 0.0 || o.velocity->at(1) != 0.0 || o.velocity->at(2) != 0.0);
}

Eigen::Matrix3Xd mjcf_mocap_positions(const std::vector<ShapeSpec>& obstacles, double t) {
  const auto moving = std::count_if(obstacles.begin(), obstacles.end(), mjcf_moving_obstacle);
  Eigen::Matrix3Xd out(3, moving);
  Eigen::Index k = 0;
  for (const ShapeSpec& o : obstacles) {
    if (!mjcf_moving_obstacle(o)) continue;
    out.col(k++) =
        o.pose().translation() + t * Eigen::Vector3d(o.velocity->at(0), o.velocity->at(1), o.velocity->at(2));
  }
  return out;
}

std::string mjcf_body_name(const RobotModel& robot, int j) {
  return robot.bodies().at(static_cast<std::size_t>(robot.body_of_joint(j))).name;
}

std::string mjcf_from_robot(const RobotModel& robot, const MjcfOptions& options) {
  const int n = robot.dof();
  std::string missing, impossible;
  for (int j = 0; j < n; ++j) {
    const JointSpec& joint = robot.joint(j);
    const std::string why = missing_inertia(joint);
    if (!why.empty()) {
      if (!options.placeholder_inertia)
        missing += (missing.empty() ? "" : ", ") + ("'" + joint.name + "' (" + why + ")");
    } else if (const std::string invalid = joint.inertia->invalid(); !invalid.empty() && !options.balance_inertia) {
      impossible += (impossible.empty() ? "" : ", ") + ("'" + joint.name + "' (" + invalid + ")");
    }
  }
  if (!missing.empty() || !impossible.empty()) {
    std::string what = "robot '" + robot.name() + "': MuJoCo needs physical mass properties for every moving link";
    if (!missing.empty())
      what += "; the links of these joints have none usable: " + missing +
              " (give each joint an `inertia`, or allow placeholder masses: MjcfOptions::placeholder_inertia)";
    if (!impossible.empty())
      what += "; the links of these joints have mass properties no rigid body has: " + impossible +
              " (correct them, or let MuJoCo balance the principal moments: MjcfOptions::balance_inertia)";
    throw std::invalid_argument(what);
  }
  if (!(options.placeholder_mass > kMinValue) || !(options.placeholder_moment > kMinValue))
    throw std::invalid_argument("MjcfOptions: the placeholder mass and moment must be > 1e-15");

  // The shapes of each joint's link, and the hulls' mesh assets.
  std::vector<std::string> geoms(static_cast<std::size_t>(n));
  std::string assets;
  std::vector<int> count(static_cast<std::size_t>(n), 0);
  for (const RobotModel::LinkShape& s : robot.link_shapes()) {
    const auto j = static_cast<std::size_t>(s.link);
    const std::string name = xml_escaped(mjcf_body_name(robot, s.link)) + "_shape" + std::to_string(count[j]++);
    std::string& g = geoms[j];
    g += "      <geom name=\"" + name + "\" ";
    g += shape_attributes(s.spec, s.pose, name, assets,
                          "robot '" + robot.name() + "': joint '" + robot.joint(s.link).name + "'");
    g += "/>\n";
  }

  std::ostringstream out;
  const std::string model = options.model_name.empty() ? robot.name() : options.model_name;
  out << "<mujoco model=\"" << xml_escaped(model) << "\">\n"
      << "  <!-- Written by redres (mjcf_from_robot). -->\n"
      << "  <compiler angle=\"radian\" inertiafromgeom=\"false\""
      << (options.balance_inertia ? " balanceinertia=\"true\"" : "") << "/>\n";
  // MuJoCo leaves out contacts between a body and its parent; redres checks a side branch's links (a URDF's hand)
  // against the neighbouring joint's link, so the excluded pairs below decide alone.
  if (options.plant) {
    const PlantConfig& plant = *options.plant;
    if (!(plant.timestep > 0.0)) throw std::invalid_argument("MjcfOptions: the plant's timestep must be > 0");
    const char* integrator = plant.integrator == PlantIntegrator::kImplicit ? "implicit" : "Euler";
    out << "  <option timestep=\"" << num(plant.timestep) << "\" integrator=\"" << integrator << "\" gravity=\""
        << nums({0.0, 0.0, -9.81 * plant.gravity}) << "\">\n";
  } else {
    out << "  <option>\n";
  }
  out << "    <flag filterparent=\"disable\"/>\n  </option>\n";
  // Offscreen frames (a film of the run) up to 1920 x 1080.
  out << "  <visual>\n    <global offwidth=\"1920\" offheight=\"1080\"/>\n  </visual>\n";
  // Obstacles: contype 2, conaffinity 1 collide with the robot's geoms (1, 1), not with each other.
  std::string still, moving;
  for (std::size_t k = 0; k < options.obstacles.size(); ++k) {
    const ShapeSpec& o = options.obstacles[k];
    const std::string name = "obstacle" + std::to_string(k);
    const std::string look = "contype=\"2\" conaffinity=\"1\" rgba=\"0.85 0.3 0.25 0.6\" ";
    if (!mjcf_moving_obstacle(o)) {
      still += "    <geom name=\"" + name + "\" " + look +
               shape_attributes(o, o.pose(), name, assets, "obstacle " + std::to_string(k)) + "/>\n";
    } else {
      moving += "    <body name=\"" + name + "\" mocap=\"true\" " + pose_attributes(o.pose()) +
                ">\n      <geom name=\"" + name + "\" " + look +
                shape_attributes(o, Eigen::Isometry3d::Identity(), name, assets, "obstacle " + std::to_string(k)) +
                "/>\n    </body>\n";
    }
  }
  if (!assets.empty()) out << "  <asset>\n" << assets << "  </asset>\n";
  out << "  <worldbody>\n" << still << moving;
  std::string indent = "    ";
  for (int j = 0; j < n; ++j) {
    const JointSpec& joint = robot.joint(j);
    // Body j's frame is the link frame of joint j; at theta_j = 0 it sits at B_{j-1} A_j in its parent (P A_1 for the
    // first), and the joint moves it about/along u_j through its origin.
    const Eigen::Isometry3d place = (j == 0 ? robot.base() : robot.after(j - 1)) * robot.before(j);
    out << indent << "<body name=\"" << xml_escaped(mjcf_body_name(robot, j)) << "\" " << pose_attributes(place)
        << ">\n";
    const std::string in = indent + "  ";
    out << in << "<joint name=\"" << xml_escaped(joint.name) << "\" type=\""
        << (joint.type == JointType::kRevolute ? "hinge" : "slide") << "\" pos=\"0 0 0\" axis=\"" << vec3(robot.axis(j))
        << "\" limited=\"true\" range=\"" << nums({joint.lower, joint.upper}) << "\"";
    if (joint.damping) out << " damping=\"" << num(*joint.damping) << "\"";
    if (joint.armature) out << " armature=\"" << num(*joint.armature) << "\"";
    out << "/>\n";
    if (missing_inertia(joint).empty()) {
      const Inertia& m = *joint.inertia;
      const Eigen::Matrix3d& I = m.tensor;
      out << in << "<inertial pos=\"" << vec3(m.com) << "\" mass=\"" << num(m.mass) << "\" fullinertia=\""
          << nums({I(0, 0), I(1, 1), I(2, 2), 0.5 * (I(0, 1) + I(1, 0)), 0.5 * (I(0, 2) + I(2, 0)),
                   0.5 * (I(1, 2) + I(2, 1))})
          << "\"/>\n";
    } else {  // placeholder (checked above that it is allowed)
      const double I = options.placeholder_moment;
      out << in << "<!-- placeholder: the robot gives no usable mass properties for this link -->\n"
          << in << "<inertial pos=\"0 0 0\" mass=\"" << num(options.placeholder_mass) << "\" diaginertia=\""
          << nums({I, I, I}) << "\"/>\n";
    }
    // The shapes were written with six spaces of indent; re-indent them for this depth.
    std::istringstream lines(geoms[static_cast<std::size_t>(j)]);
    for (std::string line; std::getline(lines, line);) out << in << line.substr(6) << "\n";
    if (j == n - 1)
      out << in << "<site name=\"" << xml_escaped(options.end_effector_site) << "\" "
          << pose_attributes(robot.after(j) * robot.end_effector()) << "/>\n";
    indent = in;
  }
  for (int j = n - 1; j >= 0; --j) out << std::string(4 + 2 * static_cast<std::size_t>(j), ' ') << "</body>\n";
  out << "  </worldbody>\n";

  // Body pairs redres never checks: every redres body on joint i against every one on joint k unchecked.
  std::vector<std::vector<int>> bodies_of(static_cast<std::size_t>(n));
  for (int b = 0; b < static_cast<int>(robot.bodies().size()); ++b)
    bodies_of[static_cast<std::size_t>(robot.bodies()[static_cast<std::size_t>(b)].link)].push_back(b);
  std::string excludes;
  for (int i = 0; i < n; ++i)
    for (int k = i + 1; k < n; ++k) {
      bool checked = false;
      for (const int a : bodies_of[static_cast<std::size_t>(i)])
        for (const int b : bodies_of[static_cast<std::size_t>(k)])
          checked = checked || robot.self_collision_bodies(a, b);
      if (!checked)
        excludes += "    <exclude body1=\"" + xml_escaped(mjcf_body_name(robot, i)) + "\" body2=\"" +
                    xml_escaped(mjcf_body_name(robot, k)) + "\"/>\n";
    }
  if (!excludes.empty()) out << "  <contact>\n" << excludes << "  </contact>\n";
  if (options.plant && options.plant->actuator != PlantActuator::kIdealVelocity) {
    const PlantConfig& plant = *options.plant;
    const bool servo = plant.actuator == PlantActuator::kVelocityServo;
    const Eigen::VectorXd kv = plant.kv.resolve(n, "kv"), kp = plant.kp.resolve(n, "kp"),
                          kd = plant.kd.resolve(n, "kd");
    out << "  <actuator>\n";
    for (int j = 0; j < n; ++j) {
      const JointSpec& joint = robot.joint(j);
      out << "    <general name=\"" << xml_escaped(joint.name) << "\" joint=\"" << xml_escaped(joint.name)
          << "\" ctrllimited=\"false\" gaintype=\"fixed\" biastype=\"affine\" ";
      if (servo) {  // kv (ctrl - qdot): ctrl is the velocity command
        out << "gainprm=\"" << num(kv(j)) << "\" biasprm=\"0 0 " << num(-kv(j)) << "\"";
      } else {  // ctrl - kp q - kd qdot: ctrl is kp q_ref + kd theta_dot_cmd
        out << "gainprm=\"1\" biasprm=\"0 " << num(-kp(j)) << " " << num(-kd(j)) << "\"";
      }
      if (joint.effort_limit) {
        out << " forcelimited=\"true\" forcerange=\"" << nums({-*joint.effort_limit, *joint.effort_limit}) << "\"";
      } else {
        out << " forcelimited=\"false\"";
      }
      out << "/>\n";
    }
    out << "  </actuator>\n";
  }
  out << "</mujoco>\n";
  return out.str();
}

}  // namespace redres

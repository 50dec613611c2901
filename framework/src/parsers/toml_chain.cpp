#include "parsers/toml_chain.hpp"

#include <array>
#include <utility>
#include <vector>

#include "common/text.hpp"
#include "parsers/robot_toml_values.hpp"

namespace redres {

using Eigen::Vector3d;

const Schema<JointReading>& JointReading::schema() {
  using C = JointReading;
  const auto dh = [](const char* key, double JointSpec::*member, bool length, const char* unit, const char* help) {
    return entry<C>(key, "number", unit, "0", help, [key, member, length](const TableReader& r, C& c) {
      if (c.kind != ChainKind::kSpatial || c.convention == DhConvention::kJointFrames) return;
      c.jt.*member = r.number(key, 0.0);
      if (length) length_value(r, key, c.jt.*member);
    });
  };
  static const Schema<C> s{{
      entry<C>("name", "string", "", "", "the joint's name, unique in the robot",
               [](const TableReader& r, C&) { (void)r.has("name"); })  // read first, by load_joint
          .required(),
      entry<C>("type", "one of 'revolute', 'prismatic'", "", "\"revolute\"",
               "revolute (theta in rad) or prismatic (in m; spatial chains only)",
               [](const TableReader& r, C& c) {
                 const std::string type = c.kind == ChainKind::kPlanar
                                              ? r.choice("type", {"revolute"}, "revolute")
                                              : r.choice("type", {"revolute", "prismatic"}, "revolute");
                 c.jt.type = type == "revolute" ? JointType::kRevolute : JointType::kPrismatic;
               }),
      entry<C>(
          "length", "number", "m", "none; required in a planar chain", "the link's length after the joint",
          [](const TableReader& r, C& c) {
            if (c.kind != ChainKind::kPlanar) return;
            c.jt.length = r.number("length");
            if (!(c.jt.length > 0.0)) r.fail("length", "expected a link length > 0 m, got " + num(c.jt.length));
            length_value(r, "length", c.jt.length);
          },
          "> 0; |x| <= 1000 m"),
      entry<C>("origin", "table {xyz, rpy}", "", "the identity",
               "the joint's frame in its parent's (convention = \"joints\")",
               [](const TableReader& r, C& c) {
                 if (c.kind != ChainKind::kSpatial || c.convention != DhConvention::kJointFrames) return;
                 if (r.has("origin")) c.jt.origin = read_pose(r, "origin", "joint '" + c.jt.name + "' origin", false);
               }),
      entry<C>(
          "axis", "array of 3 numbers", "", "[0, 0, 1]",
          "the joint's axis in its frame, normalised (convention = \"joints\")",
          [](const TableReader& r, C& c) {
            if (c.kind != ChainKind::kSpatial || c.convention != DhConvention::kJointFrames || !r.has("axis")) {
              return;
            }
            const std::vector<double> a = r.numbers("axis", 3);
            c.jt.axis = Vector3d(a[0], a[1], a[2]);
            if (!(c.jt.axis.norm() > 1e-9)) r.fail("axis", "expected a non-zero axis vector [x, y, z]");
            c.jt.axis.normalize();
          },
          "non-zero"),
      dh("a", &JointSpec::a, true, "m", "DH link length (convention = \"dh\" or \"modified_dh\")"),
      dh("alpha", &JointSpec::alpha, false, "rad", "DH link twist"),
      dh("d", &JointSpec::d, true, "m", "DH link offset"),
      dh("theta_offset", &JointSpec::theta_offset, false, "rad", "DH joint-angle offset"),
      entry<C>(
          "limits", "array of 2 numbers", "rad or m", "", "[lower, upper], the joint's range",
          [](const TableReader& r, C& c) { read_limits(r, c.jt); }, "lower < upper")
          .required(),
      entry<C>(
          "collision", "array of inline tables (below)", "", "[] (none)",
          "the link's collision shapes, in the joint's frame (self-collision, obstacle avoidance)",
          [](const TableReader& r, C& c) {
            if (!r.has("collision")) return;
            JointSpec& joint = c.jt;
            config_io::read(r, "collision", joint.collision);
            for (std::size_t k = 0; k < joint.collision.size(); ++k) {
              const ShapeSpec& sh = joint.collision[k];
              const std::string which = "joint '" + joint.name + "': key 'collision': shape " + std::to_string(k + 1);
              if (sh.velocity) {
                throw ConfigError(r.location("collision"), which + " has a velocity; only obstacles move");
              }
              const bool placed = sh.xyz != std::array<double, 3>{0, 0, 0} || sh.rpy != std::array<double, 3>{0, 0, 0};
              if (sh.shape == ShapeSpec::Kind::kCapsule && !sh.length && !sh.from && placed) {
                throw ConfigError(r.location("collision"),
                                  which +
                                      ": a capsule with `xyz` or `rpy` needs its `length` (or give `from` "
                                      "and `to`, or none of these to run along the link)");
              }
            }
          }),
      entry<C>("velocity_limit", "table", "", "",
               "the joint's velocity-limit law; `type` names it, its keys are its own (redres plugins)",
               [](const TableReader& r, C& c) { read_velocity_law(r, c.jt); })
          .required(),
      entry<C>("acceleration_limit", "table", "rad/s^2 or m/s^2", "none (unbounded)",
               "the joint's acceleration limits: a law of the same kinds as velocity_limit (constant, push_rod, ...)",
               [](const TableReader& r, C& c) {
                 if (!r.has("acceleration_limit")) return;  // none: unbounded
                 read_law(r, "acceleration_limit", "acceleration-limit", "rad/s^2 or m/s^2", c.jt,
                          c.jt.acceleration_limit, c.jt.acceleration_limit_source);
               }),
      entry<C>("jerk_limit", "table", "rad/s^3 or m/s^3", "none (unbounded)",
               "the joint's jerk limits (the rate of change of acceleration): a law as velocity_limit",
               [](const TableReader& r, C& c) {
                 if (!r.has("jerk_limit")) return;  // none: unbounded
                 read_law(r, "jerk_limit", "jerk-limit", "rad/s^3 or m/s^3", c.jt, c.jt.jerk_limit,
                          c.jt.jerk_limit_source);
               }),
      entry<C>("effort_limit", "number", "N m or N", "none", "the largest torque (force) the joint's drive gives",
               [](const TableReader& r, C& c) {
                 if (r.has("effort_limit")) read_effort(r, c.jt);
               }),
      entry<C>("damping", "number", "N m s/rad or N s/m", "0 (a URDF's <dynamics damping>)",
               "viscous damping of the joint in a physics plant ([plant] kind = \"mujoco\", docs/plant.md)",
               [](const TableReader& r, C& c) {
                 if (r.has("damping")) read_drive(r, "damping", "N m s/rad or N s/m", c.jt.damping);
               }),
      entry<C>("armature", "number", "kg m^2 or kg", "0",
               "the drive's reflected rotor inertia, added to the joint's in a physics plant (docs/plant.md)",
               [](const TableReader& r, C& c) {
                 if (r.has("armature")) read_drive(r, "armature", "kg m^2 or kg", c.jt.armature);
               }),
      entry<C>("inertia", "table {mass, com, ixx, iyy, izz, ixy, ixz, iyz}", "kg, m, kg m^2", "none",
               "the mass properties of the link the joint moves, in the link's frame: mass > 0, centre of mass "
               "`com` (default [0, 0, 0]), the inertia tensor about it (ixy, ixz, iyz default 0)",
               [](const TableReader& r, C& c) {
                 if (r.has("inertia")) read_inertia(r, c.jt);
               }),
  }};
  return s;
}

JointSpec load_joint(const TableReader& entry, ChainKind kind, DhConvention convention, std::set<std::string>& names) {
  JointReading reading;
  reading.kind = kind;
  reading.convention = convention;
  reading.jt.name = entry.string("name");
  if (reading.jt.name.empty()) entry.fail("name", "expected a non-empty joint name");
  if (!is_printable_name(reading.jt.name)) {
    entry.fail("name", "expected a name without control characters, got '" + printable(reading.jt.name) + "'");
  }
  const TableReader r(entry.file_ptr(), entry.raw(), "joint '" + reading.jt.name + "'");
  if (!names.insert(reading.jt.name).second) r.fail("name", "duplicate joint name '" + reading.jt.name + "'");
  read_config(r, JointReading::schema(), reading);
  r.finish();
  return std::move(reading.jt);
}

ChainDescription read_toml_chain(const TableReader& r, ChainKind kind, DhConvention convention) {
  ChainDescription chain;
  chain.file = r.file().path;
  std::set<std::string> names;
  const std::vector<TableReader> entries = r.tables("joints");
  if (entries.size() > kMaxJoints) {
    r.fail("joints",
           "expected at most " + std::to_string(kMaxJoints) + " joints, got " + std::to_string(entries.size()));
  }
  for (const TableReader& entry : entries) {
    ChainJoint joint;
    joint.spec = load_joint(entry, kind, convention, names);
    chain.joints.push_back(std::move(joint));
  }
  return chain;
}

}  // namespace redres

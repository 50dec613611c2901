#include "redres/parsers/robot_toml.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include "common/text.hpp"
#include "model/transforms.hpp"
#include "parsers/urdf.hpp"
#include "redres/config/plugin_loader.hpp"
#include "redres/model/convex.hpp"
#include "redres/model/mesh.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"

namespace redres {

using Eigen::Isometry3d;
using Eigen::Vector3d;

namespace {

// The URDF's <limit velocity=...> as a `constant` law of +-limit, built by name from the registry the way a robot
// file's [joints.velocity_limit] table names it (the framework includes no plugin header).
std::unique_ptr<VelocityLimitLaw> symmetric_constant_law(double limit, const std::filesystem::path& file) {
  auto doc = std::make_shared<TomlFile>();
  doc->path = file;
  doc->root.insert("type", "constant");
  doc->root.insert("lower", -limit);
  doc->root.insert("upper", limit);
  return make_velocity_limit(TableReader::root(doc, "velocity_limit"));
}

// A length, offset or position in metres, within the physical range of config.hpp's physical_bound("m").
double length_value(const TableReader& r, const char* key, double value) {
  const double bound = *physical_bound("m");
  if (!(std::abs(value) <= bound)) {
    r.fail(key, "expected |x| <= " + num(bound) + " m (a physical range), got " + num(value));
  }
  return value;
}

std::vector<double> length_values(const TableReader& r, const char* key, std::vector<double> values) {
  for (double v : values) length_value(r, key, v);
  return values;
}

// A pose table ([base], [end_effector], a joint's `origin`): spatial `xyz` (m) and `rpy` (rad, roll-pitch-yaw
// about the fixed x, y, z axes); planar `xyz` ([x, y], m) and `angle` (rad, about z). `position` is accepted for
// `xyz` (the end effector's older key).
struct PoseTable {
  bool planar = false;  // set before the table is read
  std::vector<double> xyz;
  std::vector<double> rpy{0.0, 0.0, 0.0};
  double angle = 0.0;
  [[nodiscard]] Isometry3d pose() const {
    const std::vector<double> p = !xyz.empty() ? xyz : std::vector<double>(planar ? 2 : 3, 0.0);
    if (planar) return trans(p[0], p[1], 0.0) * rot_z(angle);
    return trans(p[0], p[1], p[2]) * Isometry3d(rpy_matrix({rpy[0], rpy[1], rpy[2]}));
  }
  static const Schema<PoseTable>& schema() {
    using C = PoseTable;
    const auto position = [](const char* key) {
      return [key](const TableReader& t, C& c) {
        if (!t.has(key)) return;
        c.xyz = length_values(t, key, t.numbers(key, c.planar ? 2 : 3));
      };
    };
    static const Schema<C> s{{
        entry<C>("xyz", "array of 3 numbers (planar: 2)", "m", "[0, 0, 0] (planar: [0, 0])", "the position",
                 position("xyz"), "|x| <= 1000 m"),
        entry<C>(
            "position", "array of 3 numbers (planar: 2)", "m", "[0, 0, 0] (planar: [0, 0])", "the older name of `xyz`",
            [position](const TableReader& t, C& c) {
              if (t.has("xyz") && t.has("position")) t.fail("position", "give `xyz` or `position`, not both");
              position("position")(t, c);
            },
            "|x| <= 1000 m"),
        entry<C>("rpy", "array of 3 numbers", "rad", "[0, 0, 0]",
                 "roll, pitch, yaw about the fixed x, y, z axes (spatial)",
                 [](const TableReader& t, C& c) {
                   if (!c.planar && t.has("rpy")) c.rpy = t.numbers("rpy", 3);
                 }),
        entry<C>("angle", "number", "rad", "0", "the rotation about z (planar)",
                 [](const TableReader& t, C& c) {
                   if (c.planar) c.angle = t.number("angle", 0.0);
                 }),
    }};
    return s;
  }
};

// The pose table at `key` of `r`, named `context` in messages.
Isometry3d read_pose(const TableReader& r, const char* key, const std::string& context, bool planar) {
  const TableReader t = r.table(key);
  const TableReader pose_reader(t.file_ptr(), t.raw(), context);
  PoseTable pose;
  pose.planar = planar;
  read_config(pose_reader, PoseTable::schema(), pose);
  pose_reader.finish();
  return pose.pose();
}

// A joint's `limits` = [lower, upper], lower < upper, into jt.
void read_limits(const TableReader& r, JointSpec& jt) {
  const std::vector<double> lim = r.numbers("limits", 2);
  jt.lower = lim[0];
  jt.upper = lim[1];
  if (!(jt.lower < jt.upper)) {
    r.fail("limits",
           "expected [lower, upper] with lower < upper, got lower " + num(jt.lower) + " >= upper " + num(jt.upper));
  }
}

// A joint's limit-law table `key` (velocity_limit, acceleration_limit, jerk_limit) into `law` and `source`, checked
// over the joint's range (jt.lower, jt.upper set before). The three are laws of the same kinds (redres plugins).
void read_law(const TableReader& r, const char* key, const char* what, const char* unit, JointSpec& jt,
              std::shared_ptr<const VelocityLimitLaw>& law, std::string& source) {
  const TableReader law_table = r.table(key);
  const TableReader law_reader(law_table.file_ptr(), law_table.raw(), "joint '" + jt.name + "' " + key);
  law = make_velocity_limit(law_reader);
  source = r.location(key).str();
  law_reader.finish();
  if (auto bad = check_velocity_law(*law, jt.lower, jt.upper, *physical_bound(unit))) {
    law_reader.fail(std::string(what) + " law '" + law->type() + "' is invalid at theta = " + num(bad->theta) +
                    (jt.type == JointType::kRevolute ? " rad" : " m") + " (joint range [" + num(jt.lower) + ", " +
                    num(jt.upper) + "]): " + bad->reason);
  }
}

void read_velocity_law(const TableReader& r, JointSpec& jt) {
  read_law(r, "velocity_limit", "velocity-limit", "rad/s or m/s", jt, jt.velocity_limit, jt.velocity_limit_source);
}

void read_effort(const TableReader& r, JointSpec& jt) {
  const double e = r.number("effort_limit");
  if (!(std::isfinite(e) && e > 0.0 && e <= 1e7)) {
    r.fail("effort_limit", "expected a torque or force 0 < effort_limit <= 1e7 (N m or N), got " + num(e));
  }
  jt.effort_limit = e;
}

// `damping` or `armature` (docs/plant.md): a number >= 0.
void read_drive(const TableReader& r, const char* key, const char* unit, std::optional<double>& into) {
  const double v = r.number(key);
  if (!(std::isfinite(v) && v >= 0.0 && v <= 1e6)) {
    r.fail(key, std::string("expected 0 <= ") + key + " <= 1e6 (" + unit + "), got " + num(v));
  }
  into = v;
}

// An `inertia` table (of a joint: the link it moves; of a [[links]] entry: that URDF link), in the link's frame.
// `who` names it in messages ("joint 'j1'", "link 'head'").
Inertia read_inertia_table(const TableReader& r, const std::string& who) {
  const TableReader t = r.table("inertia");
  const TableReader in(t.file_ptr(), t.raw(), who + " inertia");
  Inertia body;
  body.mass = in.number("mass");
  const std::vector<double> com = in.has("com") ? in.numbers("com", 3) : std::vector<double>{0.0, 0.0, 0.0};
  body.com = Eigen::Vector3d(com[0], com[1], com[2]);
  const double ixx = in.number("ixx"), iyy = in.number("iyy"), izz = in.number("izz");
  const double ixy = in.has("ixy") ? in.number("ixy") : 0.0, ixz = in.has("ixz") ? in.number("ixz") : 0.0;
  const double iyz = in.has("iyz") ? in.number("iyz") : 0.0;
  body.tensor << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
  in.finish();
  if (const std::string bad = body.invalid(); !bad.empty()) r.fail("inertia", bad);
  return body;
}

// A joint's `inertia` table: the mass properties of the link it moves, in that link's frame.
void read_inertia(const TableReader& r, JointSpec& jt) {
  jt.inertia = read_inertia_table(r, "joint '" + jt.name + "'");
  jt.inertia_source = r.location("inertia").str();
}

// The optional motion limits of a joint beyond its velocity: acceleration and jerk laws, and the effort limit (a
// URDF joint's [[joints]] override; a [[joints]] entry of a TOML chain reads them key by key).
void read_motion_limits(const TableReader& r, JointSpec& jt) {
  if (r.has("acceleration_limit")) {
    read_law(r, "acceleration_limit", "acceleration-limit", "rad/s^2 or m/s^2", jt, jt.acceleration_limit,
             jt.acceleration_limit_source);
  }
  if (r.has("jerk_limit"))
    read_law(r, "jerk_limit", "jerk-limit", "rad/s^3 or m/s^3", jt, jt.jerk_limit, jt.jerk_limit_source);
  if (r.has("effort_limit")) read_effort(r, jt);
  if (r.has("damping")) read_drive(r, "damping", "N m s/rad or N s/m", jt.damping);
  if (r.has("armature")) read_drive(r, "armature", "kg m^2 or kg", jt.armature);
  if (r.has("inertia")) read_inertia(r, jt);
}

// The entries of the array of tables `key` (absent: none), by their `name`: each must name a `noun` that `known`
// accepts and appear once. An unknown name reads "no <what> named '<name>'<where>".
std::map<std::string, TableReader> named_entries(const TableReader& r, const char* key,
                                                 const std::function<bool(const std::string&)>& known,
                                                 const std::string& noun, const std::string& what,
                                                 const std::string& where,
                                                 std::vector<ConfigError>* problems = nullptr) {
  std::map<std::string, TableReader> out;
  if (!r.has(key)) return out;
  for (const TableReader& entry : r.tables(key)) {
    const std::string name = entry.string("name");
    if (!known(name)) {
      try {
        entry.fail("name", "no " + what + " named '" + name + "'" + where);
      } catch (const ConfigError& e) {
        if (problems == nullptr) throw;
        problems->push_back(e);
        (void)entry.raw();  // the entry's other keys are not read: it names nothing
        continue;
      }
    }
    if (!out.emplace(name, entry).second) entry.fail("name", "a second entry for " + noun + " '" + name + "'");
  }
  return out;
}

// A [[joints]] entry of a chain given joint by joint, read key by key in this order (the range comes before the
// velocity-limit law, which is checked over it). The URDF's [[joints]] entries are overrides: `name`, `limits` and
// `velocity_limit` only (load_urdf_chain).
struct JointReading {
  ChainKind kind = ChainKind::kPlanar;
  DhConvention convention = DhConvention::kStandard;
  JointSpec jt;
  static const Schema<JointReading>& schema();
};

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
            JointSpec& jt = c.jt;
            config_io::read(r, "collision", jt.collision);
            for (std::size_t k = 0; k < jt.collision.size(); ++k) {
              const ShapeSpec& sh = jt.collision[k];
              const std::string which = "joint '" + jt.name + "': key 'collision': shape " + std::to_string(k + 1);
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

// A robot file's top level, read key by key in this order. A file that names a URDF (`urdf`, `base_link`,
// `tip_link`) takes its chain from it (read_urdf_chain): `[[joints]]` entries, by joint name, may replace a joint's
// `limits`, `velocity_limit` and the motion limits (acceleration, jerk, effort); `[[links]]` entries, by link name,
// give collision shapes that replace
// (`replace = true`, the default) or add to the URDF's.
struct RobotReading {
  RobotSpec spec;
  std::string collision_model = "capsule";  // what a mesh collision element becomes (per link: [[links]])
  PackagePaths packages;                    // `packages`: where package://NAME/ is
  bool from_urdf = false;
  std::filesystem::path urdf;
  std::string base_link, tip_link;
  UrdfChain chain;
  std::map<std::string, double> held;  // `held_joints`
  // Problems found while reading the URDF's joints and links, reported together (throw_problems()).
  std::vector<ConfigError> problems;
  static const Schema<RobotReading>& schema();
};

// Runs f, keeping a ConfigError it throws among c.problems (so that the reading goes on to find the others).
template <class F>
void gather(RobotReading& c, F&& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    c.problems.push_back(e);
  }
}

// Throws the problems gathered, all in one error at the first one's place.
void throw_problems(const RobotReading& c) {
  if (c.problems.empty()) return;
  if (c.problems.size() == 1) throw c.problems.front();
  std::string all = std::to_string(c.problems.size()) + " problems in this robot file:";
  for (const ConfigError& e : c.problems) all += "\n  " + std::string(e.what());
  throw ConfigError(c.problems.front().where(), all);
}

// The URDF's joints, with the [[joints]] overrides. Every joint's problems are gathered (gather()).
void read_urdf_joints(const TableReader& r, RobotReading& c) {
  const std::map<std::string, TableReader> overrides = named_entries(
      r, "joints",
      [&](const std::string& name) {
        return std::any_of(c.chain.joints.begin(), c.chain.joints.end(),
                           [&](const UrdfJoint& j) { return j.name == name; });
      },
      "joint", "moving joint", " between '" + c.base_link + "' and '" + c.tip_link + "' in " + c.urdf.string(),
      &c.problems);
  for (const UrdfJoint& uj : c.chain.joints) {
    JointSpec jt;
    jt.name = uj.name;
    jt.type = uj.prismatic ? JointType::kPrismatic : JointType::kRevolute;
    jt.origin = uj.origin;
    jt.axis = uj.axis;
    jt.lower = uj.lower;
    jt.upper = uj.upper;
    gather(c, [&] {
      const auto o = overrides.find(uj.name);
      const std::optional<TableReader> entry =
          o == overrides.end() ? std::nullopt
                               : std::optional<TableReader>(
                                     TableReader(o->second.file_ptr(), o->second.raw(), "joint '" + uj.name + "'"));
      if (entry) (void)entry->has("name");
      if (entry && entry->has("limits")) {
        read_limits(*entry, jt);
      } else if (uj.continuous) {
        r.fail("urdf", uj.where +
                           " is continuous, which gives it no position limits: give its `limits` in a "
                           "[[joints]] entry");
      } else if (!(uj.lower < uj.upper)) {
        r.fail("urdf", uj.where + " has limits lower " + num(uj.lower) + " >= upper " + num(uj.upper) +
                           ": fix the URDF or give its `limits` in a [[joints]] entry");
      }
      if (entry && entry->has("velocity_limit")) {
        read_velocity_law(*entry, jt);
      } else if (uj.velocity > 0.0) {
        jt.velocity_limit = symmetric_constant_law(uj.velocity, c.urdf);
      } else {
        r.fail("urdf", uj.where +
                           " has no velocity limit: give one in the URDF (<limit velocity=...>) or a `velocity_limit` "
                           "in a [[joints]] entry");
      }
      if (uj.effort > 0.0) jt.effort_limit = uj.effort;
      if (uj.damping >= 0.0) jt.damping = uj.damping;
      if (entry) read_motion_limits(*entry, jt);
      if (entry) entry->finish();
    });
    c.spec.joints.push_back(std::move(jt));
  }
}

// A [[links]] entry of a URDF robot: collision shapes for one of the chain's links.
struct LinkEntry {
  std::string name;
  bool replace = true;
  std::vector<ShapeSpec> collision;
  std::string collision_model;  // empty: the robot's
  std::optional<Inertia> inertia;
  static const Schema<LinkEntry>& schema() {
    using C = LinkEntry;
    static const Schema<C> s{{
        field("name", &C::name, "", "the URDF link's name").required(),
        field("replace", &C::replace, "", "the shapes replace the URDF's collision elements (false: add to them)"),
        field("collision", &C::collision, "", "the link's shapes, in the link's frame (capsules need `length`)")
            .listed_default("[] (none)"),
        field("collision_model", &C::collision_model, "",
              "what this link's mesh collision elements become: \"capsule\", \"hull\" or \"none\" (default: the "
              "robot's)",
              rule<std::string>("\"capsule\", \"hull\" or \"none\"",
                                [](const std::string& v) { return v == "capsule" || v == "hull" || v == "none"; }))
            .listed_default("the robot's `collision_model`"),
        entry<C>("inertia", "table {mass, com, ixx, iyy, izz, ixy, ixz, iyz}", "kg, m, kg m^2", "the URDF's <inertial>",
                 "the link's mass properties, in the link's frame, replacing the URDF's (as a [[joints]] entry's "
                 "`inertia`)",
                 [](const TableReader& r, C& c) {
                   if (r.has("inertia")) c.inertia = read_inertia_table(r, "link '" + c.name + "'");
                 }),
    }};
    return s;
  }
};

// The collision shapes of the URDF's links, with the [[links]] entries.
void read_urdf_links(const TableReader& r, RobotReading& c) {
  std::string moving;  // the links that move with the chain, for the message naming a missing one
  for (const UrdfLink& l : c.chain.links) moving += (moving.empty() ? "'" : ", '") + l.name + "'";
  std::string all_links;
  for (const std::string& l : c.chain.all_links) all_links += (all_links.empty() ? "'" : ", '") + l + "'";
  const std::map<std::string, TableReader> link_entries = named_entries(
      r, "links",
      [&](const std::string& name) {
        return std::any_of(c.chain.links.begin(), c.chain.links.end(),
                           [&](const UrdfLink& l) { return l.name == name; });
      },
      "link", "link",
      " that moves with the chain from '" + c.base_link + "' to '" + c.tip_link + "' in " + c.urdf.string() +
          " (those are " + moving + "; the file's links are " + all_links + ")",
      &c.problems);
  std::vector<std::string> problems;  // every mesh that cannot be used, reported together
  const std::filesystem::path base_dir = c.urdf.parent_path();
  // The visual elements, for a viewer: a mesh that cannot be found is not drawn (and says why), never an error.
  const auto add_visual = [&](const UrdfVisual& v, int joint, const Eigen::Isometry3d& at) {
    VisualSpec out;
    out.kind = static_cast<VisualSpec::Kind>(static_cast<int>(v.kind));
    out.joint = joint;
    out.link = v.link;
    out.pose = at * v.pose;
    out.uri = v.filename;
    out.scale = v.scale;
    out.size = v.size;
    out.radius = v.radius;
    out.length = v.length;
    out.rgba = v.rgba;
    if (v.kind == UrdfVisual::Kind::kMesh) {
      try {
        out.file = std::filesystem::absolute(resolve_mesh(v.filename, base_dir, c.packages));
      } catch (const std::exception& ex) {
        out.problem = ex.what();
      }
    }
    c.spec.visuals.push_back(std::move(out));
  };
  for (const UrdfVisual& v : c.chain.base_visuals) add_visual(v, -1, Eigen::Isometry3d::Identity());
  for (const UrdfLink& link : c.chain.links) {
    if (c.spec.joints.size() <= static_cast<std::size_t>(link.joint)) break;
    for (const UrdfVisual& v : link.visuals) add_visual(v, link.joint, link.pose);
  }
  for (const UrdfLink& link : c.chain.links) {
    if (c.spec.joints.size() <= static_cast<std::size_t>(link.joint)) break;
    JointSpec& jt = c.spec.joints[static_cast<std::size_t>(link.joint)];
    if (jt.link_name.empty()) jt.link_name = link.name;  // the first link met on a joint is the one it moves
    jt.frames.emplace_back(link.name, link.pose);        // every link: a frame tasks can name
    if (link.branch) jt.branch_links.push_back(link.name);
    const std::size_t first_shape = jt.collision.size();
    const auto e = link_entries.find(link.name);
    bool replace = false;
    std::string model = c.collision_model;
    std::optional<Inertia> given_inertia;
    if (e != link_entries.end())
      gather(c, [&] {
        const TableReader entry(e->second.file_ptr(), e->second.raw(), "link '" + link.name + "'");
        LinkEntry links;
        read_config(entry, LinkEntry::schema(), links);
        replace = links.replace;
        if (!links.collision_model.empty()) model = links.collision_model;
        given_inertia = links.inertia;
        for (std::size_t k = 0; k < links.collision.size(); ++k) {
          const ShapeSpec& shape = links.collision[k];
          if (shape.shape == ShapeSpec::Kind::kCapsule && !shape.length && !shape.from) {
            entry.fail("collision", "shape " + std::to_string(k + 1) +
                                        ": a capsule of a URDF link needs `length` (with `xyz`, `rpy`) or `from` and "
                                        "`to`, in the link's frame");
          }
          if (shape.velocity) {
            entry.fail("collision", "shape " + std::to_string(k + 1) + " has a velocity; only obstacles move");
          }
          jt.collision.push_back(shape.placed(link.pose));
        }
        entry.finish();
      });
    // The link's mass properties (the [[links]] entry's, else the URDF's), in the joint's link frame; a [[joints]]
    // entry's `inertia` replaces them all.
    const std::optional<Inertia>& body = given_inertia ? given_inertia : link.inertia;
    if (body && jt.inertia_source.empty()) {
      const Inertia placed = body->moved(link.pose);
      jt.inertia = jt.inertia ? jt.inertia->combined(placed) : placed;
      if (!given_inertia) {
        for (const std::string& w : link.warnings) jt.inertia_warning += (jt.inertia_warning.empty() ? "" : "; ") + w;
      }
    }
    // Every shape of this link belongs to it (a body of its own: RobotModel::bodies()).
    const auto own = [&] {
      for (std::size_t k = first_shape; k < jt.collision.size(); ++k) jt.collision[k].body = link.name;
    };
    if (replace) {
      own();
      continue;
    }
    for (const ShapeSpec& shape : link.shapes) jt.collision.push_back(shape.placed(link.pose));
    if (model == "none") {
      own();
      continue;
    }
    // Mesh collision elements: a capsule fitted to each mesh, every piece of it (a file's meshes, e.g. an OBJ's
    // material groups, or a convex decomposition's pieces) together; or ("hull") the convex hull of each piece.
    for (const UrdfMesh& mesh : link.meshes) {
      try {
        const MeshData data =
            read_mesh(std::filesystem::absolute(resolve_mesh(mesh.filename, base_dir, c.packages)), mesh.scale);
        if (model == "hull") {
          const int pieces = static_cast<int>(data.pieces.size());
          for (int k = 0; k < pieces; ++k) {
            jt.collision.push_back(convex_shape(data.pieces[static_cast<std::size_t>(k)], data.file, k, pieces)
                                       .placed(link.pose * mesh.pose));
            jt.collision.back().source = data.file;
          }
          continue;
        }
        std::vector<Eigen::Vector3d> all;
        all.reserve(data.vertex_count());
        for (const auto& piece : data.pieces) all.insert(all.end(), piece.begin(), piece.end());
        jt.collision.push_back(fit_capsule(all).placed(link.pose * mesh.pose));
        jt.collision.back().source = data.file;
      } catch (const std::exception& ex) {
        problems.push_back(link.where + ": " + ex.what());
      }
    }
    own();
  }
  if (!problems.empty()) {
    std::string all = std::to_string(problems.size()) + " mesh" + (problems.size() == 1 ? "" : "es") + " of " +
                      c.urdf.string() + " cannot be used:";
    for (const std::string& p : problems) all += "\n  " + p;
    all += "\n(give a link's shapes in a [[links]] entry, or set its `collision_model = \"none\"`)";
    gather(c, [&] { r.fail("urdf", all); });
  }
  throw_problems(c);
}

// `key` of a robot file with a URDF only: refused in one without.
void only_with_urdf(const TableReader& r, const RobotReading& c, const char* key, const char* instead) {
  // Looked up without marking the key known: in a robot without a URDF, the known keys are the chain's.
  if (!c.from_urdf && r.raw().contains(key)) r.fail(key, std::string("is used only with `urdf`") + instead);
}

// `collision_exclude`: pairs of joints (all their links) or of links by name (a URDF's links, side branches
// included) that self-collision does not check.
void read_collision_exclude(const TableReader& r, RobotSpec& spec) {
  if (!r.has("collision_exclude")) return;
  const toml::array* pairs = r.raw().get("collision_exclude")->as_array();
  if (pairs == nullptr) {
    r.fail("collision_exclude", "expected an array of pairs of joint or link names, e.g. [[\"j1\", \"j3\"]]");
  }
  // The links that have shapes (bodies), by name; a joint stands for its link.
  std::vector<std::string> links;
  for (const JointSpec& jt : spec.joints) {
    for (const ShapeSpec& shape : jt.collision) {
      if (!shape.body.empty() && std::find(links.begin(), links.end(), shape.body) == links.end()) {
        links.push_back(shape.body);
      }
    }
  }
  for (const toml::node& p : *pairs) {
    const toml::array* pair = p.as_array();
    std::string names[2];
    int joints[2] = {-1, -1};
    for (std::size_t k = 0; k < 2; ++k) {
      const toml::node* el = pair != nullptr && pair->size() == 2 ? pair->get(k) : nullptr;
      const auto* name = el != nullptr ? el->as_string() : nullptr;
      if (name != nullptr) {
        names[k] = name->get();
        for (std::size_t j = 0; j < spec.joints.size(); ++j) {
          if (spec.joints[j].name == names[k]) joints[k] = static_cast<int>(j);
        }
      }
      const bool link = std::find(links.begin(), links.end(), names[k]) != links.end() ||
                        std::any_of(spec.joints.begin(), spec.joints.end(), [&](const JointSpec& jt) {
                          return !jt.link_name.empty() && jt.link_name == names[k];
                        });
      if (name == nullptr || (joints[k] < 0 && !link)) {
        std::string known;
        for (const JointSpec& jt : spec.joints) known += (known.empty() ? "'" : ", '") + jt.name + "'";
        for (const std::string& l : links) known += ", '" + l + "'";
        throw ConfigError(location_of(r.file(), p),
                          "key 'collision_exclude': expected pairs of two joint or link names of this robot, e.g. "
                          "[\"j1\", \"j3\"]" +
                              (name != nullptr ? ", got '" + names[k] + "' (known: " + known + ")" : std::string()));
      }
    }
    if (names[0] == names[1]) {
      throw ConfigError(location_of(r.file(), p), "key 'collision_exclude': a pair names one joint or link twice");
    }
    if (joints[0] >= 0 && joints[1] >= 0) {
      if (joints[0] == joints[1]) {
        throw ConfigError(location_of(r.file(), p), "key 'collision_exclude': a pair names one joint twice");
      }
      spec.collision_exclude.emplace_back(joints[0], joints[1]);
      continue;
    }
    // A link by name (or a joint, standing for the link it moves).
    for (std::size_t k = 0; k < 2; ++k) {
      if (joints[k] >= 0) {
        const JointSpec& jt = spec.joints[static_cast<std::size_t>(joints[k])];
        names[k] = jt.link_name.empty() ? jt.name : jt.link_name;
      }
    }
    spec.collision_exclude_bodies.emplace_back(names[0], names[1]);
  }
}

const Schema<RobotReading>& RobotReading::schema() {
  using C = RobotReading;
  static const Schema<C> s{{
      plugins_entry<C>("plugin libraries to load first (their velocity-limit laws may be named below)"),
      entry<C>("urdf", "path", "", "none (the chain is [[joints]])",
               "a URDF file whose chain from base_link to tip_link is the robot (docs/robot_format.md)",
               [](const TableReader& r, C& c) {
                 c.from_urdf = r.has("urdf");
                 if (!c.from_urdf) return;
                 c.urdf = r.path("urdf");
                 c.base_link = r.string("base_link");
                 c.tip_link = r.string("tip_link");
                 if (r.raw().contains("held_joints")) {  // needed to place the side branches: read here
                   const TableReader t = r.table("held_joints");
                   for (const auto& [key, value] : t.raw()) {
                     const std::string name(key.str());
                     c.held[name] = t.number(name);
                   }
                 }
                 try {
                   c.chain = read_urdf_chain(c.urdf, c.base_link, c.tip_link, c.held);
                 } catch (const UrdfError& e) {
                   r.fail("urdf", e.what());
                 } catch (const ConfigError& e) {
                   if (e.where().line == 0) r.fail("urdf", e.what());  // missing, not a regular file, too large
                   throw;
                 }
                 c.spec.end_effector = c.chain.tip;
                 for (const UrdfHeldJoint& h : c.chain.held) c.spec.held_joints.emplace_back(h.name, h.value);
               }),
      entry<C>("base_link", "string", "", "none; required with `urdf`",
               "the URDF link the chain starts at (required with `urdf`)",
               [](const TableReader& r, C& c) { only_with_urdf(r, c, "base_link", ""); }),
      entry<C>("tip_link", "string", "", "none; required with `urdf`",
               "the URDF link the chain ends at (required with `urdf`)",
               [](const TableReader& r, C& c) { only_with_urdf(r, c, "tip_link", ""); }),
      entry<C>("held_joints", "table { JOINT = number }", "rad or m", "0 (or the limit nearest 0)",
               "the positions the URDF's side-branch joints (a head's, a gripper's fingers') are held at; a mimic "
               "joint follows its leader (docs/robot_format.md, \"Trees\")",
               [](const TableReader& r, C& c) {
                 if (!r.has("held_joints")) return;
                 only_with_urdf(r, c, "held_joints", "");
                 const TableReader t = r.table("held_joints");
                 std::string names;
                 for (const UrdfHeldJoint& h : c.chain.held) names += (names.empty() ? "'" : ", '") + h.name + "'";
                 for (const auto& entry : c.held) {  // read with `urdf`, which places the branches with them
                   // Named copies, not a structured binding: clang before 16 cannot capture a binding in a lambda.
                   const std::string& name = entry.first;
                   const double v = entry.second;
                   const auto it = std::find_if(c.chain.held.begin(), c.chain.held.end(),
                                                [&](const UrdfHeldJoint& h) { return h.name == name; });
                   if (it == c.chain.held.end()) {
                     t.fail(name, "no held joint named '" + name + "' (the joints of side branches off the chain " +
                                      "from '" + c.base_link + "' to '" + c.tip_link + "'" +
                                      (names.empty() ? std::string(": there are none") : " are " + names) + ")");
                   }
                   if (!it->mimics.empty()) {
                     t.fail(name, "joint '" + name + "' is a mimic of joint '" + it->mimics +
                                      "' and follows it: hold '" + it->mimics + "' instead");
                   }
                   if (it->limited && (v < std::min(it->lower, it->upper) || v > std::max(it->lower, it->upper))) {
                     t.fail(name, "expected joint '" + name + "' within its limits [" + num(it->lower) + ", " +
                                      num(it->upper) + "], got " + num(v));
                   }
                 }
               }),
      entry<C>("collision_model", "\"capsule\", \"hull\" or \"none\"", "", "\"capsule\"",
               "what a URDF's mesh collision elements become: a capsule fitted to each mesh (all its pieces "
               "together), the convex hull of each piece, or nothing; a [[links]] entry may set its own "
               "(docs/robot_format.md, \"Meshes\")",
               [](const TableReader& r, C& c) {
                 if (!r.has("collision_model")) return;
                 only_with_urdf(r, c, "collision_model", "");
                 c.collision_model = r.choice("collision_model", {"capsule", "hull", "none"});
               }),
      entry<C>("packages", "table { NAME = \"dir\" }", "", "none",
               "where a URDF's package://NAME/ paths are, relative to this file (before REDRES_PACKAGE_PATH, "
               "ROS_PACKAGE_PATH and the URDF's own directory)",
               [](const TableReader& r, C& c) {
                 if (!r.has("packages")) return;
                 only_with_urdf(r, c, "packages", "");
                 const TableReader t = r.table("packages");
                 for (const auto& [key, value] : t.raw()) {
                   const std::string name(key.str());
                   c.packages.named[name] = t.path(name);
                 }
               }),
      entry<C>("name", "string", "", "the URDF's; required without `urdf`", "the robot's name",
               [](const TableReader& r, C& c) {
                 if (c.from_urdf) {
                   c.spec.name = r.string("name", c.chain.robot_name);
                   if (c.spec.name.empty()) r.fail("name", "expected a non-empty robot name (the URDF gives none)");
                 } else {
                   c.spec.name = r.string("name");
                   if (c.spec.name.empty()) r.fail("name", "expected a non-empty robot name");
                   if (!is_printable_name(c.spec.name)) {
                     r.fail("name", "expected a name without control characters, got '" + printable(c.spec.name) + "'");
                   }
                 }
               }),
      entry<C>("kind", "one of 'planar', 'spatial'", "", "\"spatial\" with `urdf`; required without",
               "planar (x, y in the plane, revolute joints with `length`) or spatial",
               [](const TableReader& r, C& c) {
                 if (c.from_urdf) {
                   if (r.has("kind") && r.choice("kind", {"spatial"}) != "spatial") {
                     r.fail("kind", "a URDF chain is spatial");
                   }
                   c.spec.kind = ChainKind::kSpatial;
                   return;
                 }
                 c.spec.kind =
                     r.choice("kind", {"planar", "spatial"}) == "planar" ? ChainKind::kPlanar : ChainKind::kSpatial;
               }),
      entry<C>("convention", "one of 'dh', 'modified_dh', 'joints'", "",
               "\"joints\" with `urdf`; required for a spatial chain",
               "how a spatial chain's joints are placed: DH parameters (a, alpha, d, theta_offset), modified DH, or "
               "joint frames (origin, axis), as a URDF's",
               [](const TableReader& r, C& c) {
                 if (c.from_urdf) {
                   if (r.has("convention") && r.choice("convention", {"joints"}) != "joints") {
                     r.fail("convention", "a URDF chain is made of joint frames");
                   }
                   c.spec.convention = DhConvention::kJointFrames;
                   return;
                 }
                 if (c.spec.kind != ChainKind::kSpatial) return;
                 const std::string conv = r.choice("convention", {"dh", "modified_dh", "joints"});
                 c.spec.convention = conv == "dh"            ? DhConvention::kStandard
                                     : conv == "modified_dh" ? DhConvention::kModified
                                                             : DhConvention::kJointFrames;
               }),
      entry<C>("task", "\"position\", \"pose\" or an array of rows", "", "\"position\"",
               "the task rows a scenario tracks unless it sets its own `task`",
               [](const TableReader& r, C& c) { read_task(r, c.spec); }),
      entry<C>("joints", "array of tables [[joints]] (below)", "", "none with `urdf`; required without",
               "the chain, base to tip (with `urdf`: overrides of `limits`, `velocity_limit`, `acceleration_limit`, "
               "`jerk_limit` and `effort_limit` by joint name)",
               [](const TableReader& r, C& c) {
                 if (c.from_urdf) {
                   read_urdf_joints(r, c);
                   return;
                 }
                 std::set<std::string> names;
                 const std::vector<TableReader> entries = r.tables("joints");
                 if (entries.size() > kMaxJoints) {
                   r.fail("joints", "expected at most " + std::to_string(kMaxJoints) + " joints, got " +
                                        std::to_string(entries.size()));
                 }
                 for (const TableReader& entry : entries) {
                   c.spec.joints.push_back(load_joint(entry, c.spec.kind, c.spec.convention, names));
                 }
               }),
      entry<C>("links", "array of tables [[links]] (below)", "", "none",
               "collision shapes of the URDF's links (with `urdf` only)",
               [](const TableReader& r, C& c) {
                 only_with_urdf(r, c, "links", " (a [[joints]] entry's `collision` gives its link's shapes)");
                 if (c.from_urdf) read_urdf_links(r, c);
               }),
      entry<C>("end_effector", "table {xyz, rpy} (planar: {xyz, angle})", "", "the last joint's frame (a URDF's tip)",
               "the end effector's frame in the last joint's (after the URDF's tip link)",
               [](const TableReader& r, C& c) {
                 if (!r.has("end_effector")) return;
                 c.spec.end_effector = c.spec.end_effector *
                                       read_pose(r, "end_effector", "end_effector", c.spec.kind == ChainKind::kPlanar);
               }),
      entry<C>("base", "table {xyz, rpy} (planar: {xyz, angle})", "", "the world frame",
               "the chain's base in the world",
               [](const TableReader& r, C& c) {
                 if (r.has("base")) c.spec.base = read_pose(r, "base", "base", c.spec.kind == ChainKind::kPlanar);
               }),
      entry<C>(
          "home", "array of numbers, one per joint", "rad or m", "zeros",
          "the configuration a scenario starts from unless it sets theta0",
          [](const TableReader& r, C& c) {
            if (!r.has("home")) return;
            RobotSpec& spec = c.spec;
            const auto n = static_cast<Eigen::Index>(spec.joints.size());
            const std::vector<double> h = r.numbers("home", static_cast<std::size_t>(n));
            spec.home = Eigen::Map<const Eigen::VectorXd>(h.data(), n);
            for (std::size_t j = 0; j < spec.joints.size(); ++j) {
              const JointSpec& jt = spec.joints[j];
              if (h[j] < jt.lower || h[j] > jt.upper) {
                r.fail("home", "expected joint '" + jt.name + "' within its limits [" + num(jt.lower) + ", " +
                                   num(jt.upper) + "], got " + num(h[j]));
              }
            }
          },
          "within the limits"),
      entry<C>("collision_exclude", "array of pairs of joint or link names", "", "[] (none)",
               "pairs of links that self-collision leaves out (neighbours always are): a joint names every link it "
               "moves, a URDF link's name that link alone",
               [](const TableReader& r, C& c) { read_collision_exclude(r, c.spec); }),
  }};
  return s;
}

}  // namespace

void read_task(const TableReader& r, RobotSpec& spec) {
  if (!r.has("task")) return;
  if (!r.raw()["task"].is_array()) {
    spec.task = r.choice("task", {"position", "pose"}) == "position" ? TaskRows::kPosition : TaskRows::kPose;
    spec.task_axes.clear();
    return;
  }
  const std::vector<std::string>& all = pose_row_names(spec.kind);
  std::vector<std::string> axes = r.strings("task");
  if (axes.empty()) r.fail("task", "expected \"position\", \"pose\" or a non-empty array of rows from " + join(all));
  std::ptrdiff_t previous = -1;
  for (const std::string& name : axes) {
    const auto it = std::find(all.begin(), all.end(), name);
    if (it == all.end()) {
      r.fail("task", "expected rows of the " + std::string(to_string(spec.kind)) + " pose (" + join(all) + "), got '" +
                         name + "'");
    }
    if (it - all.begin() <= previous) {
      r.fail("task", "expected each row once, in the order " + join(all) + " ('" + name + "' is out of place)");
    }
    previous = it - all.begin();
  }
  spec.task_axes = std::move(axes);
}

RobotModel load_urdf_robot(const std::filesystem::path& urdf, const std::string& base_link,
                           const std::string& tip_link) {
  std::string base = base_link, tip = tip_link;
  if (base.empty() || tip.empty()) {
    std::pair<std::string, std::string> chain;
    try {
      chain = default_urdf_chain(urdf);
    } catch (const UrdfError& e) {
      throw std::runtime_error(e.what());
    }
    if (base.empty()) base = chain.first;
    if (tip.empty()) tip = chain.second;
  }
  auto doc = std::make_shared<TomlFile>();
  doc->path = urdf;  // the keys below are the command line's; paths resolve beside the URDF
  doc->root.insert("urdf", std::filesystem::absolute(urdf).string());
  doc->root.insert("base_link", base);
  doc->root.insert("tip_link", tip);
  return load_robot(TableReader::root(doc, "robot"));
}

RobotModel load_robot(const std::filesystem::path& file) {
  return load_robot(TableReader::root(parse_toml_file(file), "robot"));
}

RobotModel load_robot(const TableReader& r) {
  RobotReading reading;
  reading.spec.source = r.file().path.string();
  read_config(r, RobotReading::schema(), reading);
  r.finish();
  return RobotModel(std::move(reading.spec));
}

const std::vector<KeyTable>& robot_key_tables() {
  static const std::vector<KeyTable> tables = {
      {"robot", "", "a robot file's top level", describe_keys(RobotReading::schema())},
      {"robot", "[[joints]]", "one joint and the link after it (a URDF robot's: name, limits, velocity_limit)",
       describe_keys(JointReading::schema())},
      {"robot", "[base], [end_effector], origin", "a pose", describe_keys(PoseTable::schema())},
      {"robot", "[[links]]", "collision shapes of a URDF link", describe_keys(LinkEntry::schema())},
      {"robot", "collision = [{...}]", "one collision shape (of a joint's link, a URDF link or an obstacle)",
       describe_keys(ShapeSpec::schema())},
  };
  return tables;
}

}  // namespace redres

#include "redres/parsers/robot_toml.hpp"

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "common/text.hpp"
#include "parsers/chain_build.hpp"
#include "parsers/chain_description.hpp"
#include "parsers/collision_exclusions.hpp"
#include "parsers/robot_toml_values.hpp"
#include "parsers/toml_chain.hpp"
#include "parsers/urdf.hpp"
#include "parsers/urdf_overlay.hpp"
#include "redres/config/plugin_loader.hpp"

namespace redres {

namespace {

// A robot file's top level, read key by key in this order. A file that names a URDF (`urdf`, `base_link`,
// `tip_link`) takes its chain from it (read_urdf_chain): `[[joints]]` entries, by joint name, may replace a joint's
// `limits`, `velocity_limit` and the motion limits (acceleration, jerk, effort); `[[links]]` entries, by link name,
// give collision shapes that replace
// (`replace = true`, the default) or add to the URDF's.
struct RobotReading {
  RobotSpec spec;
  ChainOptions options;  // `collision_model` (what a mesh collision element becomes; per link: [[links]]), `packages`
  bool from_urdf = false;
  std::filesystem::path urdf;
  std::string base_link, tip_link;
  ChainDescription chain;              // the URDF's, or the [[joints]] given joint by joint
  std::map<std::string, double> held;  // `held_joints`
  // Problems found while building the chain's joints and links, reported together (build_chain()).
  std::vector<ConfigError> problems;
  static const Schema<RobotReading>& schema();
};

// A chain given joint by joint, built as given: a problem of its own would be the `joints` key's.
class AsGiven final : public ChainAmendments {
 public:
  explicit AsGiven(const TableReader& r) : r_(r) {}
  [[noreturn]] void fail(const std::string& message) const override { r_.fail("joints", message); }

 private:
  const TableReader& r_;
};

// `key` of a robot file with a URDF only: refused in one without.
void only_with_urdf(const TableReader& r, const RobotReading& c, const char* key, const char* instead) {
  // Looked up without marking the key known: in a robot without a URDF, the known keys are the chain's.
  if (!c.from_urdf && r.raw().contains(key)) r.fail(key, std::string("is used only with `urdf`") + instead);
}

// A robot's acceleration (jerk) limits are enforced on every joint or on none (joint_acceleration_limits and the
// braking law need every joint's): limits on some joints only are refused, naming the joints without one, where they
// would otherwise go unenforced without a word.
void motion_limits_on_every_joint(const TableReader& r, const RobotSpec& spec) {
  for (const bool acceleration : {true, false}) {
    std::string without;
    std::size_t with = 0;
    for (const JointSpec& jt : spec.joints) {
      if (acceleration ? jt.acceleration_limit != nullptr : jt.jerk_limit != nullptr) {
        ++with;
      } else {
        without += (without.empty() ? "'" : ", '") + jt.name + "'";
      }
    }
    if (with == 0 || with == spec.joints.size()) continue;
    const char* key = acceleration ? "acceleration_limit" : "jerk_limit";
    r.fail("joints", std::string(acceleration ? "expected an " : "expected a ") + key + " on every joint or on none: " +
                         std::to_string(with) + " of " + std::to_string(spec.joints.size()) + " joints have one, and " +
                         without + " not (limits on some joints only would not be enforced on any)");
  }
}

}  // namespace

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
                 for (const HeldJoint& h : c.chain.held) names += (names.empty() ? "'" : ", '") + h.name + "'";
                 for (const auto& entry : c.held) {  // read with `urdf`, which places the branches with them
                   // Named copies, not a structured binding: clang before 16 cannot capture a binding in a lambda.
                   const std::string& name = entry.first;
                   const double v = entry.second;
                   const auto it = std::find_if(c.chain.held.begin(), c.chain.held.end(),
                                                [&](const HeldJoint& h) { return h.name == name; });
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
                 c.options.collision_model = r.choice("collision_model", {"capsule", "hull", "none"});
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
                   c.options.packages.named[name] = t.path(name);
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
                 // The chain, from the URDF (amended by the [[joints]] and [[links]] entries) or given joint by joint,
                 // built into the robot's joints, shapes, frames, inertias and visuals.
                 if (c.from_urdf) {
                   UrdfOverlay overlay(r, c.base_link, c.tip_link, c.problems);
                   build_chain(c.chain, c.options, overlay, c.spec, c.problems);
                   motion_limits_on_every_joint(r, c.spec);
                   return;
                 }
                 c.chain = read_toml_chain(r, c.spec.kind, c.spec.convention);
                 AsGiven as_given(r);
                 build_chain(c.chain, c.options, as_given, c.spec, c.problems);
                 motion_limits_on_every_joint(r, c.spec);
               }),
      entry<C>("links", "array of tables [[links]] (below)", "", "none",
               "collision shapes of the URDF's links (with `urdf` only)",
               [](const TableReader& r, C& c) {
                 // With `urdf`, the entries are read with the chain (`joints`).
                 only_with_urdf(r, c, "links", " (a [[joints]] entry's `collision` gives its link's shapes)");
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
            RobotSpec& robot = c.spec;
            const auto n = static_cast<Eigen::Index>(robot.joints.size());
            const std::vector<double> h = r.numbers("home", static_cast<std::size_t>(n));
            robot.home = Eigen::Map<const Eigen::VectorXd>(h.data(), n);
            for (std::size_t j = 0; j < robot.joints.size(); ++j) {
              const JointSpec& jt = robot.joints[j];
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

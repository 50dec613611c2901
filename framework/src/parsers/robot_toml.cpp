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

// A pose table: spatial `xyz` (m) and `rpy` (rad, roll-pitch-yaw about the fixed x, y, z axes); planar `xyz`
// ([x, y], m) and `angle` (rad, about z). `position` is accepted for `xyz` (the end effector's older key).
Isometry3d read_pose(const TableReader& t, bool planar) {
  if (t.has("xyz") && t.has("position")) t.fail("position", "give `xyz` or `position`, not both");
  const char* key = t.has("position") ? "position" : "xyz";
  if (planar) {
    const std::vector<double> p = t.has(key) ? length_values(t, key, t.numbers(key, 2)) : std::vector<double>{0.0, 0.0};
    return trans(p[0], p[1], 0.0) * rot_z(t.number("angle", 0.0));
  }
  const std::vector<double> p =
      t.has(key) ? length_values(t, key, t.numbers(key, 3)) : std::vector<double>{0.0, 0.0, 0.0};
  const std::vector<double> rpy = t.has("rpy") ? t.numbers("rpy", 3) : std::vector<double>{0.0, 0.0, 0.0};
  return trans(p[0], p[1], p[2]) * Isometry3d(rpy_matrix({rpy[0], rpy[1], rpy[2]}));
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

// A joint's `velocity_limit` table into jt, checked over the joint's range (jt.lower, jt.upper set before).
void read_velocity_law(const TableReader& r, JointSpec& jt) {
  const TableReader law_table = r.table("velocity_limit");
  const TableReader law_reader(law_table.file_ptr(), law_table.raw(), "joint '" + jt.name + "' velocity_limit");
  jt.velocity_limit = make_velocity_limit(law_reader);
  jt.velocity_limit_source = r.location("velocity_limit").str();
  law_reader.finish();
  if (auto bad = check_velocity_law(*jt.velocity_limit, jt.lower, jt.upper)) {
    law_reader.fail("velocity-limit law '" + jt.velocity_limit->type() + "' is invalid at theta = " + num(bad->theta) +
                    (jt.type == JointType::kRevolute ? " rad" : " m") + " (joint range [" + num(jt.lower) + ", " +
                    num(jt.upper) + "]): " + bad->reason);
  }
}

// The entries of the array of tables `key` (absent: none), by their `name`: each must name a `noun` that `known`
// accepts and appear once. An unknown name reads "no <what> named '<name>'<where>".
std::map<std::string, TableReader> named_entries(const TableReader& r, const char* key,
                                                 const std::function<bool(const std::string&)>& known,
                                                 const std::string& noun, const std::string& what,
                                                 const std::string& where) {
  std::map<std::string, TableReader> out;
  if (!r.has(key)) return out;
  for (const TableReader& entry : r.tables(key)) {
    const std::string name = entry.string("name");
    if (!known(name)) entry.fail("name", "no " + what + " named '" + name + "'" + where);
    if (!out.emplace(name, entry).second) entry.fail("name", "a second entry for " + noun + " '" + name + "'");
  }
  return out;
}

JointSpec load_joint(const TableReader& entry, ChainKind kind, DhConvention convention, std::set<std::string>& names) {
  JointSpec jt;
  jt.name = entry.string("name");
  if (jt.name.empty()) entry.fail("name", "expected a non-empty joint name");
  const TableReader r(entry.file_ptr(), entry.raw(), "joint '" + jt.name + "'");
  (void)r.has("name");
  if (!names.insert(jt.name).second) r.fail("name", "duplicate joint name '" + jt.name + "'");

  const std::string type = kind == ChainKind::kPlanar ? r.choice("type", {"revolute"}, "revolute")
                                                      : r.choice("type", {"revolute", "prismatic"}, "revolute");
  jt.type = type == "revolute" ? JointType::kRevolute : JointType::kPrismatic;

  if (kind == ChainKind::kPlanar) {
    jt.length = r.number("length");
    if (!(jt.length > 0.0)) r.fail("length", "expected a link length > 0 m, got " + num(jt.length));
    length_value(r, "length", jt.length);
  } else if (convention == DhConvention::kJointFrames) {
    if (auto origin = r.optional_table("origin")) {
      const TableReader o(origin->file_ptr(), origin->raw(), "joint '" + jt.name + "' origin");
      jt.origin = read_pose(o, false);
      o.finish();
    }
    if (r.has("axis")) {
      const std::vector<double> a = r.numbers("axis", 3);
      jt.axis = Vector3d(a[0], a[1], a[2]);
      if (!(jt.axis.norm() > 1e-9)) r.fail("axis", "expected a non-zero axis vector [x, y, z]");
      jt.axis.normalize();
    }
  } else {
    jt.a = length_value(r, "a", r.number("a", 0.0));
    jt.alpha = r.number("alpha", 0.0);
    jt.d = length_value(r, "d", r.number("d", 0.0));
    jt.theta_offset = r.number("theta_offset", 0.0);
  }

  read_limits(r, jt);

  if (r.has("collision")) {
    config_io::read(r, "collision", jt.collision);
    for (std::size_t k = 0; k < jt.collision.size(); ++k) {
      const ShapeSpec& c = jt.collision[k];
      const std::string which = "joint '" + jt.name + "': key 'collision': shape " + std::to_string(k + 1);
      if (c.velocity) throw ConfigError(r.location("collision"), which + " has a velocity; only obstacles move");
      const bool placed = c.xyz != std::array<double, 3>{0, 0, 0} || c.rpy != std::array<double, 3>{0, 0, 0};
      if (c.shape == ShapeSpec::Kind::kCapsule && !c.length && !c.from && placed) {
        throw ConfigError(r.location("collision"), which +
                                                       ": a capsule with `xyz` or `rpy` needs its `length` (or give "
                                                       "`from` and `to`, or none of these to run along the link)");
      }
    }
  }

  read_velocity_law(r, jt);
  r.finish();
  return jt;
}

// A robot file that names a URDF (`urdf`, `base_link`, `tip_link`): the chain comes from the URDF
// (read_urdf_chain); `[[joints]]` entries, by joint name, may replace a joint's `limits` and `velocity_limit`;
// `[[links]]` entries, by link name, give collision shapes that replace (`replace = true`, the default) or add to
// the URDF's. Fills name, kind, convention, joints and end_effector (the tip link's frame).
void load_urdf_chain(const TableReader& r, RobotSpec& spec) {
  const std::filesystem::path file = r.path("urdf");
  const std::string base_link = r.string("base_link"), tip_link = r.string("tip_link");
  UrdfChain chain;
  try {
    chain = read_urdf_chain(file, base_link, tip_link);
  } catch (const UrdfError& e) {
    r.fail("urdf", e.what());
  } catch (const ConfigError& e) {
    if (e.where().line == 0) r.fail("urdf", e.what());  // missing, not a regular file, too large: at the key
    throw;
  }
  spec.name = r.string("name", chain.robot_name);
  if (spec.name.empty()) r.fail("name", "expected a non-empty robot name (the URDF gives none)");
  if (r.has("kind") && r.choice("kind", {"spatial"}) != "spatial") r.fail("kind", "a URDF chain is spatial");
  if (r.has("convention") && r.choice("convention", {"joints"}) != "joints") {
    r.fail("convention", "a URDF chain is made of joint frames");
  }
  spec.kind = ChainKind::kSpatial;
  spec.convention = DhConvention::kJointFrames;
  spec.end_effector = chain.tip;

  // Overrides by joint name.
  const std::map<std::string, TableReader> overrides = named_entries(
      r, "joints",
      [&](const std::string& name) {
        return std::any_of(chain.joints.begin(), chain.joints.end(),
                           [&](const UrdfJoint& j) { return j.name == name; });
      },
      "joint", "moving joint", " between '" + base_link + "' and '" + tip_link + "' in " + file.string());
  for (const UrdfJoint& uj : chain.joints) {
    JointSpec jt;
    jt.name = uj.name;
    jt.type = uj.prismatic ? JointType::kPrismatic : JointType::kRevolute;
    jt.origin = uj.origin;
    jt.axis = uj.axis;
    jt.lower = uj.lower;
    jt.upper = uj.upper;
    const auto o = overrides.find(uj.name);
    const std::optional<TableReader> entry =
        o == overrides.end()
            ? std::nullopt
            : std::optional<TableReader>(TableReader(o->second.file_ptr(), o->second.raw(), "joint '" + uj.name + "'"));
    if (entry) (void)entry->has("name");
    if (entry && entry->has("limits")) {
      read_limits(*entry, jt);
    } else if (uj.continuous) {
      r.fail("urdf", "joint '" + uj.name + "' is continuous in " + file.string() +
                         ", which gives it no position limits: give its `limits` in a [[joints]] entry");
    } else if (!(uj.lower < uj.upper)) {
      r.fail("urdf", "joint '" + uj.name + "' in " + file.string() + " has limits lower " + num(uj.lower) +
                         " >= upper " + num(uj.upper) + ": fix the URDF or give its `limits` in a [[joints]] entry");
    }
    if (entry && entry->has("velocity_limit")) {
      read_velocity_law(*entry, jt);
    } else if (uj.velocity > 0.0) {
      jt.velocity_limit = symmetric_constant_law(uj.velocity, file);
    } else {
      r.fail("urdf", "joint '" + uj.name + "' in " + file.string() +
                         " has no velocity limit: give one in the URDF (<limit velocity=...>) or a `velocity_limit` "
                         "in a [[joints]] entry");
    }
    if (entry) entry->finish();
    spec.joints.push_back(std::move(jt));
  }

  // Collision shapes: the URDF's, per link, unless [[links]] replaces them.
  const std::map<std::string, TableReader> link_entries = named_entries(
      r, "links",
      [&](const std::string& name) {
        return std::any_of(chain.links.begin(), chain.links.end(), [&](const UrdfLink& l) { return l.name == name; });
      },
      "link", "link", " that moves with the chain from '" + base_link + "' to '" + tip_link + "' in " + file.string());
  for (const UrdfLink& link : chain.links) {
    JointSpec& jt = spec.joints[static_cast<std::size_t>(link.joint)];
    const auto e = link_entries.find(link.name);
    bool replace = false;
    if (e != link_entries.end()) {
      const TableReader entry(e->second.file_ptr(), e->second.raw(), "link '" + link.name + "'");
      (void)entry.has("name");
      replace = entry.boolean("replace", true);
      std::vector<ShapeSpec> shapes;
      if (entry.has("collision")) config_io::read(entry, "collision", shapes);
      for (std::size_t k = 0; k < shapes.size(); ++k) {
        if (shapes[k].shape == ShapeSpec::Kind::kCapsule && !shapes[k].length && !shapes[k].from) {
          entry.fail("collision", "shape " + std::to_string(k + 1) +
                                      ": a capsule of a URDF link needs `length` (with `xyz`, `rpy`) or `from` and "
                                      "`to`, in the link's frame");
        }
        if (shapes[k].velocity)
          entry.fail("collision", "shape " + std::to_string(k + 1) + " has a velocity; only obstacles move");
        jt.collision.push_back(shapes[k].placed(link.pose));
      }
      entry.finish();
    }
    if (replace) continue;
    if (!link.meshes.empty()) {
      r.fail("urdf", "link '" + link.name + "' in " + file.string() + " has a mesh collision element ('" +
                         link.meshes.front() +
                         "'), which redres does not read: give the link's shapes in a [[links]] entry (replace = "
                         "true), e.g. capsules");
    }
    for (const ShapeSpec& s : link.shapes) jt.collision.push_back(s.placed(link.pose));
  }
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

RobotModel load_robot(const std::filesystem::path& file) {
  return load_robot(TableReader::root(parse_toml_file(file), "robot"));
}

RobotModel load_robot(const TableReader& r) {
  load_plugins_from(r);  // plugin libraries first: their velocity-limit laws may be named below
  RobotSpec spec;
  spec.source = r.file().path.string();
  const bool from_urdf = r.has("urdf");
  if (from_urdf) {
    load_urdf_chain(r, spec);
  } else {
    spec.name = r.string("name");
    if (spec.name.empty()) r.fail("name", "expected a non-empty robot name");
    spec.kind = r.choice("kind", {"planar", "spatial"}) == "planar" ? ChainKind::kPlanar : ChainKind::kSpatial;
    if (spec.kind == ChainKind::kSpatial) {
      const std::string c = r.choice("convention", {"dh", "modified_dh", "joints"});
      spec.convention = c == "dh"            ? DhConvention::kStandard
                        : c == "modified_dh" ? DhConvention::kModified
                                             : DhConvention::kJointFrames;
    }
  }
  read_task(r, spec);

  if (!from_urdf) {
    std::set<std::string> names;
    for (const TableReader& entry : r.tables("joints")) {
      spec.joints.push_back(load_joint(entry, spec.kind, spec.convention, names));
    }
  }
  const auto n = static_cast<Eigen::Index>(spec.joints.size());

  if (auto ee = r.optional_table("end_effector")) {
    const TableReader e(ee->file_ptr(), ee->raw(), "end_effector");
    // After the URDF's tip link, when there is one (spec.end_effector holds that link's frame).
    spec.end_effector = spec.end_effector * read_pose(e, spec.kind == ChainKind::kPlanar);
    e.finish();
  }
  if (auto base = r.optional_table("base")) {
    const TableReader b(base->file_ptr(), base->raw(), "base");
    spec.base = read_pose(b, spec.kind == ChainKind::kPlanar);
    b.finish();
  }

  if (r.has("home")) {
    const std::vector<double> h = r.numbers("home", static_cast<std::size_t>(n));
    spec.home = Eigen::Map<const Eigen::VectorXd>(h.data(), n);
    for (Eigen::Index j = 0; j < n; ++j) {
      const JointSpec& jt = spec.joints[static_cast<std::size_t>(j)];
      if (h[static_cast<std::size_t>(j)] < jt.lower || h[static_cast<std::size_t>(j)] > jt.upper) {
        r.fail("home", "expected joint '" + jt.name + "' within its limits [" + num(jt.lower) + ", " + num(jt.upper) +
                           "], got " + num(h[static_cast<std::size_t>(j)]));
      }
    }
  }
  if (r.has("collision_exclude")) {
    const toml::array* pairs = r.raw().get("collision_exclude")->as_array();
    if (pairs == nullptr) r.fail("collision_exclude", "expected an array of joint-name pairs, e.g. [[\"j1\", \"j3\"]]");
    for (const toml::node& p : *pairs) {
      const toml::array* pair = p.as_array();
      const auto index = [&](std::size_t k) {
        const toml::node* el = pair != nullptr && pair->size() == 2 ? pair->get(k) : nullptr;
        const auto* name = el != nullptr ? el->as_string() : nullptr;
        if (name != nullptr) {
          for (std::size_t j = 0; j < spec.joints.size(); ++j) {
            if (spec.joints[j].name == name->get()) return static_cast<int>(j);
          }
        }
        throw ConfigError(location_of(r.file(), p),
                          "key 'collision_exclude': expected pairs of two joint names of "
                          "this robot, e.g. [\"j1\", \"j3\"]");
      };
      const int a = index(0), b = index(1);
      if (a == b) throw ConfigError(location_of(r.file(), p), "key 'collision_exclude': a pair names one joint twice");
      spec.collision_exclude.emplace_back(a, b);
    }
  }
  r.finish();
  return RobotModel(std::move(spec));
}

}  // namespace redres

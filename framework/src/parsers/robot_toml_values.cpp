#include "parsers/robot_toml_values.hpp"

#include <cmath>

#include "common/text.hpp"
#include "model/transforms.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"

namespace redres {

using Eigen::Isometry3d;

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

Isometry3d PoseTable::pose() const {
  const std::vector<double> p = !xyz.empty() ? xyz : std::vector<double>(planar ? 2 : 3, 0.0);
  if (planar) return trans(p[0], p[1], 0.0) * rot_z(angle);
  return trans(p[0], p[1], p[2]) * Isometry3d(rpy_matrix({rpy[0], rpy[1], rpy[2]}));
}

const Schema<PoseTable>& PoseTable::schema() {
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

Isometry3d read_pose(const TableReader& r, const char* key, const std::string& context, bool planar) {
  const TableReader t = r.table(key);
  const TableReader pose_reader(t.file_ptr(), t.raw(), context);
  PoseTable pose;
  pose.planar = planar;
  read_config(pose_reader, PoseTable::schema(), pose);
  pose_reader.finish();
  return pose.pose();
}

void read_limits(const TableReader& r, JointSpec& jt) {
  const std::vector<double> lim = r.numbers("limits", 2);
  jt.lower = lim[0];
  jt.upper = lim[1];
  if (!(jt.lower < jt.upper)) {
    r.fail("limits",
           "expected [lower, upper] with lower < upper, got lower " + num(jt.lower) + " >= upper " + num(jt.upper));
  }
}

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

void read_drive(const TableReader& r, const char* key, const char* unit, std::optional<double>& into) {
  const double v = r.number(key);
  if (!(std::isfinite(v) && v >= 0.0 && v <= 1e6)) {
    r.fail(key, std::string("expected 0 <= ") + key + " <= 1e6 (" + unit + "), got " + num(v));
  }
  into = v;
}

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

void read_inertia(const TableReader& r, JointSpec& jt) {
  jt.inertia = read_inertia_table(r, "joint '" + jt.name + "'");
  jt.inertia_source = r.location("inertia").str();
}

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

std::map<std::string, TableReader> named_entries(const TableReader& r, const char* key,
                                                 const std::function<bool(const std::string&)>& known,
                                                 const std::string& noun, const std::string& what,
                                                 const std::string& where, std::vector<ConfigError>* problems) {
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

}  // namespace redres

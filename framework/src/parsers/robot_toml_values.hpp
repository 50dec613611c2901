#pragma once
// The values a robot file reads alike in several of its tables (its top level, the [[joints]] of a chain given joint
// by joint, the overrides of a URDF's joints and links): lengths within their physical range, poses, a joint's range,
// limit laws, drive and inertia, and arrays of tables found by name.

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "redres/config/config.hpp"
#include "redres/model/robot.hpp"

namespace redres {

// A length, offset or position in metres, within the physical range of config.hpp's physical_bound("m").
double length_value(const TableReader& r, const char* key, double value);
std::vector<double> length_values(const TableReader& r, const char* key, std::vector<double> values);

// A pose table ([base], [end_effector], a joint's `origin`): spatial `xyz` (m) and `rpy` (rad, roll-pitch-yaw
// about the fixed x, y, z axes); planar `xyz` ([x, y], m) and `angle` (rad, about z). `position` is accepted for
// `xyz` (the end effector's older key).
struct PoseTable {
  bool planar = false;  // set before the table is read
  std::vector<double> xyz;
  std::vector<double> rpy{0.0, 0.0, 0.0};
  double angle = 0.0;
  [[nodiscard]] Eigen::Isometry3d pose() const;
  static const Schema<PoseTable>& schema();
};

// The pose table at `key` of `r`, named `context` in messages.
Eigen::Isometry3d read_pose(const TableReader& r, const char* key, const std::string& context, bool planar);

// A joint's `limits` = [lower, upper], lower < upper, into jt.
void read_limits(const TableReader& r, JointSpec& jt);

// A joint's limit-law table `key` (velocity_limit, acceleration_limit, jerk_limit) into `law` and `source`, checked
// over the joint's range (jt.lower, jt.upper set before). The three are laws of the same kinds (redres plugins).
void read_law(const TableReader& r, const char* key, const char* what, const char* unit, JointSpec& jt,
              std::shared_ptr<const VelocityLimitLaw>& law, std::string& source);

void read_velocity_law(const TableReader& r, JointSpec& jt);

void read_effort(const TableReader& r, JointSpec& jt);

// `damping` or `armature` (docs/plant.md): a number >= 0.
void read_drive(const TableReader& r, const char* key, const char* unit, std::optional<double>& into);

// An `inertia` table (of a joint: the link it moves; of a [[links]] entry: that URDF link), in the link's frame.
// `who` names it in messages ("joint 'j1'", "link 'head'").
Inertia read_inertia_table(const TableReader& r, const std::string& who);

// A joint's `inertia` table: the mass properties of the link it moves, in that link's frame.
void read_inertia(const TableReader& r, JointSpec& jt);

// The optional motion limits of a joint beyond its velocity: acceleration and jerk laws, and the effort limit (a
// URDF joint's [[joints]] override; a [[joints]] entry of a TOML chain reads them key by key).
void read_motion_limits(const TableReader& r, JointSpec& jt);

// The entries of the array of tables `key` (absent: none), by their `name`: each must name a `noun` that `known`
// accepts and appear once. An unknown name reads "no <what> named '<name>'<where>".
std::map<std::string, TableReader> named_entries(const TableReader& r, const char* key,
                                                 const std::function<bool(const std::string&)>& known,
                                                 const std::string& noun, const std::string& what,
                                                 const std::string& where,
                                                 std::vector<ConfigError>* problems = nullptr);

}  // namespace redres

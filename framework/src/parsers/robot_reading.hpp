#pragma once
// What reading a robot file's top level gathers (robot_toml.cpp reads it through RobotReading's schema; the overrides
// of a URDF chain, urdf_overlay.cpp, read into it too).

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "parsers/urdf.hpp"
#include "redres/config/config.hpp"
#include "redres/model/mesh.hpp"
#include "redres/model/robot.hpp"

namespace redres {

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

}  // namespace redres

#pragma once
// A URDF chain's joints and links as a robot file amends them: its [[joints]] entries override a joint's range and
// limits by name, its [[links]] entries give a link's collision shapes, collision model and inertia by name.

#include <optional>
#include <string>
#include <vector>

#include "parsers/robot_reading.hpp"
#include "redres/config/config.hpp"
#include "redres/model/collision.hpp"
#include "redres/model/robot.hpp"

namespace redres {

// A [[links]] entry of a URDF robot: collision shapes for one of the chain's links.
struct LinkEntry {
  std::string name;
  bool replace = true;
  std::vector<ShapeSpec> collision;
  std::string collision_model;  // empty: the robot's
  std::optional<Inertia> inertia;
  static const Schema<LinkEntry>& schema();
};

// The URDF's joints, with the [[joints]] overrides, into c.spec.joints. Every joint's problems are gathered in
// c.problems.
void read_urdf_joints(const TableReader& r, RobotReading& c);

// The collision shapes, frames, inertias and visuals of the URDF's links, with the [[links]] entries, into c.spec;
// then throws every problem gathered (the joints' too).
void read_urdf_links(const TableReader& r, RobotReading& c);

}  // namespace redres

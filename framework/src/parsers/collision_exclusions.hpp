#pragma once
// A robot file's `collision_exclude`: the pairs of links that self-collision leaves out, by joint or link name.

#include "redres/config/config.hpp"
#include "redres/model/robot.hpp"

namespace redres {

// `collision_exclude`: pairs of joints (all their links) or of links by name (a URDF's links, side branches
// included) that self-collision does not check, into spec.collision_exclude (two joints) and
// spec.collision_exclude_bodies (by name). The joints and their shapes are read before.
void read_collision_exclude(const TableReader& r, RobotSpec& spec);

}  // namespace redres

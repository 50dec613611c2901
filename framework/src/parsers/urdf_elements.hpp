#pragma once
// A URDF link's elements as urdfdom gives them, checked and turned into the chain's terms: origins as transforms,
// <collision> elements as shapes and meshes, <visual> elements, <inertial> elements, and names. Private to the URDF
// reader; urdfdom's types are only named here (urdf_elements.cpp and urdf.cpp include urdfdom).

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "parsers/urdf.hpp"
#include "parsers/urdf_outline.hpp"

namespace urdf {
class Link;
class Pose;
}  // namespace urdf

namespace redres {

Eigen::Isometry3d pose_of(const urdf::Pose& p);

// A length of the URDF (an origin's coordinate, a radius, a side) within the robot file's physical range.
void check_length(const std::string& who, const char* what, double value, bool positive);

void check_pose(const std::string& who, const char* what, const urdf::Pose& p);

// The collision elements of `link`, whose frame is `at` in the frame of the ChainLink `out` gathers shapes for.
void add_shapes(const Namer& names, const urdf::Link& link, const Eigen::Isometry3d& at, const std::string& messages,
                ChainLink& out);

// The visual elements of `link`, whose frame is `at` in the frame they are gathered in. Checked as the collision
// elements are (a bad one is an error: the file is wrong), but a viewer alone uses them.
void add_visuals(const Namer& names, const urdf::Link& link, const Eigen::Isometry3d& at,
                 std::vector<ChainVisual>& out);

// A name of the file (`who` names its element): UTF-8 without control characters, else UrdfError.
void check_name(const std::string& who, const std::string& name);

}  // namespace redres

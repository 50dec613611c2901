#pragma once
// A robot's chain as a robot format describes it, in no format's types: what each format's reader fills (a URDF's,
// urdf.cpp; a robot file's own [[joints]], toml_chain.cpp; an MJCF reader would be one more file filling it), and
// what build_chain() (chain_build.hpp) alone turns into the model's joints, collision shapes, frames, inertias and
// visuals. Private to parsers/.

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "redres/model/collision.hpp"
#include "redres/model/robot.hpp"

namespace redres {

/// One moving joint of the chain: the model's joint as far as the format gives it, and what the format leaves open.
struct ChainJoint {
  /// Its name, type, frame (joint frames: origin and axis; a robot file's chain: DH parameters or a planar length
  /// too), its range, and the limits, drive, inertia and collision shapes the format gives.
  JointSpec spec;
  std::string where;        //!< "file:line: joint 'name'", for messages (empty: the robot file's own joint)
  bool continuous = false;  //!< the format gives it no position range (a continuous joint): the robot file must
  /// A velocity limit the format gives as one number (rad/s or m/s; 0: none), made a symmetric `constant` law unless
  /// the robot file gives a law (spec.velocity_limit, when the format gives a law, is kept as it is).
  double velocity = 0.0;
};

/// A mesh collision element: the file as the format names it, its scale, and its pose in the joint's link frame.
struct ChainMesh {
  std::string filename;                                    //!< as written (package://..., file://..., or a path)
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();         //!< the mesh's scale
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  //!< the mesh's frame in the link's frame
};

/// A visual element (what a viewer draws; nothing is computed from it): a mesh as the format names it, or a box,
/// cylinder or sphere, its pose in the frame of the link (or the base) it rides on, and its material's colour.
struct ChainVisual {
  enum class Kind { kMesh, kBox, kCylinder, kSphere };
  Kind kind = Kind::kMesh;
  std::string filename;                                    //!< a mesh: as written (package://..., file://, a path)
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();         //!< a mesh's scale
  std::array<double, 3> size{0.0, 0.0, 0.0};               //!< a box's sides (m)
  double radius = 0.0, length = 0.0;                       //!< a cylinder's or sphere's (m)
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  //!< in the frame its shapes are placed in
  std::optional<std::array<double, 4>> rgba;               //!< the material's colour, when it has one
  std::string link;                                        //!< the link it belongs to
};

/// A link that moves with a joint of the chain: a link of the chain itself (after the joint, and those fixed to it), or
/// a link of a side branch hanging from one (a hand, a head, a finger), its branch's joints held. Its shapes are
/// placed in that joint's link frame.
struct ChainLink {
  std::string name;   //!< the link's name
  std::string where;  //!< "file:line: link 'name'", for messages
  /// On a side branch, below a joint that could move (held at a value): a body of its own, which self-collision
  /// checks against the chain's links next to its joint's. False for the chain's links and for links fixed to them.
  bool branch = false;
  int joint = 0;                                           //!< index of the moving joint it rides on (0-based)
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  //!< the link's frame in that joint's link frame
  std::vector<ShapeSpec> shapes;                           //!< its sphere, box and cylinder collision elements
  std::vector<ChainMesh> meshes;                           //!< its mesh collision elements
  std::vector<ChainVisual> visuals;                        //!< its visual elements, in the link's frame
  std::optional<Inertia> inertia;     //!< its mass properties and those riding on it, in the link's frame; none if none
  std::vector<std::string> warnings;  //!< what is wrong with them (kept as given)
};

/// A joint of a side branch that could move (revolute, continuous, prismatic), held at a value: the value the robot
/// file gives (`held_joints`), else 0 (or the limit nearest 0 when 0 is outside its limits); a mimic joint follows
/// its leader (multiplier * leader + offset). A mimic joint of the chain whose leader is not on the chain is held too.
struct HeldJoint {
  std::string name;                 //!< the joint's name
  std::string where;                //!< "file:line: joint 'name'"
  double value = 0.0;               //!< the position it is held at (rad or m)
  bool limited = false;             //!< it has position limits (not continuous)
  double lower = 0.0, upper = 0.0;  //!< its limits, when limited
  std::string mimics;               //!< the leader's name, for a mimic joint (empty: not a mimic)
};

/// The chain from a base link to a tip link, as one file describes it.
struct ChainDescription {
  std::string robot_name;          //!< the robot's name as the file gives it (empty: none)
  std::filesystem::path file;      //!< the file it was read from: its meshes are found beside it; messages name it
  std::vector<ChainJoint> joints;  //!< the moving joints, base to tip
  std::vector<ChainLink> links;    //!< the links after the first moving joint, base to tip
  Eigen::Isometry3d tip = Eigen::Isometry3d::Identity();  //!< the tip link's frame in the last joint's link frame
  std::vector<HeldJoint> held;                            //!< the held joints met (side branches, off-chain mimics)
  std::vector<std::string> all_links;                     //!< every link of the file, in file order (for messages)
  /// The visual elements of the links that do not move (the base link and those fixed to it before the first moving
  /// joint), in the base link's frame.
  std::vector<ChainVisual> base_visuals;
};

}  // namespace redres

#pragma once
/// @file
/// Reading a serial chain out of a URDF file (urdfdom, Debian's liburdfdom-dev), for robot files that name one
/// (`urdf = "..."`, docs/robot_format.md). Only the chain between two links is read: its moving joints become joint
/// frames (origin and axis, robot.hpp), fixed joints are folded into the next origin (or into the tip transform
/// after the last moving joint), and the collision elements of the links the chain moves become collision shapes.
/// urdfdom is included only by urdf.cpp and urdf_elements.cpp.

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "redres/model/collision.hpp"
#include "redres/model/robot.hpp"

namespace redres {

/// The bounds a URDF file is read within (checked before and after urdfdom parses it; the message names the bound).
inline constexpr std::size_t kMaxUrdfDepth = 64;          //!< XML elements nested in each other
inline constexpr std::size_t kMaxUrdfElements = 500'000;  //!< XML elements in the file
inline constexpr std::size_t kMaxUrdfLinks = 10'000;      //!< links, and joints, in the file

/// A problem with a URDF file: the message names the file and the element.
class UrdfError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One moving joint of the chain, as the URDF gives it.
struct UrdfJoint {
  std::string name;                                          //!< the joint's name
  std::string where;                                         //!< "file:line: joint 'name'", for messages
  bool prismatic = false;                                    //!< else revolute or continuous
  bool continuous = false;                                   //!< a continuous joint has no position limits
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  //!< from the previous moving joint's link frame
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();           //!< in the joint's frame (normalised)
  double lower = 0.0, upper = 0.0;                           //!< position limits (rad or m); unset if continuous
  double velocity = 0.0;                                     //!< velocity limit (rad/s or m/s); 0 if not given
  double effort = 0.0;                                       //!< effort limit (N m or N); 0 if not given
  double damping = -1.0;                                     //!< <dynamics damping>; < 0 if not given
};

/// A mesh collision element: the file as the URDF names it, its scale, and its pose in the joint's link frame.
struct UrdfMesh {
  std::string filename;                                    //!< as written (package://..., file://..., or a path)
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();         //!< the <mesh scale="...">
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  //!< the mesh's frame in the link's frame
};

/// A visual element (what a viewer draws; nothing is computed from it): a mesh as the URDF names it, or a box,
/// cylinder or sphere, its pose in the frame of the link (or the base) it rides on, and its material's colour.
struct UrdfVisual {
  enum class Kind { kMesh, kBox, kCylinder, kSphere };
  Kind kind = Kind::kMesh;
  std::string filename;                                    //!< a mesh: as written (package://..., file://, a path)
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();         //!< a mesh's <mesh scale="...">
  std::array<double, 3> size{0.0, 0.0, 0.0};               //!< a box's sides (m)
  double radius = 0.0, length = 0.0;                       //!< a cylinder's or sphere's (m)
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  //!< in the frame its shapes are placed in
  std::optional<std::array<double, 4>> rgba;               //!< the <material> colour, when it has one
  std::string link;                                        //!< the URDF link it belongs to
};

/// A link that moves with a joint of the chain: a link of the chain itself (after the joint, and those fixed to it), or
/// a link of a side branch hanging from one (a hand, a head, a finger), its branch's joints held. Its shapes are
/// placed in that joint's link frame.
struct UrdfLink {
  std::string name;   //!< the link's name
  std::string where;  //!< "file:line: link 'name'", for messages
  /// On a side branch, below a joint that could move (held at a value): a body of its own, which self-collision
  /// checks against the chain's links next to its joint's. False for the chain's links and for links fixed to them.
  bool branch = false;
  int joint = 0;                                           //!< index of the moving joint it rides on (0-based)
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  //!< the link's frame in that joint's link frame
  std::vector<ShapeSpec> shapes;                           //!< its sphere, box and cylinder collision elements
  std::vector<UrdfMesh> meshes;                            //!< its mesh collision elements
  std::vector<UrdfVisual> visuals;                         //!< its visual elements, in the link's frame
  std::optional<Inertia> inertia;     //!< its <inertial> and those riding on it, in the link's frame; none if none
  std::vector<std::string> warnings;  //!< what is wrong with them (kept as given)
};

/// The root link of a URDF and the link below it with the most revolute joints above it (then the fewest prismatic or
/// mimic joints, a gripper's, then the most links): the
/// chain `redres robot FILE.urdf` shows when no --base-link or --tip-link is given. Throws UrdfError as
/// read_urdf_chain() does.
[[nodiscard]] std::pair<std::string, std::string> default_urdf_chain(const std::filesystem::path& file);

/// A joint of a side branch that could move (revolute, continuous, prismatic), held at a value: the value the robot
/// file gives (`held_joints`), else 0 (or the limit nearest 0 when 0 is outside its limits); a mimic joint follows
/// its leader (multiplier * leader + offset). A mimic joint of the chain whose leader is not on the chain is held too.
struct UrdfHeldJoint {
  std::string name;                 //!< the joint's name
  std::string where;                //!< "file:line: joint 'name'"
  double value = 0.0;               //!< the position it is held at (rad or m)
  bool limited = false;             //!< it has position limits (not continuous)
  double lower = 0.0, upper = 0.0;  //!< its limits, when limited
  std::string mimics;               //!< the leader's name, for a mimic joint (empty: not a mimic)
};

/// The chain from `base_link` to `tip_link`.
struct UrdfChain {
  std::string robot_name;                                 //!< the URDF's robot name
  std::vector<UrdfJoint> joints;                          //!< the moving joints, base to tip
  std::vector<UrdfLink> links;                            //!< the links after the first moving joint, base to tip
  Eigen::Isometry3d tip = Eigen::Isometry3d::Identity();  //!< tip_link's frame in the last joint's link frame
  std::vector<UrdfHeldJoint> held;                        //!< the held joints met (side branches, off-chain mimics)
  std::vector<std::string> all_links;                     //!< every link of the URDF, in file order (for messages)
  /// The visual elements of the links that do not move (the base link and those fixed to it before the first moving
  /// joint), in the base link's frame.
  std::vector<UrdfVisual> base_visuals;
};

/// Reads the chain. Throws UrdfError naming the file and the element for: a missing or unparsable file (with
/// urdfdom's own messages), XML nested deeper or with more elements than the bounds above, joints that do not form
/// a tree (a cycle, a link that is its own parent, a link with two parents), more links or joints than
/// kMaxUrdfLinks or more moving joints than kMaxJoints, a name that is not UTF-8 or holds control characters, a
/// length, position limit or velocity outside the robot file's physical range, a missing link, a tip that is not
/// below the base, a floating or planar joint in the chain, a mimic joint whose leader is on the chain (coupled joints
/// are not supported), and a chain without moving joints. Messages give the element's line where the file has it.
/// `held` gives the positions of side-branch joints by name (others: 0, see UrdfHeldJoint); names it gives that the
/// file has no held joint for are not an error here (the caller reports them, with UrdfChain::held).
[[nodiscard]] UrdfChain read_urdf_chain(const std::filesystem::path& file, const std::string& base_link,
                                        const std::string& tip_link, const std::map<std::string, double>& held = {});

}  // namespace redres

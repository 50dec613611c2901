#pragma once
/// @file
/// Reading a serial chain out of a URDF file (urdfdom, Debian's liburdfdom-dev), for robot files that name one
/// (`urdf = "..."`, docs/robot_format.md), as a ChainDescription. Only the chain between two links is read: its moving
/// joints become joint frames (origin and axis, robot.hpp), fixed joints are folded into the next origin (or into the
/// tip transform after the last moving joint), and the elements of the links the chain moves ride on their joints.
/// urdfdom is included only by urdf.cpp and urdf_elements.cpp.

#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "parsers/chain_description.hpp"

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

/// The root link of a URDF and the link below it with the most revolute joints above it (then the fewest prismatic or
/// mimic joints, a gripper's, then the most links): the
/// chain `redres robot FILE.urdf` shows when no --base-link or --tip-link is given. Throws UrdfError as
/// read_urdf_chain() does.
[[nodiscard]] std::pair<std::string, std::string> default_urdf_chain(const std::filesystem::path& file);

/// Reads the chain from `base_link` to `tip_link` as a ChainDescription (file = `file`): its joints' frames, ranges,
/// velocity, effort and damping; its links' shapes, meshes, visuals and inertias; the held joints. Throws UrdfError
/// naming the file and the element for: a missing or unparsable file (with urdfdom's own messages), XML nested deeper
/// or with more elements than the bounds above, joints that do not form a tree (a cycle, a link that is its own parent,
/// a link with two parents), more links or joints than kMaxUrdfLinks or more moving joints than kMaxJoints, a name that
/// is not UTF-8 or holds control characters, a length, position limit or velocity outside the robot file's physical
/// range, a missing link, a tip that is not below the base, a floating or planar joint in the chain, a mimic joint
/// whose leader is on the chain (coupled joints are not supported), and a chain without moving joints. Messages give
/// the element's line where the file has it. `held` gives the positions of side-branch joints by name (others: 0, see
/// HeldJoint); names it gives that the file has no held joint for are not an error here (the caller reports them, with
/// ChainDescription::held).
[[nodiscard]] ChainDescription read_urdf_chain(const std::filesystem::path& file, const std::string& base_link,
                                               const std::string& tip_link,
                                               const std::map<std::string, double>& held = {});

}  // namespace redres

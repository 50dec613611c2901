#pragma once
// The one way a described chain (ChainDescription, whichever format's reader filled it) becomes the model's: its
// joints, the shapes, frames, inertias and visuals of its links, its tip and held joints, in a RobotSpec, with what
// the robot file gives in place of the format's (ChainAmendments). A new robot format is a reader filling a
// ChainDescription; this file does not change for it.

#include <optional>
#include <string>
#include <vector>

#include "parsers/chain_description.hpp"
#include "redres/common/error.hpp"
#include "redres/model/collision.hpp"
#include "redres/model/robot.hpp"
#include "redres/parsers/mesh_file.hpp"

namespace redres {

/// What the robot file gives for one link of the chain (a [[links]] entry), read just before the link is built.
struct LinkAmendment {
  bool replace = false;            //!< `shapes` replace the format's shapes and meshes (false: they are added)
  std::string collision_model;     //!< what the link's meshes become: "capsule", "hull" or "none" (empty: the robot's)
  std::optional<Inertia> inertia;  //!< the link's mass properties in the link's frame, replacing the format's
  std::vector<ShapeSpec> shapes;   //!< collision shapes in the link's frame
};

/// What the robot file says about a chain's joints and links, asked for in chain order while build_chain() builds
/// them (urdf_overlay.hpp: a robot file's [[joints]] and [[links]] entries). The defaults say nothing: the chain as its
/// format gives it.
class ChainAmendments {
 public:
  virtual ~ChainAmendments() = default;
  /// Before the first joint.
  virtual void begin_joints(const ChainDescription& /*chain*/) {}
  /// Joint by joint: first begin_joint(); then range(), which gives the joint's range into `jt` (true) or leaves the
  /// format's (false); velocity_limit() likewise for its velocity-limit law; end_joint() gives the rest (acceleration
  /// and jerk laws, effort, drive, inertia).
  virtual void begin_joint(const ChainJoint& /*joint*/) {}
  virtual bool range(const ChainJoint& /*joint*/, JointSpec& /*jt*/) { return false; }
  virtual bool velocity_limit(const ChainJoint& /*joint*/, JointSpec& /*jt*/) { return false; }
  virtual void end_joint(const ChainJoint& /*joint*/, JointSpec& /*jt*/) {}
  /// Before the first link (after every joint).
  virtual void begin_links(const ChainDescription& /*chain*/) {}
  /// Link by link, into `amendment` (which starts as LinkAmendment{}).
  virtual void link(const ChainLink& /*link*/, LinkAmendment& /*amendment*/) {}
  /// A problem of the chain itself (a joint without a range or a velocity limit, meshes that cannot be used): throws
  /// the ConfigError the robot file reports it as.
  [[noreturn]] virtual void fail(const std::string& message) const = 0;
};

/// The robot-wide choices a chain is built with.
struct ChainOptions {
  std::string collision_model = "capsule";  //!< what a link's mesh collision elements become (LinkAmendment)
  PackagePaths packages;                    //!< where package://NAME/ is, for the meshes
};

/// Builds `chain` into spec.joints (in chain order), spec.visuals, spec.end_effector (the chain's tip) and
/// spec.held_joints. Each joint's problems and each link's are gathered in `problems`, which are thrown together at
/// the end (one ConfigError at the first one's place; "N problems in this robot file:"), with those already there.
void build_chain(const ChainDescription& chain, const ChainOptions& options, ChainAmendments& amend, RobotSpec& spec,
                 std::vector<ConfigError>& problems);

}  // namespace redres

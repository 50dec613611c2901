#pragma once
// A URDF chain as a robot file amends it: its [[joints]] entries override a joint's range and limits by name, its
// [[links]] entries give a link's collision shapes, collision model and inertia by name (ChainAmendments, asked by
// build_chain()). Nothing here depends on the chain coming from a URDF but the messages' words.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "parsers/chain_build.hpp"
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

// The [[joints]] and [[links]] entries of the robot file `r` whose chain runs from `base_link` to `tip_link` (for
// messages). An entry naming no joint or link of the chain, and every problem of an entry, is kept in `problems`
// (reported together by build_chain()); a problem of the chain itself fails at the key `urdf`.
class UrdfOverlay final : public ChainAmendments {
 public:
  UrdfOverlay(const TableReader& r, std::string base_link, std::string tip_link, std::vector<ConfigError>& problems)
      : r_(r), base_link_(std::move(base_link)), tip_link_(std::move(tip_link)), problems_(problems) {}
  void begin_joints(const ChainDescription& chain) override;
  void begin_joint(const ChainJoint& joint) override;
  bool range(const ChainJoint& joint, JointSpec& jt) override;
  bool velocity_limit(const ChainJoint& joint, JointSpec& jt) override;
  void end_joint(const ChainJoint& joint, JointSpec& jt) override;
  void begin_links(const ChainDescription& chain) override;
  void link(const ChainLink& link, LinkAmendment& amendment) override;
  [[noreturn]] void fail(const std::string& message) const override;

 private:
  const TableReader& r_;
  std::string base_link_, tip_link_;
  std::vector<ConfigError>& problems_;
  std::map<std::string, TableReader> joint_entries_, link_entries_;
  std::optional<TableReader> joint_entry_;  // the entry of the joint being built
};

}  // namespace redres

#pragma once
// A robot file's chain given joint by joint: its [[joints]] entries, each read through JointReading's schema, as a
// ChainDescription (its joints only: a joint's `collision` holds its link's shapes).

#include <set>
#include <string>

#include "parsers/chain_description.hpp"
#include "redres/config/config.hpp"
#include "redres/model/robot.hpp"

namespace redres {

// A [[joints]] entry of a chain given joint by joint, read key by key in this order (the range comes before the
// velocity-limit law, which is checked over it). The URDF's [[joints]] entries are overrides: `name`, `limits` and
// `velocity_limit` only (load_urdf_chain).
struct JointReading {
  ChainKind kind = ChainKind::kPlanar;
  DhConvention convention = DhConvention::kStandard;
  JointSpec jt;
  static const Schema<JointReading>& schema();
};

// The [[joints]] entry `entry` of a chain of `kind` and `convention`: its name (unique among `names`, which it joins)
// first, then its keys in JointReading's order.
JointSpec load_joint(const TableReader& entry, ChainKind kind, DhConvention convention, std::set<std::string>& names);

// The [[joints]] entries of the robot file `r` (at least one, at most kMaxJoints, names unique), base to tip, in a
// chain of `kind` and `convention`; file = the robot file.
ChainDescription read_toml_chain(const TableReader& r, ChainKind kind, DhConvention convention);

}  // namespace redres

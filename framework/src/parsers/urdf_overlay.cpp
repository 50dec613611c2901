#include "parsers/urdf_overlay.hpp"

#include <algorithm>
#include <utility>

#include "parsers/robot_toml_values.hpp"

namespace redres {

const Schema<LinkEntry>& LinkEntry::schema() {
  using C = LinkEntry;
  static const Schema<C> s{{
      field("name", &C::name, "", "the URDF link's name").required(),
      field("replace", &C::replace, "", "the shapes replace the URDF's collision elements (false: add to them)"),
      field("collision", &C::collision, "", "the link's shapes, in the link's frame (capsules need `length`)")
          .listed_default("[] (none)"),
      field("collision_model", &C::collision_model, "",
            "what this link's mesh collision elements become: \"capsule\", \"hull\" or \"none\" (default: the "
            "robot's)",
            rule<std::string>("\"capsule\", \"hull\" or \"none\"",
                              [](const std::string& v) { return v == "capsule" || v == "hull" || v == "none"; }))
          .listed_default("the robot's `collision_model`"),
      entry<C>("inertia", "table {mass, com, ixx, iyy, izz, ixy, ixz, iyz}", "kg, m, kg m^2", "the URDF's <inertial>",
               "the link's mass properties, in the link's frame, replacing the URDF's (as a [[joints]] entry's "
               "`inertia`)",
               [](const TableReader& r, C& c) {
                 if (r.has("inertia")) c.inertia = read_inertia_table(r, "link '" + c.name + "'");
               }),
  }};
  return s;
}

void UrdfOverlay::begin_joints(const ChainDescription& chain) {
  joint_entries_ = named_entries(
      r_, "joints",
      [&](const std::string& name) {
        return std::any_of(chain.joints.begin(), chain.joints.end(),
                           [&](const ChainJoint& j) { return j.spec.name == name; });
      },
      "joint", "moving joint", " between '" + base_link_ + "' and '" + tip_link_ + "' in " + chain.file.string(),
      &problems_);
}

void UrdfOverlay::begin_joint(const ChainJoint& joint) {
  const std::string& name = joint.spec.name;
  const auto o = joint_entries_.find(name);
  joint_entry_ =
      o == joint_entries_.end()
          ? std::nullopt
          : std::optional<TableReader>(TableReader(o->second.file_ptr(), o->second.raw(), "joint '" + name + "'"));
  if (joint_entry_) (void)joint_entry_->has("name");
}

bool UrdfOverlay::range(const ChainJoint& /*joint*/, JointSpec& jt) {
  if (!joint_entry_ || !joint_entry_->has("limits")) return false;
  read_limits(*joint_entry_, jt);
  return true;
}

bool UrdfOverlay::velocity_limit(const ChainJoint& /*joint*/, JointSpec& jt) {
  if (!joint_entry_ || !joint_entry_->has("velocity_limit")) return false;
  read_velocity_law(*joint_entry_, jt);
  return true;
}

void UrdfOverlay::end_joint(const ChainJoint& /*joint*/, JointSpec& jt) {
  if (joint_entry_) read_motion_limits(*joint_entry_, jt);
  if (joint_entry_) joint_entry_->finish();
}

void UrdfOverlay::begin_links(const ChainDescription& chain) {
  std::string moving;  // the links that move with the chain, for the message naming a missing one
  for (const ChainLink& l : chain.links) moving += (moving.empty() ? "'" : ", '") + l.name + "'";
  std::string all_links;
  for (const std::string& l : chain.all_links) all_links += (all_links.empty() ? "'" : ", '") + l + "'";
  link_entries_ = named_entries(
      r_, "links",
      [&](const std::string& name) {
        return std::any_of(chain.links.begin(), chain.links.end(), [&](const ChainLink& l) { return l.name == name; });
      },
      "link", "link",
      " that moves with the chain from '" + base_link_ + "' to '" + tip_link_ + "' in " + chain.file.string() +
          " (those are " + moving + "; the file's links are " + all_links + ")",
      &problems_);
}

void UrdfOverlay::link(const ChainLink& link, LinkAmendment& amendment) {
  const auto e = link_entries_.find(link.name);
  if (e == link_entries_.end()) return;
  const TableReader entry(e->second.file_ptr(), e->second.raw(), "link '" + link.name + "'");
  LinkEntry links;
  read_config(entry, LinkEntry::schema(), links);
  amendment.replace = links.replace;
  amendment.collision_model = links.collision_model;
  amendment.inertia = links.inertia;
  for (std::size_t k = 0; k < links.collision.size(); ++k) {
    const ShapeSpec& shape = links.collision[k];
    if (shape.shape == ShapeSpec::Kind::kCapsule && !shape.length && !shape.from) {
      entry.fail("collision", "shape " + std::to_string(k + 1) +
                                  ": a capsule of a URDF link needs `length` (with `xyz`, `rpy`) or `from` and "
                                  "`to`, in the link's frame");
    }
    if (shape.velocity) {
      entry.fail("collision", "shape " + std::to_string(k + 1) + " has a velocity; only obstacles move");
    }
    amendment.shapes.push_back(shape);
  }
  entry.finish();
}

void UrdfOverlay::fail(const std::string& message) const { r_.fail("urdf", message); }

}  // namespace redres

// The only translation unit that includes urdfdom.

#include "parsers/urdf.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <sstream>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include "common/input_file.hpp"
#include "redres/common/error.hpp"

namespace redres {

namespace {

// Collects urdfdom's messages (it reports parse errors through console_bridge, not through its return value), so
// that they go into the error instead of to stderr.
class Collect final : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char* /*filename*/, int /*line*/) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) messages += (messages.empty() ? "" : "; ") + text;
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) errors += (errors.empty() ? "" : "; ") + text;
  }
  std::string messages, errors;  // warnings and errors; errors only
};

Eigen::Isometry3d pose_of(const urdf::Pose& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  t.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).toRotationMatrix();
  return t;
}

// The collision elements of `link`, whose frame is `at` in the frame of the UrdfLink `out` gathers shapes for.
void add_shapes(const std::string& where, const urdf::Link& link, const Eigen::Isometry3d& at,
                const std::string& messages, UrdfLink& out) {
  for (const urdf::CollisionSharedPtr& c : link.collision_array) {
    if (!c) continue;
    if (!c->geometry) {
      throw UrdfError(where + ": link '" + link.name + "' has a <collision> element whose geometry could not be read" +
                      (messages.empty() ? std::string() : " (" + messages + ")"));
    }
    const Eigen::Isometry3d pose = at * pose_of(c->origin);
    ShapeSpec s;
    s.xyz = {pose.translation().x(), pose.translation().y(), pose.translation().z()};
    s.rpy = rpy_of(pose.linear());
    switch (c->geometry->type) {
      case urdf::Geometry::SPHERE:
        s.shape = ShapeSpec::Kind::kSphere;
        s.radius = static_cast<const urdf::Sphere&>(*c->geometry).radius;
        break;
      case urdf::Geometry::BOX: {
        const urdf::Vector3& d = static_cast<const urdf::Box&>(*c->geometry).dim;
        s.shape = ShapeSpec::Kind::kBox;
        s.size = std::array<double, 3>{d.x, d.y, d.z};
        break;
      }
      case urdf::Geometry::CYLINDER: {
        const auto& cyl = static_cast<const urdf::Cylinder&>(*c->geometry);
        s.shape = ShapeSpec::Kind::kCylinder;
        s.radius = cyl.radius;
        s.length = cyl.length;
        break;
      }
      case urdf::Geometry::MESH: out.meshes.push_back(static_cast<const urdf::Mesh&>(*c->geometry).filename); continue;
    }
    out.shapes.push_back(s);
  }
}

// A side branch below `joint` (taken at position 0), its frames placed from `at`.
void add_branch(const std::string& where, const urdf::ModelInterface& model, const urdf::Joint& joint,
                const Eigen::Isometry3d& at, const std::string& messages, UrdfLink& out) {
  const urdf::LinkConstSharedPtr link = model.getLink(joint.child_link_name);
  if (!link) return;
  const Eigen::Isometry3d frame = at * pose_of(joint.parent_to_joint_origin_transform);
  add_shapes(where, *link, frame, messages, out);
  for (const urdf::JointSharedPtr& child : link->child_joints) add_branch(where, model, *child, frame, messages, out);
}

}  // namespace

UrdfChain read_urdf_chain(const std::filesystem::path& file, const std::string& base_link,
                          const std::string& tip_link) {
  const std::string where = file.string();
  std::string xml;
  try {
    xml = read_input_file(file, "URDF file");
  } catch (const ConfigError& e) {
    throw UrdfError(e.what());
  }

  urdf::ModelInterfaceSharedPtr model;
  std::string messages;
  {
    // console_bridge's handler is process-wide: one reader at a time.
    static std::mutex lock;
    const std::lock_guard<std::mutex> guard(lock);
    Collect collect;
    struct Restore {  // the previous handler comes back however parseURDF leaves
      ~Restore() { console_bridge::restorePreviousOutputHandler(); }
    };
    console_bridge::useOutputHandler(&collect);
    {
      const Restore restore;
      model = urdf::parseURDF(xml);
    }
    messages = collect.messages;
    // urdfdom drops an element it cannot read (a <collision> with a bad <cylinder>, say) and still returns a model:
    // any error it reported fails the file, so that nothing is lost without a word.
    if (model && !collect.errors.empty())
      throw UrdfError(where + ": urdfdom could not read all of it (" + collect.errors + ")");
  }
  if (!model)
    throw UrdfError(where + ": not a valid URDF (" + (messages.empty() ? "urdfdom gave no reason" : messages) + ")");

  UrdfChain chain;
  chain.robot_name = model->getName();
  const urdf::LinkConstSharedPtr base = model->getLink(base_link);
  if (!base) throw UrdfError(where + ": no link named '" + base_link + "' (base_link)");
  urdf::LinkConstSharedPtr link = model->getLink(tip_link);
  if (!link) throw UrdfError(where + ": no link named '" + tip_link + "' (tip_link)");

  // Walk up from the tip to the base; the joints met, reversed, are the chain.
  std::vector<urdf::LinkConstSharedPtr> links{link};
  while (link->name != base_link) {
    const urdf::JointConstSharedPtr joint = link->parent_joint;
    if (!joint) {
      throw UrdfError(where + ": link '" + tip_link + "' (tip_link) is not below link '" + base_link +
                      "' (base_link): walking up from it reaches the root '" + link->name + "'");
    }
    link = model->getLink(joint->parent_link_name);
    if (!link) throw UrdfError(where + ": joint '" + joint->name + "' names a missing parent link");
    links.push_back(link);
  }
  std::reverse(links.begin(), links.end());  // base first

  Eigen::Isometry3d fixed = Eigen::Isometry3d::Identity();  // fixed joints since the last moving one
  for (std::size_t k = 1; k < links.size(); ++k) {
    const urdf::JointConstSharedPtr joint = links[k]->parent_joint;
    const std::string who = where + ": joint '" + joint->name + "'";
    if (joint->mimic) throw UrdfError(who + " is a mimic joint; a chain of independent joints is expected");
    const Eigen::Isometry3d origin = pose_of(joint->parent_to_joint_origin_transform);
    switch (joint->type) {
      case urdf::Joint::FIXED: fixed = fixed * origin; break;
      case urdf::Joint::REVOLUTE:
      case urdf::Joint::CONTINUOUS:
      case urdf::Joint::PRISMATIC: {
        UrdfJoint j;
        j.name = joint->name;
        j.prismatic = joint->type == urdf::Joint::PRISMATIC;
        j.continuous = joint->type == urdf::Joint::CONTINUOUS;
        j.origin = fixed * origin;
        fixed = Eigen::Isometry3d::Identity();
        j.axis = Eigen::Vector3d(joint->axis.x, joint->axis.y, joint->axis.z);
        if (!(j.axis.norm() > 1e-9)) throw UrdfError(who + " has a zero axis");
        j.axis.normalize();
        if (joint->limits) {
          j.lower = joint->limits->lower;
          j.upper = joint->limits->upper;
          j.velocity = joint->limits->velocity;
        }
        chain.joints.push_back(j);
        break;
      }
      default:
        throw UrdfError(who + " is a " +
                        (joint->type == urdf::Joint::FLOATING ? std::string("floating")
                         : joint->type == urdf::Joint::PLANAR ? std::string("planar")
                                                              : std::string("unknown")) +
                        " joint; a chain of revolute, continuous, prismatic and fixed joints is expected");
    }
    if (chain.joints.empty()) continue;  // still on the base: these links do not move
    UrdfLink l;
    l.name = links[k]->name;
    l.joint = static_cast<int>(chain.joints.size()) - 1;
    l.pose = fixed;
    add_shapes(where, *links[k], Eigen::Isometry3d::Identity(), messages, l);
    // Side branches hanging from this link by fixed joints (a hand, a camera) ride on it; joints that could move
    // in them are taken at position 0 (they are not part of the chain).
    for (const urdf::JointSharedPtr& child : links[k]->child_joints) {
      if (k + 1 < links.size() && child->child_link_name == links[k + 1]->name) continue;  // the chain itself
      add_branch(where, *model, *child, Eigen::Isometry3d::Identity(), messages, l);
    }
    chain.links.push_back(std::move(l));
  }
  if (chain.joints.empty()) {
    throw UrdfError(where + ": no moving joint between '" + base_link + "' and '" + tip_link + "'");
  }
  chain.tip = fixed;
  return chain;
}

}  // namespace redres

// Reading a URDF's chain through urdfdom (with urdf_elements.cpp, the translation units that include urdfdom): the
// text checked first (urdf_outline.cpp), then the chain walked from the base to the tip, its side branches held.

#include "parsers/urdf.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <set>
#include <tuple>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include "common/input_file.hpp"
#include "common/text.hpp"
#include "parsers/urdf_elements.hpp"
#include "parsers/urdf_outline.hpp"
#include "redres/common/error.hpp"
#include "redres/config/config.hpp"
#include "redres/model/robot.hpp"

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

// The motion of a URDF joint at position q (rad or m): a turn about its axis, or a slide along it; a floating or planar
// joint (held) does not move.
Eigen::Isometry3d joint_motion(const urdf::Joint& j, double q) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  Eigen::Vector3d axis(j.axis.x, j.axis.y, j.axis.z);
  if (q == 0.0 || !axis.allFinite() || !(axis.norm() > 1e-9)) return m;
  axis.normalize();
  switch (j.type) {
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS: m.linear() = Eigen::AngleAxisd(q, axis).toRotationMatrix(); break;
    case urdf::Joint::PRISMATIC: m.translation() = q * axis; break;
    default: break;
  }
  return m;
}

bool movable(const urdf::Joint& j) {
  return j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS || j.type == urdf::Joint::PRISMATIC;
}

// Where the joints off the chain are held: the robot file's values, 0 (or the limit nearest it), a mimic's leader's.
struct Holder {
  const Namer& names;
  const urdf::ModelInterface& model;
  const std::map<std::string, double>& given;
  const std::set<std::string>& chain_joints;  // the chain's moving joints
  ChainDescription& out;

  // The position `j` is held at (recorded in out.held once, with a mimic's leader).
  double value(const urdf::Joint& j) {
    HeldJoint h = describe(j);
    if (j.mimic) {
      const std::string& leader = j.mimic->joint_name;
      h.mimics = leader;
      if (chain_joints.count(leader) != 0) {
        throw UrdfError(h.where + " is a mimic of joint '" + printable(leader) +
                        "', which is on the chain: a joint that moves with a chain joint is not supported (a chain of "
                        "independent joints is expected; choose a tip_link above joint '" +
                        printable(leader) + "' or below this one)");
      }
      const urdf::JointConstSharedPtr l = model.getJoint(leader);
      if (!l)
        throw UrdfError(h.where + " is a mimic of joint '" + printable(leader) + "', which the file does not have");
      HeldJoint lead = describe(*l);
      lead.value = own(*l);
      record(lead);
      h.value = j.mimic->multiplier * lead.value + j.mimic->offset;
      if (!std::isfinite(h.value)) throw UrdfError(h.where + ": <mimic> gives a position that is not finite");
    } else {
      h.value = own(j);
    }
    record(h);
    return h.value;
  }

 private:
  HeldJoint describe(const urdf::Joint& j) const {
    HeldJoint h;
    h.name = j.name;
    h.where = names.joint(j.name);
    h.limited = j.type != urdf::Joint::CONTINUOUS && j.limits != nullptr && movable(j);
    if (h.limited) {
      h.lower = j.limits->lower;
      h.upper = j.limits->upper;
    }
    return h;
  }
  // A joint's own held position: given, else 0 within its limits.
  double own(const urdf::Joint& j) const {
    if (const auto it = given.find(j.name); it != given.end()) return it->second;
    if (j.type == urdf::Joint::CONTINUOUS || j.limits == nullptr || !movable(j)) return 0.0;
    return std::clamp(0.0, std::min(j.limits->lower, j.limits->upper), std::max(j.limits->lower, j.limits->upper));
  }
  void record(const HeldJoint& h) {
    for (const HeldJoint& e : out.held) {
      if (e.name == h.name) return;
    }
    out.held.push_back(h);
  }
};

// The side branch below `joint`, hanging from a link that rides on chain joint `index` with its frame `at` in that
// joint's link frame: each link of it a ChainLink of its own, its movable joints held (Holder). Walked with a stack of
// its own, so that a branch of 10,000 fixed links is as safe as one of 3 (the graph is a tree: checked first).
void add_branch(const Namer& names, const urdf::ModelInterface& model, const urdf::Joint& joint, int index,
                const Eigen::Isometry3d& at, bool branch, Holder& holder, const std::string& messages,
                ChainDescription& chain) {
  struct Item {
    const urdf::Joint* joint;
    Eigen::Isometry3d from;
    bool branch;
  };
  std::vector<Item> stack{{&joint, at, branch}};
  std::size_t visited = 0;
  while (!stack.empty()) {
    if (++visited > model.joints_.size()) {  // the tree checks hold this off; kept so the walk always ends
      throw UrdfError(names.joint(joint.name) + ": its side branch goes round a cycle of joints");
    }
    const Item item = stack.back();
    stack.pop_back();
    const urdf::Joint& j = *item.joint;
    const urdf::LinkConstSharedPtr link = model.getLink(j.child_link_name);
    if (!link) continue;
    check_name(names.joint(j.name), j.name);
    check_name(names.link(link->name), link->name);
    check_pose(names.joint(j.name), "<origin>", j.parent_to_joint_origin_transform);
    const bool moves = movable(j) || j.mimic != nullptr;
    Eigen::Isometry3d frame = item.from * pose_of(j.parent_to_joint_origin_transform);
    if (moves) frame = frame * joint_motion(j, holder.value(j));
    ChainLink l;
    l.name = link->name;
    l.where = names.link(link->name);
    l.branch = item.branch || moves;
    l.joint = index;
    l.pose = frame;
    add_shapes(names, *link, Eigen::Isometry3d::Identity(), messages, l);
    add_visuals(names, *link, Eigen::Isometry3d::Identity(), l.visuals);
    chain.links.push_back(std::move(l));
    for (auto it = link->child_joints.rbegin(); it != link->child_joints.rend(); ++it) {
      if (*it) stack.push_back({it->get(), frame, item.branch || moves});
    }
  }
}

}  // namespace

namespace {

// Parses `file` (bounded, checked as a tree) and calls f(model, names, messages) with the model, whose links are
// unlinked again when f returns or throws.
template <class F>
auto with_parsed_urdf(const std::filesystem::path& file, F&& f) {
  const std::string where = file.string();
  std::string xml;
  try {
    xml = read_input_file(file, "URDF file");
  } catch (const ConfigError& e) {
    throw UrdfError(e.what());
  }
  const XmlOutline outline = outline_xml(where, xml);
  const Namer names{where, outline};
  check_tree(names, outline);

  urdf::ModelInterfaceSharedPtr model;
  // urdfdom's links hold their children by shared_ptr: in a file whose joints form a cycle they hold each other,
  // and the model would never be freed. The links are unlinked when the reading ends, however it ends (the chain
  // read from them is a copy).
  struct Unlink {
    urdf::ModelInterfaceSharedPtr& model;
    ~Unlink() {
      if (!model) return;
      for (auto& entry : model->links_) {
        if (!entry.second) continue;
        entry.second->child_links.clear();
        entry.second->child_joints.clear();
        entry.second->parent_joint.reset();
      }
    }
  } const unlink{model};
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
      throw UrdfError(where + ": urdfdom could not read all of it (" + printable(collect.errors) + ")");
  }
  if (!model) {
    throw UrdfError(where + ": not a valid URDF (" +
                    (messages.empty() ? std::string("urdfdom gave no reason") : printable(messages)) + ")");
  }
  return f(*model, names, messages);
}

}  // namespace

std::pair<std::string, std::string> default_urdf_chain(const std::filesystem::path& file) {
  return with_parsed_urdf(file, [&file](const urdf::ModelInterface& model, const Namer&, const std::string&) {
    const urdf::LinkConstSharedPtr root = model.getRoot();
    if (!root) throw UrdfError(file.string() + ": no root link");
    // The link below the root with the most revolute joints above it; of those, the fewest prismatic or mimic
    // joints (a gripper's fingers are not the arm), then the most links (a tool frame on the flange). Walked with a
    // stack.
    std::string tip = root->name;
    std::tuple<int, int, int> best{-1, 0, -1};  // revolute, -(prismatic or mimic), depth
    std::vector<std::tuple<const urdf::Link*, int, int, int>> stack{{root.get(), 0, 0, 0}};
    while (!stack.empty()) {
      const auto [link, revolute, other, depth] = stack.back();
      stack.pop_back();
      if (const std::tuple<int, int, int> here{revolute, -other, depth}; here > best) {
        best = here;
        tip = link->name;
      }
      for (const urdf::JointSharedPtr& j : link->child_joints) {
        if (!j) continue;
        const urdf::LinkConstSharedPtr child = model.getLink(j->child_link_name);
        if (!child) continue;
        const bool mimic = j->mimic != nullptr;
        const bool turns = !mimic && (j->type == urdf::Joint::REVOLUTE || j->type == urdf::Joint::CONTINUOUS);
        const bool slides = mimic || j->type == urdf::Joint::PRISMATIC;
        stack.emplace_back(child.get(), revolute + (turns ? 1 : 0), other + (slides ? 1 : 0), depth + 1);
      }
    }
    return std::make_pair(root->name, tip);
  });
}

ChainDescription read_urdf_chain(const std::filesystem::path& file, const std::string& base_link,
                                 const std::string& tip_link, const std::map<std::string, double>& held) {
  return with_parsed_urdf(file, [&](const urdf::ModelInterface& model_ref, const Namer& names,
                                    const std::string& messages) {
    const std::string where = file.string();
    const urdf::ModelInterface* model = &model_ref;
    ChainDescription chain;
    chain.file = file;
    chain.robot_name = model->getName();
    check_name(where + ": <robot>", chain.robot_name);
    for (const std::string& l : names.outline.link_order) chain.all_links.push_back(l);
    const urdf::LinkConstSharedPtr base = model->getLink(base_link);
    if (!base) {
      throw UrdfError(where + ": no link named '" + printable(base_link) + "' (base_link); " + names.link_list());
    }
    urdf::LinkConstSharedPtr link = model->getLink(tip_link);
    if (!link)
      throw UrdfError(where + ": no link named '" + printable(tip_link) + "' (tip_link); " + names.link_list());

    // Walk up from the tip to the base (the tree is checked: this ends); the joints met, reversed, are the chain.
    std::vector<urdf::LinkConstSharedPtr> links{link};
    while (link->name != base_link) {
      if (links.size() > model->links_.size()) {  // the tree checks hold this off; kept so the walk always ends
        throw UrdfError(where + ": walking up from link '" + printable(tip_link) + "' goes round a cycle of joints");
      }
      const urdf::JointConstSharedPtr joint = link->parent_joint;
      if (!joint) {
        throw UrdfError(where + ": link '" + printable(tip_link) + "' (tip_link) is not below link '" +
                        printable(base_link) + "' (base_link): walking up from it reaches the root '" +
                        printable(link->name) + "'");
      }
      link = model->getLink(joint->parent_link_name);
      if (!link) throw UrdfError(names.joint(joint->name) + " names a missing parent link");
      links.push_back(link);
    }
    std::reverse(links.begin(), links.end());  // base first

    // The chain's own moving joints (a mimic joint is not one: it follows its leader).
    std::set<std::string> chain_joints;
    for (std::size_t k = 1; k < links.size(); ++k) {
      const urdf::JointConstSharedPtr joint = links[k]->parent_joint;
      if (movable(*joint) && !joint->mimic) chain_joints.insert(joint->name);
    }
    Holder holder{names, *model, held, chain_joints, chain};

    Eigen::Isometry3d fixed = Eigen::Isometry3d::Identity();  // fixed joints since the last moving one
    add_visuals(names, *links.front(), fixed, chain.base_visuals);
    for (std::size_t k = 1; k < links.size(); ++k) {
      const urdf::JointConstSharedPtr joint = links[k]->parent_joint;
      const std::string who = names.joint(joint->name);
      check_name(who, joint->name);
      check_name(names.link(links[k]->name), links[k]->name);
      check_pose(who, "<origin>", joint->parent_to_joint_origin_transform);
      const Eigen::Isometry3d origin = pose_of(joint->parent_to_joint_origin_transform);
      if (joint->mimic) {
        // A mimic joint whose leader is off the chain is held where its leader is (Holder refuses one whose leader
        // is on the chain): a fixed transform here.
        fixed = fixed * origin * joint_motion(*joint, holder.value(*joint));
        if (chain.joints.empty()) continue;
      } else {
        switch (joint->type) {
          case urdf::Joint::FIXED: fixed = fixed * origin; break;
          case urdf::Joint::REVOLUTE:
          case urdf::Joint::CONTINUOUS:
          case urdf::Joint::PRISMATIC: {
            if (chain.joints.size() == kMaxJoints) {
              throw UrdfError(who + ": the chain from '" + printable(base_link) + "' to '" + printable(tip_link) +
                              "' has more than " + std::to_string(kMaxJoints) + " moving joints, the most a robot has");
            }
            ChainJoint j;
            const bool prismatic = joint->type == urdf::Joint::PRISMATIC;
            j.spec.name = joint->name;
            j.spec.type = prismatic ? JointType::kPrismatic : JointType::kRevolute;
            j.where = who;
            j.continuous = joint->type == urdf::Joint::CONTINUOUS;
            j.spec.origin = fixed * origin;
            fixed = Eigen::Isometry3d::Identity();
            Eigen::Vector3d& axis = j.spec.axis;
            axis = Eigen::Vector3d(joint->axis.x, joint->axis.y, joint->axis.z);
            if (!axis.allFinite() || !(axis.norm() > 1e-9)) {
              throw UrdfError(who + ": <axis> expected a finite, non-zero vector, got [" + num(axis.x()) + ", " +
                              num(axis.y()) + ", " + num(axis.z()) + "]");
            }
            axis.normalize();
            if (joint->dynamics) {
              const double damping = joint->dynamics->damping;
              if (!(std::isfinite(damping) && damping >= 0.0 && damping <= 1e6)) {
                throw UrdfError(who + ": <dynamics> damping expected 0 <= damping <= 1e6, got " + num(damping));
              }
              j.spec.damping = damping;
            }
            if (joint->limits) {
              const double lower = joint->limits->lower, upper = joint->limits->upper;
              const double velocity = joint->limits->velocity, effort = joint->limits->effort;
              if (!(std::isfinite(effort) && effort >= 0.0 && effort <= 1e7)) {
                throw UrdfError(who + ": <limit> effort expected 0 <= effort <= 1e7 " + (prismatic ? "N" : "N m") +
                                ", got " + num(effort));
              }
              const double bound = *physical_bound(prismatic ? "m" : "rad");
              const char* unit = prismatic ? " m" : " rad";
              if (!j.continuous && !(std::abs(lower) <= bound && std::abs(upper) <= bound)) {
                throw UrdfError(who + ": <limit> lower and upper expected |x| <= " + num(bound) + unit +
                                " (a physical range), got " + num(lower) + " and " + num(upper));
              }
              if (!(std::abs(velocity) <= *physical_bound("rad/s or m/s")) || velocity < 0.0) {
                throw UrdfError(who + ": <limit> velocity expected 0 <= v <= " + num(*physical_bound("rad/s or m/s")) +
                                (prismatic ? " m/s" : " rad/s") + ", got " + num(velocity));
              }
              j.spec.lower = lower;
              j.spec.upper = upper;
              j.velocity = velocity;
              if (effort > 0.0) j.spec.effort_limit = effort;
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
      }
      if (chain.joints.empty()) {  // still on the base: these links do not move
        add_visuals(names, *links[k], fixed, chain.base_visuals);
        continue;
      }
      ChainLink l;
      l.name = links[k]->name;
      l.where = names.link(links[k]->name);
      l.joint = static_cast<int>(chain.joints.size()) - 1;
      l.pose = fixed;
      add_shapes(names, *links[k], Eigen::Isometry3d::Identity(), messages, l);
      add_visuals(names, *links[k], Eigen::Isometry3d::Identity(), l.visuals);
      chain.links.push_back(std::move(l));
      // Side branches hanging from this link (a hand, a camera, a head): each of their links a body of its own, riding
      // on this joint, their movable joints held (Holder).
      for (const urdf::JointSharedPtr& child : links[k]->child_joints) {
        if (k + 1 < links.size() && child->child_link_name == links[k + 1]->name) continue;  // the chain itself
        add_branch(names, *model, *child, static_cast<int>(chain.joints.size()) - 1, fixed, false, holder, messages,
                   chain);
      }
    }
    if (chain.joints.empty()) {
      throw UrdfError(where + ": no moving joint between '" + printable(base_link) + "' and '" + printable(tip_link) +
                      "'");
    }
    chain.tip = fixed;
    return chain;
  });
}

}  // namespace redres

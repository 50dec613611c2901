// The only translation unit that includes urdfdom.

#include "parsers/urdf.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <tuple>
#include <unordered_map>

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include "common/input_file.hpp"
#include "common/text.hpp"
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

// The <robot>'s links and joints as TinyXML reads them (outline_xml): where each starts, by name, for messages.
struct XmlOutline {
  std::map<std::string, std::size_t> link_lines, joint_lines;
  // Each <joint>: its name, its <parent link> and <child link>, and its line (the graph urdfdom will
  // build, checked before it does: a cycle of its shared_ptr links leaks, and some it reports only by failing).
  struct Joint {
    std::string name, parent, child;
    std::size_t line = 0;
  };
  std::vector<Joint> joints;
  std::size_t links = 0;
  std::vector<std::string> link_order;  // the links' names, in file order
};

// A linear scan of the XML before TinyXML sees it: the nesting depth and the element count are bounded (TinyXML
// parses recursively, so 50,000 nested elements overflow its stack, and 20,000 take seconds). Comments, CDATA,
// processing instructions and the DOCTYPE are skipped.
void bound_xml(const std::string& where, const std::string& xml) {
  std::size_t line = 1, depth = 0, elements = 0;
  const std::size_t n = xml.size();
  // Moves i to just past `end` (counting lines); false if the file ends first.
  const auto skip_to = [&](std::size_t& i, std::string_view end) {
    const std::size_t at = xml.find(end, i);
    const std::size_t stop = at == std::string::npos ? n : at + end.size();
    line += static_cast<std::size_t>(std::count(xml.begin() + static_cast<std::ptrdiff_t>(i),
                                                xml.begin() + static_cast<std::ptrdiff_t>(stop), '\n'));
    i = stop;
    return at != std::string::npos;
  };
  // A construct that the file does not close is malformed XML: refused here, so that the depth counted is the
  // depth TinyXML will recurse to (it is lenient). Declarations and <!...> end at the first '>', as TinyXML ends
  // them.
  std::size_t opened = 1;  // the line of the construct being read
  const auto unclosed = [&](const std::string& what) {
    throw UrdfError(where + ":" + std::to_string(opened) + ": " + what + " is not closed (malformed XML)");
  };
  for (std::size_t i = 0; i < n;) {
    if (xml[i] != '<') {
      if (xml[i] == '\n') ++line;
      ++i;
      continue;
    }
    opened = line;
    if (xml.compare(i, 4, "<!--") == 0) {
      if (!skip_to(i, "-->")) unclosed("a comment <!--");
    } else if (xml.compare(i, 9, "<![CDATA[") == 0) {
      if (!skip_to(i, "]]>")) unclosed("a <![CDATA[ section");
    } else if (xml.compare(i, 2, "<?") == 0 || xml.compare(i, 2, "<!") == 0) {
      if (!skip_to(i, ">")) unclosed("a declaration");
    } else if (xml.compare(i, 2, "</") == 0) {
      if (depth > 0) --depth;
      if (!skip_to(i, ">")) unclosed("an end tag");
    } else {
      const std::size_t start_line = line;
      std::size_t k = i + 1;
      while (k < n && !std::isspace(static_cast<unsigned char>(xml[k])) && xml[k] != '>' && xml[k] != '/') ++k;
      const std::string tag = xml.substr(i + 1, k - i - 1);
      // The attributes up to the closing '>' (one outside quotes).
      char quote = 0;
      std::size_t end = k;
      for (; end < n && (quote != 0 || xml[end] != '>'); ++end) {
        if (xml[end] == '\n') ++line;
        if (quote != 0) {
          if (xml[end] == quote) quote = 0;
        } else if (xml[end] == '"' || xml[end] == '\'') {
          quote = xml[end];
        }
      }
      if (end >= n) unclosed("the tag <" + printable(tag));
      const bool empty = xml[end - 1] == '/';
      if (++elements > kMaxUrdfElements) {
        throw UrdfError(where + ":" + std::to_string(start_line) + ": more than " + std::to_string(kMaxUrdfElements) +
                        " XML elements; a URDF has at most that many");
      }
      if (!empty && ++depth > kMaxUrdfDepth) {
        throw UrdfError(where + ":" + std::to_string(start_line) + ": <" + printable(tag) + "> is nested " +
                        std::to_string(depth) + " elements deep; a URDF nests at most " +
                        std::to_string(kMaxUrdfDepth));
      }
      i = end + 1;
    }
  }
}

// The <robot>'s links and joints as urdfdom will read them: parsed by the TinyXML that urdfdom itself parses with,
// and walked as urdfdom walks it (the first <robot>; its <link> and <joint> children; each joint's first <parent>
// and first <child>, their `link` attribute), so that the tree checked below is the graph urdfdom builds, entities,
// repeated elements and all. The file's bounds are checked first.
XmlOutline outline_xml(const std::string& where, const std::string& xml) {
  bound_xml(where, xml);
  TiXmlDocument doc;
  doc.Parse(xml.c_str());
  if (doc.Error()) {
    throw UrdfError(where + ":" + std::to_string(doc.ErrorRow()) + ":" + std::to_string(doc.ErrorCol()) +
                    ": malformed XML (" + printable(doc.ErrorDesc() != nullptr ? doc.ErrorDesc() : "") + ")");
  }
  XmlOutline out;
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  if (robot == nullptr) return out;  // urdfdom reports it
  const auto text = [](const char* value) { return value != nullptr ? std::string(value) : std::string(); };
  for (const TiXmlElement* e = robot->FirstChildElement("link"); e != nullptr; e = e->NextSiblingElement("link")) {
    out.link_lines.emplace(text(e->Attribute("name")), static_cast<std::size_t>(e->Row()));
    if (out.link_order.size() < kMaxUrdfLinks) out.link_order.push_back(text(e->Attribute("name")));
    ++out.links;
  }
  for (const TiXmlElement* e = robot->FirstChildElement("joint"); e != nullptr; e = e->NextSiblingElement("joint")) {
    XmlOutline::Joint joint{text(e->Attribute("name")), "", "", static_cast<std::size_t>(e->Row())};
    if (const TiXmlElement* p = e->FirstChildElement("parent")) joint.parent = text(p->Attribute("link"));
    if (const TiXmlElement* c = e->FirstChildElement("child")) joint.child = text(c->Attribute("link"));
    out.joint_lines.emplace(joint.name, joint.line);
    out.joints.push_back(std::move(joint));
  }
  return out;
}

Eigen::Isometry3d pose_of(const urdf::Pose& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  t.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).toRotationMatrix();
  return t;
}

// Names each element in messages, with its line where the scan found it: "file:12: link 'forearm'".
struct Namer {
  const std::string& where;
  const XmlOutline& outline;
  [[nodiscard]] std::string link(const std::string& name) const { return at(outline.link_lines, "link", name); }
  [[nodiscard]] std::string joint(const std::string& name) const { return at(outline.joint_lines, "joint", name); }
  // "the file's 12 links: 'base', 'l1', ..." (the first 60 by name).
  [[nodiscard]] std::string link_list() const {
    std::string s = "the file's " + std::to_string(outline.links) + " link" + (outline.links == 1 ? "" : "s") + ":";
    std::size_t k = 0;
    for (const std::string& name : outline.link_order) {
      if (k++ == 60) {
        s += " ... (" + std::to_string(outline.link_order.size() - 60) + " more)";
        break;
      }
      s += (k == 1 ? " '" : ", '") + printable(name) + "'";
    }
    return s;
  }

 private:
  std::string at(const std::map<std::string, std::size_t>& lines, const char* kind, const std::string& name) const {
    const auto it = lines.find(name);
    return where + (it == lines.end() ? std::string() : ":" + std::to_string(it->second)) + ": " + kind + " '" +
           printable(name) + "'";
  }
};

// A length of the URDF (an origin's coordinate, a radius, a side) within the robot file's physical range.
void check_length(const std::string& who, const char* what, double value, bool positive) {
  const double bound = *physical_bound("m");
  if (!(std::abs(value) <= bound) || (positive && !(value > 0.0))) {
    throw UrdfError(who + ": " + what + " expected " + (positive ? "> 0 and " : "") + "|x| <= " + num(bound) +
                    " m (a physical range), got " + num(value));
  }
}

void check_pose(const std::string& who, const char* what, const urdf::Pose& p) {
  const std::string xyz = std::string(what) + " xyz";
  for (double v : {p.position.x, p.position.y, p.position.z}) check_length(who, xyz.c_str(), v, false);
  const double q[4] = {p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z};
  if (!std::all_of(std::begin(q), std::end(q), [](double v) { return std::isfinite(v); })) {
    throw UrdfError(who + ": " + what + " rpy is not finite");
  }
}

// A <collision> or <visual> element's geometry (`element`: "" or "<visual> ", for messages), checked: lengths
// positive and physical, a mesh's scale positive.
UrdfVisual read_geometry(const std::string& who, const std::string& element, const urdf::Geometry& geometry) {
  UrdfVisual g;
  switch (geometry.type) {
    case urdf::Geometry::SPHERE:
      g.kind = UrdfVisual::Kind::kSphere;
      g.radius = static_cast<const urdf::Sphere&>(geometry).radius;
      check_length(who, (element + "<sphere> radius").c_str(), g.radius, true);
      break;
    case urdf::Geometry::BOX: {
      const urdf::Vector3& d = static_cast<const urdf::Box&>(geometry).dim;
      g.kind = UrdfVisual::Kind::kBox;
      g.size = {d.x, d.y, d.z};
      for (double v : g.size) check_length(who, (element + "<box> size").c_str(), v, true);
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cyl = static_cast<const urdf::Cylinder&>(geometry);
      g.kind = UrdfVisual::Kind::kCylinder;
      g.radius = cyl.radius;
      g.length = cyl.length;
      check_length(who, (element + "<cylinder> radius").c_str(), cyl.radius, true);
      check_length(who, (element + "<cylinder> length").c_str(), cyl.length, true);
      break;
    }
    case urdf::Geometry::MESH: {
      const auto& mesh = static_cast<const urdf::Mesh&>(geometry);
      g.kind = UrdfVisual::Kind::kMesh;
      g.filename = mesh.filename;
      g.scale = Eigen::Vector3d(mesh.scale.x, mesh.scale.y, mesh.scale.z);
      if (!g.scale.allFinite() || (g.scale.array() <= 0.0).any()) {
        throw UrdfError(who + ": " + element + "<mesh> scale expected > 0 on every axis");
      }
      break;
    }
  }
  return g;
}

// The collision elements of `link`, whose frame is `at` in the frame of the UrdfLink `out` gathers shapes for.
void add_shapes(const Namer& names, const urdf::Link& link, const Eigen::Isometry3d& at, const std::string& messages,
                UrdfLink& out) {
  const std::string who = names.link(link.name);
  // The mass properties ride with the shapes; a massless <inertial> (a frame with no body) adds nothing.
  if (link.inertial && link.inertial->mass != 0.0) {
    const urdf::Inertial& in = *link.inertial;
    check_pose(who, "<inertial> <origin>", in.origin);
    Inertia body;
    body.mass = in.mass;
    body.tensor << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    const Eigen::Isometry3d frame = at * pose_of(in.origin);
    if (!(std::isfinite(in.mass) && in.mass > 0.0)) throw UrdfError(who + ": <inertial>: expected a mass >= 0");
    // A maker's tensor that no rigid body has (rounded figures break the triangle inequality) does not stop the
    // robot from loading: its kinematics do not need it. It is kept as given, with a warning.
    if (const std::string bad = body.invalid(); !bad.empty()) out.warnings.push_back(who + ": <inertial>: " + bad);
    const Inertia placed = body.moved(frame);  // com at the origin of the inertial frame
    out.inertia = out.inertia ? out.inertia->combined(placed) : placed;
  }
  for (const urdf::CollisionSharedPtr& c : link.collision_array) {
    if (!c) continue;
    if (!c->geometry) {
      throw UrdfError(who + " has a <collision> element whose geometry could not be read" +
                      (messages.empty() ? std::string() : " (" + printable(messages) + ")"));
    }
    check_pose(who, "<collision> <origin>", c->origin);
    const Eigen::Isometry3d pose = at * pose_of(c->origin);
    const UrdfVisual g = read_geometry(who, "", *c->geometry);
    if (g.kind == UrdfVisual::Kind::kMesh) {
      out.meshes.push_back({g.filename, g.scale, pose});
      continue;
    }
    ShapeSpec s;
    s.xyz = {pose.translation().x(), pose.translation().y(), pose.translation().z()};
    s.rpy = rpy_of(pose.linear());
    switch (g.kind) {
      case UrdfVisual::Kind::kSphere:
        s.shape = ShapeSpec::Kind::kSphere;
        s.radius = g.radius;
        break;
      case UrdfVisual::Kind::kBox:
        s.shape = ShapeSpec::Kind::kBox;
        s.size = g.size;
        break;
      default:
        s.shape = ShapeSpec::Kind::kCylinder;
        s.radius = g.radius;
        s.length = g.length;
        break;
    }
    out.shapes.push_back(s);
  }
}

// The visual elements of `link`, whose frame is `at` in the frame they are gathered in. Checked as the collision
// elements are (a bad one is an error: the file is wrong), but a viewer alone uses them.
void add_visuals(const Namer& names, const urdf::Link& link, const Eigen::Isometry3d& at,
                 std::vector<UrdfVisual>& out) {
  const std::string who = names.link(link.name);
  for (const urdf::VisualSharedPtr& v : link.visual_array) {
    if (!v || !v->geometry) continue;  // urdfdom reports a visual it cannot read as it parses; nothing to draw
    check_pose(who, "<visual> <origin>", v->origin);
    UrdfVisual u;
    u.link = link.name;
    u.pose = at * pose_of(v->origin);
    const UrdfVisual g = read_geometry(who, "<visual> ", *v->geometry);
    u.kind = g.kind;
    u.filename = g.filename;
    u.scale = g.scale;
    u.size = g.size;
    u.radius = g.radius;
    u.length = g.length;
    if (v->material) {
      const urdf::Color& c = v->material->color;
      const std::array<double, 4> rgba{c.r, c.g, c.b, c.a};
      if (std::all_of(rgba.begin(), rgba.end(), [](double x) { return std::isfinite(x) && x >= 0.0 && x <= 1.0; })) {
        u.rgba = rgba;
      }
    }
    out.push_back(std::move(u));
  }
}

void check_name(const std::string& who, const std::string& name) {
  if (!is_printable_name(name)) {
    throw UrdfError(who + ": the name is not UTF-8 without control characters (it reads '" + printable(name) + "')");
  }
}

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
  UrdfChain& out;

  // The position `j` is held at (recorded in out.held once, with a mimic's leader).
  double value(const urdf::Joint& j) {
    UrdfHeldJoint h = describe(j);
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
      UrdfHeldJoint lead = describe(*l);
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
  UrdfHeldJoint describe(const urdf::Joint& j) const {
    UrdfHeldJoint h;
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
  void record(const UrdfHeldJoint& h) {
    for (const UrdfHeldJoint& e : out.held) {
      if (e.name == h.name) return;
    }
    out.held.push_back(h);
  }
};

// The side branch below `joint`, hanging from a link that rides on chain joint `index` with its frame `at` in that
// joint's link frame: each link of it a UrdfLink of its own, its movable joints held (Holder). Walked with a stack of
// its own, so that a branch of 10,000 fixed links is as safe as one of 3 (the graph is a tree: checked first).
void add_branch(const Namer& names, const urdf::ModelInterface& model, const urdf::Joint& joint, int index,
                const Eigen::Isometry3d& at, bool branch, Holder& holder, const std::string& messages,
                UrdfChain& chain) {
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
    UrdfLink l;
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

// The joints form a tree: at most kMaxUrdfLinks links and joints, each link the child of at most one joint, no
// joint its own link's parent, and no cycle (a link whose parents never reach a root). Checked on the text's
// outline, before urdfdom builds the graph: urdfdom checks only that one link has no parent, a cycle beside it
// would send the walks below round for ever, and its links, which hold their children by shared_ptr, would never
// be freed.
void check_tree(const Namer& names, const XmlOutline& outline) {
  if (outline.links > kMaxUrdfLinks || outline.joints.size() > kMaxUrdfLinks) {
    throw UrdfError(names.where + ": " + std::to_string(outline.links) + " links and " +
                    std::to_string(outline.joints.size()) + " joints; a URDF has at most " +
                    std::to_string(kMaxUrdfLinks) + " of each");
  }
  std::unordered_map<std::string, const XmlOutline::Joint*> parent;  // child link -> the joint above it
  for (const XmlOutline::Joint& joint : outline.joints) {
    if (joint.child.empty() || joint.parent.empty()) continue;  // urdfdom reports it
    if (joint.child == joint.parent) {
      throw UrdfError(names.joint(joint.name) + " has link '" + printable(joint.child) +
                      "' as both its parent and its child");
    }
    const auto [it, fresh] = parent.emplace(joint.child, &joint);
    if (!fresh) {
      throw UrdfError(names.joint(joint.name) + " and joint '" + printable(it->second->name) + "' both have link '" +
                      printable(joint.child) + "' as their child; a link has one parent");
    }
  }
  // Each link's way up, followed once: 1 while on the current way, 2 when it is known to reach a root.
  std::unordered_map<std::string, int> state;
  std::vector<std::string> way;
  for (const auto& entry : parent) {
    std::string at_link = entry.first;
    way.clear();
    while (state[at_link] == 0) {
      state[at_link] = 1;
      way.push_back(at_link);
      const auto up = parent.find(at_link);
      if (up == parent.end()) break;
      at_link = up->second->parent;
    }
    if (state[at_link] == 1 && parent.count(at_link) != 0) {
      std::string cycle;
      const auto first = std::find(way.begin(), way.end(), at_link);
      for (auto it = first; it != way.end(); ++it) cycle += "'" + printable(*it) + "' -> ";
      throw UrdfError(names.link(at_link) + " is on a cycle of joints (" + cycle + "'" + printable(at_link) +
                      "'): a URDF's joints form a tree");
    }
    for (const std::string& l : way) state[l] = 2;
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

UrdfChain read_urdf_chain(const std::filesystem::path& file, const std::string& base_link, const std::string& tip_link,
                          const std::map<std::string, double>& held) {
  return with_parsed_urdf(file, [&](const urdf::ModelInterface& model_ref, const Namer& names,
                                    const std::string& messages) {
    const std::string where = file.string();
    const urdf::ModelInterface* model = &model_ref;
    UrdfChain chain;
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
            UrdfJoint j;
            j.name = joint->name;
            j.where = who;
            j.prismatic = joint->type == urdf::Joint::PRISMATIC;
            j.continuous = joint->type == urdf::Joint::CONTINUOUS;
            j.origin = fixed * origin;
            fixed = Eigen::Isometry3d::Identity();
            j.axis = Eigen::Vector3d(joint->axis.x, joint->axis.y, joint->axis.z);
            if (!j.axis.allFinite() || !(j.axis.norm() > 1e-9)) {
              throw UrdfError(who + ": <axis> expected a finite, non-zero vector, got [" + num(j.axis.x()) + ", " +
                              num(j.axis.y()) + ", " + num(j.axis.z()) + "]");
            }
            j.axis.normalize();
            if (joint->dynamics) {
              j.damping = joint->dynamics->damping;
              if (!(std::isfinite(j.damping) && j.damping >= 0.0 && j.damping <= 1e6)) {
                throw UrdfError(who + ": <dynamics> damping expected 0 <= damping <= 1e6, got " + num(j.damping));
              }
            }
            if (joint->limits) {
              j.lower = joint->limits->lower;
              j.upper = joint->limits->upper;
              j.velocity = joint->limits->velocity;
              j.effort = joint->limits->effort;
              if (!(std::isfinite(j.effort) && j.effort >= 0.0 && j.effort <= 1e7)) {
                throw UrdfError(who + ": <limit> effort expected 0 <= effort <= 1e7 " + (j.prismatic ? "N" : "N m") +
                                ", got " + num(j.effort));
              }
              const double bound = *physical_bound(j.prismatic ? "m" : "rad");
              const char* unit = j.prismatic ? " m" : " rad";
              if (!j.continuous && !(std::abs(j.lower) <= bound && std::abs(j.upper) <= bound)) {
                throw UrdfError(who + ": <limit> lower and upper expected |x| <= " + num(bound) + unit +
                                " (a physical range), got " + num(j.lower) + " and " + num(j.upper));
              }
              if (!(std::abs(j.velocity) <= *physical_bound("rad/s or m/s")) || j.velocity < 0.0) {
                throw UrdfError(who + ": <limit> velocity expected 0 <= v <= " + num(*physical_bound("rad/s or m/s")) +
                                (j.prismatic ? " m/s" : " rad/s") + ", got " + num(j.velocity));
              }
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
      UrdfLink l;
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

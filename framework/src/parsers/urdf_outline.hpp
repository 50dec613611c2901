#pragma once
// A URDF's text before urdfdom reads it: its bounds (nesting depth, element count), the outline of its links and
// joints as TinyXML reads it (where each is, for messages), and the check that its joints form a tree. Private to
// the URDF reader (urdf.cpp, urdf_elements.cpp).

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "redres/common/error.hpp"

namespace redres {

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

// The <robot>'s links and joints as urdfdom will read them: parsed by the TinyXML that urdfdom itself parses with,
// and walked as urdfdom walks it (the first <robot>; its <link> and <joint> children; each joint's first <parent>
// and first <child>, their `link` attribute), so that the tree checked below is the graph urdfdom builds, entities,
// repeated elements and all. The file's bounds are checked first (UrdfError naming the bound).
XmlOutline outline_xml(const std::string& where, const std::string& xml);

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

// The joints form a tree: at most kMaxUrdfLinks links and joints, each link the child of at most one joint, no
// joint its own link's parent, and no cycle (a link whose parents never reach a root). Checked on the text's
// outline, before urdfdom builds the graph: urdfdom checks only that one link has no parent, a cycle beside it
// would send the walks below round for ever, and its links, which hold their children by shared_ptr, would never
// be freed. Throws UrdfError.
void check_tree(const Namer& names, const XmlOutline& outline);

}  // namespace redres

// The URDF's text checked before urdfdom parses it (TinyXML, which urdfdom parses with; not urdfdom itself).

#include "parsers/urdf_outline.hpp"

#include <algorithm>
#include <cctype>
#include <string_view>
#include <unordered_map>

#include <tinyxml.h>

#include "parsers/urdf.hpp"

namespace redres {

namespace {

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

}  // namespace

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

}  // namespace redres

#pragma once
/// @file
/// Escaping text for XML and HTML (private to the framework): the MuJoCo model's names, the viewer's title.

#include <string>
#include <string_view>

namespace redres {

/// Text as XML or HTML character data or an attribute value: & < > " ' escaped.
[[nodiscard]] inline std::string xml_escaped(std::string_view s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace redres

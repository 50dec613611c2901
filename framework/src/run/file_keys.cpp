#include "redres/run/file_keys.hpp"

#include <sstream>
#include <stdexcept>

#include "redres/parsers/robot_toml.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/sweep.hpp"

namespace redres {

namespace {

// A table cell: pipes escaped, so that a rule such as "|x| <= 1" keeps the table's shape, and angle brackets, so
// that "runs/<index>/" is not taken for HTML.
std::string cell(const std::string& text) {
  std::string out;
  for (char ch : text) {
    if (ch == '<') {
      out += "&lt;";
    } else if (ch == '>') {
      out += "&gt;";
    } else {
      if (ch == '|') out += '\\';
      out += ch;
    }
  }
  return out;
}

}  // namespace

std::vector<KeyTable> file_key_tables() {
  std::vector<KeyTable> out = scenario_key_tables();
  for (const auto* tables : {&robot_key_tables(), &sweep_key_tables()})
    out.insert(out.end(), tables->begin(), tables->end());
  return out;
}

std::string presence_text(const KeyInfo& key) {
  switch (key.presence) {
    case Presence::kRequired: return "required";
    case Presence::kGroup: return "group " + key.group;
    case Presence::kOptional: break;
  }
  return "= " + key.default_text;
}

std::string file_keys_markdown(std::string_view file) {
  std::ostringstream md;
  bool any = false;
  for (const KeyTable& t : file_key_tables()) {
    if (t.file != file) continue;
    if (any) md << "\n";
    any = true;
    md << "**" << (t.table.empty() ? "top level" : "`" + t.table + "`") << "**: " << t.help << ".\n\n";
    md << "| key | type | unit | default | rule | meaning |\n|---|---|---|---|---|---|\n";
    for (const KeyInfo& k : t.keys) {
      md << "| `" << k.name << "` | " << cell(k.type) << " | " << cell(k.unit) << " | " << cell(presence_text(k))
         << " | " << cell(k.rule) << " | " << cell(k.help) << " |\n";
    }
  }
  if (!any)
    throw std::invalid_argument("file_keys_markdown: file is \"scenario\", \"robot\" or \"sweep\" (got \"" +
                                std::string(file) + "\")");
  return md.str();
}

}  // namespace redres

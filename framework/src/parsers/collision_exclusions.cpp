#include "parsers/collision_exclusions.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace redres {

void read_collision_exclude(const TableReader& r, RobotSpec& spec) {
  if (!r.has("collision_exclude")) return;
  const toml::array* pairs = r.raw().get("collision_exclude")->as_array();
  if (pairs == nullptr) {
    r.fail("collision_exclude", "expected an array of pairs of joint or link names, e.g. [[\"j1\", \"j3\"]]");
  }
  // The links that have shapes (bodies), by name; a joint stands for its link.
  std::vector<std::string> links;
  for (const JointSpec& jt : spec.joints) {
    for (const ShapeSpec& shape : jt.collision) {
      if (!shape.body.empty() && std::find(links.begin(), links.end(), shape.body) == links.end()) {
        links.push_back(shape.body);
      }
    }
  }
  for (const toml::node& p : *pairs) {
    const toml::array* pair = p.as_array();
    std::string names[2];
    int joints[2] = {-1, -1};
    for (std::size_t k = 0; k < 2; ++k) {
      const toml::node* el = pair != nullptr && pair->size() == 2 ? pair->get(k) : nullptr;
      const auto* name = el != nullptr ? el->as_string() : nullptr;
      if (name != nullptr) {
        names[k] = name->get();
        for (std::size_t j = 0; j < spec.joints.size(); ++j) {
          if (spec.joints[j].name == names[k]) joints[k] = static_cast<int>(j);
        }
      }
      const bool link = std::find(links.begin(), links.end(), names[k]) != links.end() ||
                        std::any_of(spec.joints.begin(), spec.joints.end(), [&](const JointSpec& jt) {
                          return !jt.link_name.empty() && jt.link_name == names[k];
                        });
      if (name == nullptr || (joints[k] < 0 && !link)) {
        std::string known;
        for (const JointSpec& jt : spec.joints) known += (known.empty() ? "'" : ", '") + jt.name + "'";
        for (const std::string& l : links) known += ", '" + l + "'";
        throw ConfigError(location_of(r.file(), p),
                          "key 'collision_exclude': expected pairs of two joint or link names of this robot, e.g. "
                          "[\"j1\", \"j3\"]" +
                              (name != nullptr ? ", got '" + names[k] + "' (known: " + known + ")" : std::string()));
      }
    }
    if (names[0] == names[1]) {
      throw ConfigError(location_of(r.file(), p), "key 'collision_exclude': a pair names one joint or link twice");
    }
    if (joints[0] >= 0 && joints[1] >= 0) {
      if (joints[0] == joints[1]) {
        throw ConfigError(location_of(r.file(), p), "key 'collision_exclude': a pair names one joint twice");
      }
      spec.collision_exclude.emplace_back(joints[0], joints[1]);
      continue;
    }
    // A link by name (or a joint, standing for the link it moves).
    for (std::size_t k = 0; k < 2; ++k) {
      if (joints[k] >= 0) {
        const JointSpec& jt = spec.joints[static_cast<std::size_t>(joints[k])];
        names[k] = jt.link_name.empty() ? jt.name : jt.link_name;
      }
    }
    spec.collision_exclude_bodies.emplace_back(names[0], names[1]);
  }
}

}  // namespace redres

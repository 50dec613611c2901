// A bare URDF file loaded as a robot (`redres robot FILE.urdf`): a robot file with only `urdf`, `base_link` and
// `tip_link`, its chain by default from the root link to the arm's tip.

#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "parsers/urdf.hpp"
#include "redres/parsers/robot_toml.hpp"

namespace redres {

RobotModel load_urdf_robot(const std::filesystem::path& urdf, const std::string& base_link,
                           const std::string& tip_link) {
  std::string base = base_link, tip = tip_link;
  if (base.empty() || tip.empty()) {
    std::pair<std::string, std::string> chain;
    try {
      chain = default_urdf_chain(urdf);
    } catch (const UrdfError& e) {
      throw std::runtime_error(e.what());
    }
    if (base.empty()) base = chain.first;
    if (tip.empty()) tip = chain.second;
  }
  auto doc = std::make_shared<TomlFile>();
  doc->path = urdf;  // the keys below are the command line's; paths resolve beside the URDF
  doc->root.insert("urdf", std::filesystem::absolute(urdf).string());
  doc->root.insert("base_link", base);
  doc->root.insert("tip_link", tip);
  return load_robot(TableReader::root(doc, "robot"));
}

}  // namespace redres

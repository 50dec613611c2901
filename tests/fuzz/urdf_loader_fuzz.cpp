// libFuzzer target: the URDF reader (docs/fuzzing.md).
//
// The input is a URDF file. It is written into the scratch directory (fuzz_util.hpp) as input.urdf and read with
// read_urdf_chain from the first to the last <link> the text names (so that a mutated shipped URDF still yields its
// chain), the reader behind a robot file's `urdf` key: the pre-parse bounds (depth, element count), urdfdom, the
// tree checks (cycles, two parents, self-parents), the names and the physical ranges. When the chain reads, a robot
// file naming it is written and loaded with load_robot (its [[joints]] and [[links]] merging, RobotModel's
// checks), and a robot that loads is evaluated as robot_loader_fuzz evaluates one (robot_evaluation.hpp).
//
// Exceptions derived from std::exception are the reader's answers to bad input and are expected. Crashes,
// sanitizer reports, leaks, timeouts and out-of-memory are findings (a cycle of joints once grew memory for ever,
// and 50,000 nested elements overflowed TinyXML's stack).

#include <cstdint>
#include <exception>
#include <fstream>
#include <string>

#include "fuzz_util.hpp"
#include "parsers/urdf.hpp"
#include "redres/common/error.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "robot_evaluation.hpp"

namespace {

// The value of the name="..." attribute of each <link ...> of the text, in order (a rough scan; the reader's own
// scan decides what the file is).
std::vector<std::string> link_names(const std::string& xml) {
  std::vector<std::string> out;
  for (std::size_t at = xml.find("<link"); at != std::string::npos; at = xml.find("<link", at + 5)) {
    const std::size_t end = xml.find('>', at);
    const std::size_t name = xml.find("name=\"", at);
    if (end == std::string::npos || name == std::string::npos || name > end) continue;
    const std::size_t close = xml.find('"', name + 6);
    if (close == std::string::npos || close > end) continue;
    out.push_back(xml.substr(name + 6, close - name - 6));
  }
  return out;
}

// `text` as a TOML basic string.
std::string toml_string(const std::string& text) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out = "\"";
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      (out += '\\') += ch;
    } else if (c < 0x20 || c == 0x7f) {
      ((out += "\\u00") += kHex[c >> 4]) += kHex[c & 0xF];
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto& scratch = redres::fuzz::scratch();
  const auto file = scratch.write("input.urdf", data, size);
  const std::string xml(reinterpret_cast<const char*>(data), size);
  const std::vector<std::string> names = link_names(xml);
  const std::string base = names.empty() ? "base_link" : names.front();
  const std::string tip = names.empty() ? "tool0" : names.back();
  try {
    const redres::ChainDescription chain = redres::read_urdf_chain(file, base, tip);
    if (!redres::is_utf8(base) || !redres::is_utf8(tip)) return 0;  // a TOML file cannot name them
    std::string robot = "urdf = \"input.urdf\"\nbase_link = " + toml_string(base) + "\ntip_link = " + toml_string(tip) +
                        "\nname = \"fuzzed\"\n";
    for (const redres::ChainJoint& j : chain.joints) {
      // Continuous joints, and joints without limits or a velocity, get both, so that the chain loads.
      if (!redres::is_utf8(j.spec.name)) return 0;
      if (j.continuous || !(j.spec.lower < j.spec.upper) || !(j.velocity > 0.0)) {
        robot += "[[joints]]\nname = " + toml_string(j.spec.name) +
                 "\nlimits = [-3.0, 3.0]\nvelocity_limit = { type = \"constant\", lower = -1.0, upper = 1.0 }\n";
      }
    }
    for (const redres::ChainLink& l : chain.links) {
      // Mesh collision elements, which redres does not read, are replaced by none.
      if (!l.meshes.empty() && redres::is_utf8(l.name)) robot += "[[links]]\nname = " + toml_string(l.name) + "\n";
    }
    const auto robot_file =
        scratch.write("input_robot.toml", reinterpret_cast<const std::uint8_t*>(robot.data()), robot.size());
    const redres::RobotModel model = redres::load_robot(robot_file);
    redres::fuzz::evaluate_robot(model);
  } catch (const std::exception&) {
    // Bad input, reported as a UrdfError, ConfigError or std::invalid_argument.
  }
  return 0;
}

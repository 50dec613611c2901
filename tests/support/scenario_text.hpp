#pragma once
// Scenario and scheme texts for the tests that write their own: the parts those texts share, so that a test spells
// out only what it varies. Each helper gives exactly the lines it is named for (the tests check errors at file
// line numbers, so no helper adds a blank line or a comment).

#include <memory>
#include <stdexcept>
#include <string>

#include "redres/config/toml_reader.hpp"
#include "redres/control/scheme.hpp"
#include "test_util.hpp"

namespace redres {

/// The line `robot = "<source tree>/robots/<file>"`: a robot of the repository by its absolute path, so that the
/// scenario may be written into any directory.
inline std::string robot_line(const std::string& file) {
  return "robot = \"" + source_path("robots/" + file).string() + "\"\n";
}

/// One [[objectives]] entry: its `type`, then `keys` (whole TOML lines, each ending in a newline).
inline std::string objective_entry(const std::string& type, const std::string& keys = "") {
  return "[[objectives]]\ntype = \"" + type + "\"\n" + keys;
}

/// One [[constraints]] entry: its `type`, then `keys` (whole TOML lines, each ending in a newline).
inline std::string constraint_entry(const std::string& type, const std::string& keys = "") {
  return "[[constraints]]\ntype = \"" + type + "\"\n" + keys;
}

/// The end of the planar circle runs of the failure and output tests: a circle of `radius` (m, as written), MVN with
/// the task tracked at gain 8 inside the joints' velocity limits, and a [solver] table of the `solver` lines, last so
/// that a test may append a key to it.
inline std::string circle_tracking(const std::string& radius, const std::string& solver) {
  return "[path]\ntype = \"circle\"\nradius = " + radius + "\n" + objective_entry("min_velocity_norm") +
         constraint_entry("task_tracking", "gain = 8.0\n") + constraint_entry("joint_velocity_limits") + "[solver]\n" +
         solver;
}

/// The text of a shipped scenario, configs/<file>, with the robot files it names relative to configs/
/// ("../robots/...") named by their absolute paths, so that the text (edited or not) may be written into any
/// directory. Throws std::runtime_error when it names none: the test would not load the robot it means.
inline std::string shipped_scenario_text(const std::string& file) {
  std::string text = read_text(source_path("configs/" + file));
  const std::string relative = "\"../robots/";
  const std::string absolute = "\"" + source_path("robots").string() + "/";
  if (text.find(relative) == std::string::npos) {
    throw std::runtime_error("configs/" + file + " names no robot as \"../robots/...\"");
  }
  for (std::size_t at = text.find(relative); at != std::string::npos; at = text.find(relative, at + absolute.size())) {
    text.replace(at, relative.size(), absolute);
  }
  return text;
}

/// The scheme of a text of [[objectives]], [[constraints]] and an optional [scheme] for `robot`, read as the file
/// `name` (the name its errors give).
inline std::unique_ptr<Scheme> scheme_from_text(const std::string& text, const RobotModel& robot,
                                                const std::string& name = "scheme.toml") {
  const auto file = parse_toml_string(text, name);
  return std::make_unique<Scheme>(Scheme::from_toml(TableReader::root(file), robot));
}

}  // namespace redres

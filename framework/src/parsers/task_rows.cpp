// A robot's or scenario's `task`: the rows of the pose the end effector tracks.

#include <algorithm>
#include <string>
#include <vector>

#include "common/text.hpp"
#include "redres/parsers/robot_toml.hpp"

namespace redres {

void read_task(const TableReader& r, RobotSpec& spec) {
  if (!r.has("task")) return;
  if (!r.raw()["task"].is_array()) {
    spec.task = r.choice("task", {"position", "pose"}) == "position" ? TaskRows::kPosition : TaskRows::kPose;
    spec.task_axes.clear();
    return;
  }
  const std::vector<std::string>& all = pose_row_names(spec.kind);
  std::vector<std::string> axes = r.strings("task");
  if (axes.empty()) r.fail("task", "expected \"position\", \"pose\" or a non-empty array of rows from " + join(all));
  std::ptrdiff_t previous = -1;
  for (const std::string& name : axes) {
    const auto it = std::find(all.begin(), all.end(), name);
    if (it == all.end()) {
      r.fail("task", "expected rows of the " + std::string(to_string(spec.kind)) + " pose (" + join(all) + "), got '" +
                         name + "'");
    }
    if (it - all.begin() <= previous) {
      r.fail("task", "expected each row once, in the order " + join(all) + " ('" + name + "' is out of place)");
    }
    previous = it - all.begin();
  }
  spec.task_axes = std::move(axes);
}

}  // namespace redres

// Loading a scenario file (load_scenario; its keys are read through the schema in scenario_schema.cpp) and what a
// loaded scenario gives (its obstacles, its MuJoCo model, its number of steps).

#include "redres/run/scenario.hpp"

#include "run/scenario_reading.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "config/overrides.hpp"
#include "redres/plant/mujoco_model.hpp"
#include "redres/run/plugin_output.hpp"

namespace redres {

using scenario_detail::ScenarioReading;
using scenario_detail::solve_start;

std::vector<ShapeSpec> scenario_obstacles(const Scenario& s, bool inactive) {
  std::vector<ShapeSpec> out;
  for (const auto& c : s.scheme->constraints()) {
    const PluginOutput* output = output_of(*c);
    if (output != nullptr && (inactive || c->active())) output->scene_obstacles(out);
  }
  return out;
}

std::string scenario_mjcf(const Scenario& s) {
  if (s.plant.kind != "mujoco")
    throw std::invalid_argument("scenario '" + s.name + "' runs on the kinematic plant: set [plant] kind = \"mujoco\"");
  MjcfOptions options;
  options.plant = s.plant;
  options.obstacles = scenario_obstacles(s, true);
  return mjcf_from_robot(*s.robot, options);
}

int Scenario::steps() const {
  const double ratio = duration / tau;
  REDRES_REQUIRE(ratio >= 0.5 && ratio <= kMaxSteps, "Scenario::steps",
                 "duration / step is in [1, " + std::to_string(static_cast<long long>(kMaxSteps)) + "] (got " +
                     std::to_string(ratio) + ")");
  return static_cast<int>(std::lround(ratio));
}

Scenario load_scenario(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  const std::shared_ptr<TomlFile> parsed = parse_toml_file(file);
  apply_overrides(parsed->root, overrides);
  const std::shared_ptr<const TomlFile> doc = parsed;
  const TableReader r = TableReader::root(doc, "scenario");

  ScenarioReading reading;
  reading.s.source = file.string();
  reading.s.name = file.stem().string();
  read_config(r, ScenarioReading::schema(), reading);
  r.finish();
  if (reading.s.label.empty()) reading.s.label = reading.s.name;
  if (reading.ik) solve_start(reading.s, *reading.ik, reading.ik_where);
  Scenario s = std::move(reading.s);
  s.record = reading.output.record;
  s.plots = reading.output.plots;
  s.animate = reading.output.animate;
  return s;
}

}  // namespace redres

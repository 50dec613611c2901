#include "redres/run/collision_output.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "redres/common/error.hpp"
#include "redres/run/trajectory.hpp"

namespace redres {

namespace {
const PairDistances& distances_of(const PluginData* data, const Plugin& self) {
  REDRES_REQUIRE(data != nullptr, "PairOutput", "constraint '" + self.name() + "' has the data of the run");
  return static_cast<const PairData&>(*data).distances;
}
}  // namespace

PairOutput::PairOutput(const Plugin& self, std::string minimum, std::string active)
    : self_(&self), minimum_(std::move(minimum)), active_(std::move(active)) {}

void PairOutput::record(const PluginData* data, double* values) const { distances_of(data, *self_).record(values); }

void PairOutput::summarise(const RobotModel& /*robot*/, const Trajectory& run, const PluginData* data,
                           std::vector<Metric>& out) const {
  const PairDistances& distances = distances_of(data, *self_);
  const std::size_t cd = own_column(run, self_->name(), minimum_), ca = own_column(run, self_->name(), active_);
  double low = std::numeric_limits<double>::infinity();
  double steps = 0.0, measured = 0.0;
  for (std::size_t r = 0; r < run.size(); ++r) {
    low = std::min(low, run(r, cd));
    steps += run(r, ca) > 0.0 ? 1.0 : 0.0;
    measured += std::isfinite(run(r, cd)) ? 1.0 : 0.0;
  }
  // A step whose pairs the broadphase all found beyond the influence distance measures none (its column reads inf);
  // a run that never measured one is stated as d_i, which every pair stayed beyond, with steps_measured = 0.
  out.push_back({minimum_, {std::isfinite(low) ? low : distances.damper().influence_distance}, "m"});
  out.push_back({"steps_measured", {measured}, ""});
  out.push_back({"steps_with_active_rows", {steps}, ""});
  out.push_back({"fcl_failures", {static_cast<double>(distances.failures())}, ""});
  out.push_back(
      {"contributions_short_of_rows", {static_cast<double>(static_cast<const PairData&>(*data).short_of_rows)}, ""});
  out.push_back({"safety_distance", {distances.damper().safety_distance}, "m"});
  out.push_back({"influence_distance", {distances.damper().influence_distance}, "m"});
}

}  // namespace redres

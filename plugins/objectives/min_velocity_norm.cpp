/// `min_velocity_norm`: the minimum-velocity-norm term x'x/2 (MVN; with no other objective this is the paper's
/// p = 0 scheme). Adds W += weight * I. TOML keys: only the common ones (`name`, `weight` = 1, `active` = true).

#include "redres/plugin.hpp"

namespace redres {
namespace {

class MinVelocityNorm final : public Objective {
 public:
  explicit MinVelocityNorm(const TableReader& config) : Objective(config) {}

 private:
  void add_to(const Context& /*ctx*/, QpBuilder& builder) const override { builder.add_identity(); }
  void write_config(toml::table& /*out*/) const override {}
};

const bool kRegistered = objective_registry().add({
    "min_velocity_norm",
    "x'x/2: W += weight * I (MVN, the paper's p = 0)",
    {},
    [](const TableReader& r, const RobotModel& /*robot*/) -> std::unique_ptr<Objective> {
      return std::make_unique<MinVelocityNorm>(r);
    },
});

}  // namespace
}  // namespace redres

#include "redres/parsers/velocity_limit_registry.hpp"

namespace redres {

VelocityLimitRegistry& velocity_limit_registry() {
  static VelocityLimitRegistry registry("velocity-limit law");
  return registry;
}

std::unique_ptr<VelocityLimitLaw> make_velocity_limit(const TableReader& table) {
  auto law = velocity_limit_registry().create(table);
  table.finish();
  return law;
}

}  // namespace redres

#include "redres/run/plants.hpp"

#include <stdexcept>

#include "run/builtin_plants.hpp"

namespace redres {

bool PlantRegistry::add(PlantType type) {
  if (type.name.empty() || !type.make) throw std::invalid_argument("PlantRegistry::add: a plant has a name and a make");
  if (find(type.name) != nullptr) {
    throw std::invalid_argument("PlantRegistry::add: a plant named '" + type.name + "' is registered already");
  }
  types_.push_back(std::move(type));
  return true;
}

const PlantType* PlantRegistry::find(const std::string& name) const {
  for (const PlantType& t : types_) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

const PlantType& PlantRegistry::at(const std::string& name) const {
  if (const PlantType* t = find(name)) return *t;
  std::string names;
  for (const PlantType& t : types_) names += (names.empty() ? "'" : ", '") + t.name + "'";
  throw std::invalid_argument("unknown plant '" + name + "'; the plants are " + names);
}

PlantRegistry& plant_registry() {
  static PlantRegistry registry = [] {
    PlantRegistry r;
    r.add(kinematic_plant_type());
    r.add(mujoco_plant_type());
    return r;
  }();
  return registry;
}

}  // namespace redres

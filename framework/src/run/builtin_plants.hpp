#pragma once
// The plants built into redres (private to run/), registered by plant_registry() itself so that a static library
// cannot drop them: the kinematic plant (kinematic_plant.cpp) and the MuJoCo plant (mujoco_run_plant.cpp).

#include "redres/run/plants.hpp"

namespace redres {

[[nodiscard]] PlantType kinematic_plant_type();
[[nodiscard]] PlantType mujoco_plant_type();

}  // namespace redres

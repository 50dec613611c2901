// The [plant] table in any build: a scenario asking for MuJoCo loads where redres has MuJoCo, and where it has not
// the error names the Debian package to install (docs/plant.md). The kinematic plant is the default and its files
// say nothing of a plant.

#include <string>

#include <gtest/gtest.h>

#include "redres/plant/mujoco_model.hpp"
#include "redres/plant/mujoco_plant.hpp"
#include "redres/run/scenario.hpp"

namespace redres {
namespace {

TEST(PlantConfig, TheKinematicPlantIsTheDefault) {
  const Scenario s = load_scenario("configs/paper_r_tvcmm.toml");
  EXPECT_EQ(s.plant.kind, std::string("kinematic"));
}

TEST(PlantConfig, AScenarioAskingForMujocoLoadsOrNamesThePackageToInstall) {
  if (mujoco_available()) {
    const Scenario s = load_scenario("configs/paper_r_mujoco.toml");
    EXPECT_EQ(s.plant.kind, std::string("mujoco"));
    EXPECT_EQ(s.plant.timestep, 0.001);
  } else {
    try {
      (void)load_scenario("configs/paper_r_mujoco.toml");
      FAIL() << "a MuJoCo scenario loaded in a build without MuJoCo";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("libmujoco-dev"), std::string::npos) << what;
      EXPECT_NE(what.find("key 'kind'"), std::string::npos) << what;
    }
    PlantConfig config;
    config.kind = "mujoco";
    const Scenario s = load_scenario("configs/paper_r_tvcmm.toml");
    EXPECT_THROW(MujocoPlant(*s.robot, config, 0.01, {}, s.theta0), std::runtime_error);
  }
}

}  // namespace
}  // namespace redres

#pragma once
// The shipped scenarios that run on the MuJoCo plant, in a build without MuJoCo (docs/plant.md): a test that runs
// every configs/*.toml leaves them out there, after checking that loading one is refused with the Debian package to
// install. With MuJoCo they are run like every other.

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "redres/config/toml_reader.hpp"
#include "redres/plant/mujoco_model.hpp"
#include "redres/run/scenario.hpp"

namespace redres {

/// True when `config` asks for the MuJoCo plant ([plant] kind = "mujoco") and this build has no MuJoCo; it then also
/// checks (a test failure otherwise) that loading it is a ConfigError naming libmujoco-dev.
inline bool mujoco_config_without_mujoco(const std::filesystem::path& config) {
  if (mujoco_available()) return false;
  const auto file = parse_toml_file(config);
  if (file->root["plant"]["kind"].value_or(std::string()) != "mujoco") return false;
  try {
    (void)load_scenario(config);
    ADD_FAILURE() << config << " asks for MuJoCo and loaded in a build without it";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("libmujoco-dev"), std::string::npos) << e.what();
  }
  return true;
}

}  // namespace redres

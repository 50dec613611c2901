// Golden runs: every configs/*.toml is run, and its summary figures must stay within stated tolerances of the
// figures recorded in tests/golden/<name>.json. To record new goldens after an intended change:
//   REDRES_UPDATE_GOLDEN=1 build/release/bin/redres_tests --gtest_filter='Golden*'
// and review the diff.
//
// Tolerances: final theta 1e-6 rad; manipulability (initial, final, mean, min, max) 1e-6 relative; joint-velocity
// norms 1e-6 rad/s absolute; position errors 10 % relative + 1e-8 m (they sit near the solver's tolerance); the
// number of failed steps exactly; on the MuJoCo plant, the contacts exactly and the largest torques 1e-3 relative.

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "mujoco_configs.hpp"
#include "redres/run/run_summary.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

std::vector<std::string> configs() {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(source_path("configs"))) {
    if (e.path().extension() == ".toml") out.push_back(e.path().stem().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

class Golden : public ::testing::TestWithParam<std::string> {};

TEST_P(Golden, SummaryStaysWithinTolerances) {
  const std::string name = GetParam();
  if (mujoco_config_without_mujoco(source_path("configs/" + name + ".toml"))) return;  // its refusal was checked
  Scenario s = load_scenario(source_path("configs/" + name + ".toml"));
  const RunResult run = simulate(s);
  const RunSummary got = summarise(s, run);
  const std::filesystem::path file = source_path("tests/golden/" + name + ".json");
  if (std::getenv("REDRES_UPDATE_GOLDEN") != nullptr) {
    std::filesystem::create_directories(file.parent_path());
    nlohmann::json keep = nlohmann::json::parse(to_json(got));
    keep.erase("wall_time_s");
    keep.erase("source");
    keep["plant"].erase("control_step_us");  // timings: never golden
    keep["plant"].erase("mujoco_step_us");
    std::ofstream(file) << keep.dump(2) << "\n";
    GTEST_SKIP() << "recorded " << file;
  }
  std::ifstream in(file);
  ASSERT_TRUE(in) << "no golden file " << file << "; record it with REDRES_UPDATE_GOLDEN=1";
  const nlohmann::json want = nlohmann::json::parse(in);

  EXPECT_EQ(got.steps, want["steps"].get<int>());
  EXPECT_EQ(got.solver.failures, want["solver"]["failures"].get<int>());
  EXPECT_EQ(got.solver.engine, want["solver"]["engine"].get<std::string>());
  const ManipulabilityStats& w = got.manipulability;
  const std::pair<const char*, double> ws[] = {
      {"initial", w.initial}, {"final", w.final}, {"mean", w.mean}, {"min", w.min}, {"max", w.max}};
  for (const auto& [k, v] : ws) {
    const double expected = want["manipulability"][k];
    EXPECT_NEAR(v, expected, 1e-6 * std::abs(expected)) << "manipulability." << k;
  }
  EXPECT_NEAR(got.initial_joint_velocity_norm, want["initial_joint_velocity_norm"].get<double>(), 1e-6);
  EXPECT_NEAR(got.final_joint_velocity_norm, want["final_joint_velocity_norm"].get<double>(), 1e-6);
  const double e_max = want["max_position_error"], e_final = want["final_position_error"];
  EXPECT_NEAR(got.max_position_error, e_max, 0.1 * e_max + 1e-8);
  EXPECT_NEAR(got.final_position_error, e_final, 0.1 * e_final + 1e-8);
  EXPECT_LE(got.max_joint_angle_violation, 0.0);
  EXPECT_LE(got.max_joint_velocity_violation, 0.0);
  // The MuJoCo plant: its contacts exactly, its largest torques to 1e-3 relative.
  EXPECT_EQ(got.plant_kind, want["plant"]["kind"].get<std::string>());
  EXPECT_EQ(got.plant.max_contacts, want["plant"]["max_contacts"].get<int>());
  ASSERT_EQ(got.plant.max_torque.size(), want["plant"]["max_torque"].size());
  for (std::size_t j = 0; j < got.plant.max_torque.size(); ++j) {
    const double expected = want["plant"]["max_torque"][j];
    EXPECT_NEAR(got.plant.max_torque[j], expected, 1e-3 * expected + 1e-9) << "plant.max_torque, joint " << j + 1;
  }
  ASSERT_EQ(got.final_theta.size(), want["final_theta"].size());
  for (std::size_t j = 0; j < got.final_theta.size(); ++j) {
    EXPECT_NEAR(got.final_theta[j], want["final_theta"][j].get<double>(), 1e-6) << "joint " << j + 1;
  }
}

INSTANTIATE_TEST_SUITE_P(Configs, Golden, ::testing::ValuesIn(configs()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

}  // namespace
}  // namespace redres

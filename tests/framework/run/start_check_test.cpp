// The checked start (issue 26): `redres validate` and step 0 of `redres run` refuse a theta(0) in collision, singular
// for the task or away from the path's start, at once and with every problem named; every shipped scenario passes.

#include <chrono>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "mujoco_configs.hpp"
#include "redres/run/simulation.hpp"
#include "redres/run/start_check.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

TEST(StartCheck, EveryShippedScenarioStartsWell) {
  int checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(source_path("configs"))) {
    if (entry.path().extension() != ".toml") continue;
    SCOPED_TRACE(entry.path().filename().string());
    if (mujoco_config_without_mujoco(entry.path())) continue;
    Scenario s = load_scenario(entry.path());
    const StartReport r = check_start(s);
    EXPECT_TRUE(r.ok()) << r.text();
    EXPECT_GE(r.sigma_min, kSingularTolerance);
    EXPECT_LE(r.path_offset, s.max_task_error);
    ++checked;
  }
  EXPECT_GE(checked, 15);
}

TEST(StartCheck, AStartInCollisionNamesThePairAndDepthAtOnce) {
  Scenario s = load_scenario(source_path("configs/panda_table_pole.toml"),
                             {"constraints.3.obstacles=[{ shape = \"box\", size = [2.0, 2.0, 0.1], xyz = [0.0, 0.0, "
                              "0.3] }]"});
  const auto start = std::chrono::steady_clock::now();
  const StartReport r = check_start(s);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  ASSERT_EQ(r.problems.size(), 1u) << r.text();
  EXPECT_EQ(r.problems[0].kind, "collision");
  EXPECT_NE(r.problems[0].message.find("obstacle 1"), std::string::npos) << r.text();
  EXPECT_NE(r.problems[0].message.find("at distance -"), std::string::npos) << r.text();
  EXPECT_THROW(require_good_start(s), StartError);
  // The run it saves: every step of it fails.
  const RunResult run = simulate(s);
  EXPECT_GT(run.failures, 0);
}

TEST(StartCheck, ASingularStartIsRefusedWithANearbyRegularConfiguration) {
  Scenario s = load_scenario(source_path("configs/iiwa_pose_circle.toml"), {"theta0=[0, 0, 0, 0, 0, 0, 0]"});
  const StartReport r = check_start(s);
  ASSERT_EQ(r.problems.size(), 1u) << r.text();
  EXPECT_EQ(r.problems[0].kind, "singular");
  EXPECT_LT(r.sigma_min, kSingularTolerance);
  EXPECT_LT(r.w, 1e-12);
  // The suggestion is a configuration that is regular: load it and check it.
  const std::string& text = r.problems[0].suggestion;
  const auto at = text.find("theta0 = ");
  ASSERT_NE(at, std::string::npos) << text;
  const std::string theta0 = text.substr(at + 9, text.find(']', at) - at - 8);
  Scenario again = load_scenario(source_path("configs/iiwa_pose_circle.toml"), {"theta0=" + theta0});
  const StartReport fixed = check_start(again);
  EXPECT_TRUE(fixed.ok()) << theta0 << ": " << fixed.text();
}

TEST(StartCheck, APathThatStartsAwayFromTheEndEffectorIsRefused) {
  Scenario s = load_scenario(source_path("configs/panda_helix.toml"),
                             {"path.placement=\"absolute\"", "path.origin=[0.9, 0.0, 0.3]"});
  const StartReport r = check_start(s);
  ASSERT_EQ(r.problems.size(), 1u) << r.text();
  EXPECT_EQ(r.problems[0].kind, "path");
  EXPECT_GT(r.path_offset, 0.5);
  EXPECT_NE(r.problems[0].message.find("max_task_error"), std::string::npos);
}

TEST(StartCheck, EveryProblemIsReportedTogether) {
  // Singular and away from the path at once.
  Scenario s =
      load_scenario(source_path("configs/iiwa_pose_circle.toml"),
                    {"theta0=[0, 0, 0, 0, 0, 0, 0]", "path.placement=\"absolute\"", "path.origin=[0.9, 0.0, 0.3]"});
  const StartReport r = check_start(s);
  ASSERT_EQ(r.problems.size(), 2u) << r.text();
  try {
    require_good_start(s);
    FAIL() << "expected StartError";
  } catch (const StartError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("singular"), std::string::npos) << what;
    EXPECT_NE(what.find("path starts"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace redres

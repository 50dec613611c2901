// Finished work is never discarded, and every figure means what it says (the second reliability probe): a run whose
// collision constraint never measured a pair states its distance instead of failing at the end; a scene of 10,000
// obstacles keeps a QP of max_rows shared rows; self_collision with nothing to check is refused; and a run whose
// task error exceeds [solver] max_task_error is not a success.

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_util.hpp"
#include "redres/control/controller.hpp"
#include "redres/run/scenario.hpp"
#include "scenario_text.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

TEST(Measurement, ARunThatNeverMeasuredAPairStatesItsDistance) {
  const auto dir = scratch("never_measured");
  const Cli r = redres("run configs/paper_r_obstacle.toml --quiet --out '" + (dir / "out").string() +
                       "' --set 'constraints.3.obstacles=[{shape=\"sphere\", radius=0.05, xyz=[5.0, 5.0, 0.0]}]' "
                       "--set 'constraints.3.broadphase=\"always\"'");
  EXPECT_EQ(r.code, 0) << r.out;
  const nlohmann::json s = read_summary(dir / "out");
  const nlohmann::json& m = s["metrics"]["obstacle_avoidance"];
  EXPECT_EQ(m["steps_measured"].get<double>(), 0.0) << m;
  EXPECT_EQ(m["min_obstacle_distance"].get<double>(), m["influence_distance"].get<double>()) << m;
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "trajectory.csv"));
  std::filesystem::remove_all(dir);
}

TEST(Measurement, SelfCollisionWithEveryPairLeftOutIsRefused) {
  const auto dir = scratch_dir("nothing_to_check");
  std::ofstream(dir / "two.toml") << R"(name = "two"
kind = "planar"
[[joints]]
name = "a"
length = 0.3
limits = [-1, 1]
velocity_limit = { type = "constant", lower = -1, upper = 1 }
collision = [{ shape = "capsule", radius = 0.02 }]
[[joints]]
name = "b"
length = 0.3
limits = [-1, 1]
velocity_limit = { type = "constant", lower = -1, upper = 1 }
collision = [{ shape = "capsule", radius = 0.02 }]
)";
  std::ofstream(dir / "s.toml") << "robot = \"two.toml\"\nduration = 1.0\nstep = 0.1\n[path]\ntype = \"line\"\n"
                                << "delta = [0.01, 0.0]\n"
                                << objective_entry("min_velocity_norm") << constraint_entry("task_tracking")
                                << constraint_entry("self_collision");
  const Cli r = redres("validate '" + (dir / "s.toml").string() + "'");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("robot 'two' has no pair of link shapes to check"), std::string::npos) << r.out;
  std::filesystem::remove_all(dir);
}

TEST(Measurement, TenThousandObstaclesShareMaxRowsRows) {
  const auto dir = scratch_dir("many_obstacles");
  std::string text = shipped_scenario_text("paper_r_obstacle.toml");
  const std::string one = R"(obstacles = [{ shape = "sphere", radius = 0.02, xyz = [0.551, 0.492, 0.0] }])";
  ASSERT_NE(text.find(one), std::string::npos);
  std::string many = "obstacles = [" + one.substr(one.find('{'), one.rfind('}') - one.find('{') + 1);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> far(2.0, 4.0);
  for (int k = 1; k < 10000; ++k) {
    many += ", { shape = \"sphere\", radius = 0.01, xyz = [" + std::to_string(far(rng)) + ", " +
            std::to_string(far(rng)) + ", 0.0] }";
  }
  text.replace(text.find(one), one.size(), many + "]");
  std::ofstream(dir / "many.toml") << text;
  Scenario s = load_scenario(dir / "many.toml", {"duration=0.5"});
  const auto controller = Controller::from_scenario(s);
  EXPECT_EQ(controller->qp().m_in(), 64) << "6 link shapes x 10,000 obstacles share max_rows = 64 rows";
  StepOutput out = controller->make_output();
  controller->step(s.theta0, 0.0, out);
  EXPECT_EQ(out.info.status, SolverStatus::kSolved) << out.info.diagnosis;
  std::filesystem::remove_all(dir);
}

TEST(Measurement, ARunBeyondItsTaskErrorBoundIsNoSuccess) {
  const auto dir = scratch("task_error");
  const Cli r = redres("run configs/paper_r_fast.toml --quiet --out '" + (dir / "out").string() +
                       "' --set solver.max_task_error=1e-12");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("the task was not tracked: max position error"), std::string::npos) << r.out;
  const nlohmann::json s = read_summary(dir / "out");
  EXPECT_TRUE(s["task_error_exceeded"].get<bool>());
  EXPECT_EQ(s["solver"]["failures"].get<int>(), 0) << "every step solved, and still no success";
  const Cli ok = redres("run configs/paper_r_fast.toml --quiet --out '" + (dir / "ok").string() + "'");
  EXPECT_EQ(ok.code, 0) << ok.out;
  EXPECT_FALSE(read_summary(dir / "ok")["task_error_exceeded"].get<bool>());
  std::filesystem::remove_all(dir);
}

TEST(Measurement, ASweepVariationBeyondItsTaskErrorBoundIsNotOk) {
  const auto dir = scratch_dir("sweep_task_error");
  std::ofstream(dir / "bound.toml") << "name = \"bound\"\nscenario = \""
                                    << source_path("configs/paper_r_fast.toml").string()
                                    << "\"\n[[vary]]\nkey = \"solver.max_task_error\"\nvalues = [1e-12, 1.0]\n";
  const Cli r = redres("sweep '" + (dir / "bound.toml").string() + "' --quiet --out '" + (dir / "out").string() + "'");
  EXPECT_EQ(r.code, 1) << r.out;
  const std::string table = read_text(dir / "out" / "sweep.csv");
  EXPECT_NE(table.find(",task_error_exceeded,max position error "), std::string::npos) << table;
  EXPECT_NE(table.find(",ok,"), std::string::npos) << table;
  std::filesystem::remove_all(dir);
}
}  // namespace
}  // namespace redres

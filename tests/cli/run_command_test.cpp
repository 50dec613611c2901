// The scenario commands of the CLI: run, validate, compare, --set, exit codes, and the output formats of
// docs/output_formats.md.

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_util.hpp"
#include "scenario_text.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

std::string first_line(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  return line;
}

TEST(CliScenario, RunWritesTheTrajectoryAndSummaryOfOutputFormats) {
  const auto dir = scratch("run");
  const Cli r = redres("run configs/paper_r_mvn.toml --out '" + dir.string() + "' --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  std::string expected = "t";
  for (const char* prefix : {"theta_", "theta_dot_", "lo_", "hi_"}) {
    for (int j = 1; j <= 6; ++j) expected += "," + std::string(prefix) + std::to_string(j);
  }
  expected += ",rd_x,rd_y,r_x,r_y,position_error,manipulability,solver_iterations,solver_residual";
  EXPECT_EQ(first_line(dir / "trajectory.csv").rfind(expected, 0), 0u) << first_line(dir / "trajectory.csv");
  const nlohmann::json s = read_summary(dir);
  for (const char* k :
       {"steps", "tau", "duration", "max_position_error", "final_position_error", "initial_joint_velocity_norm",
        "final_joint_velocity_norm", "manipulability", "max_joint_angle_violation", "max_joint_velocity_violation",
        "final_theta", "solver", "wall_time_s"}) {
    EXPECT_TRUE(s.contains(k)) << k;
  }
  for (const char* k : {"initial", "final", "min", "mean", "max"}) EXPECT_TRUE(s["manipulability"].contains(k)) << k;
  for (const char* k : {"engine", "mean_iterations", "max_iterations", "max_residual", "failures"}) {
    EXPECT_TRUE(s["solver"].contains(k)) << k;
  }
  EXPECT_EQ(s["steps"], 4000);
  EXPECT_EQ(s["final_theta"].size(), 6u);
  // One line per step, t = 0 .. T.
  std::ifstream csv(dir / "trajectory.csv");
  std::size_t lines = 0;
  for (std::string l; std::getline(csv, l);) ++lines;
  EXPECT_EQ(lines, 4002u);
  std::filesystem::remove_all(dir);
}

std::size_t line_count(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::size_t lines = 0;
  for (std::string l; std::getline(in, l);) ++lines;
  return lines;
}

// --record every=N keeps rows 0, N, 2N, ... and the last; --record none writes the summary only (and removes an
// earlier run's trajectory); the summary is the same in every case, since it uses every step; bad values are exit 2.
TEST(CliScenario, RecordKeepsEveryNthRowOrNoneWhileTheSummaryUsesEveryStep) {
  const auto dir = scratch("record");
  const auto summary_of = [&dir] {
    nlohmann::json s = read_summary(dir);
    s.erase("wall_time_s");
    return s;
  };
  ASSERT_EQ(redres("run configs/paper_r_mvn.toml --quiet --out '" + dir.string() + "'").code, 0);
  const nlohmann::json all = summary_of();
  ASSERT_EQ(redres("run configs/paper_r_mvn.toml --quiet --record every=7 --out '" + dir.string() + "'").code, 0);
  EXPECT_EQ(line_count(dir / "trajectory.csv"), 1u + 4000 / 7 + 1 + 1) << "header, rows 0, 7, ..., 3997, and 4000";
  EXPECT_EQ(summary_of(), all);
  std::ifstream csv(dir / "trajectory.csv");
  std::string line, last;
  while (std::getline(csv, line)) last = line;
  EXPECT_EQ(last.rfind("40,", 0), 0u) << "the last row is t = T: " << last.substr(0, 20);
  ASSERT_EQ(redres("run configs/paper_r_mvn.toml --quiet --record none --out '" + dir.string() + "'").code, 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "trajectory.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir / "frames.csv"));
  EXPECT_EQ(summary_of(), all);
  for (const char* bad : {"every=0", "every=x", "some", "every=3x"}) {
    const Cli r =
        redres("run configs/paper_r_mvn.toml --quiet --record " + std::string(bad) + " --out '" + dir.string() + "'");
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_NE(r.out.find("expected \"all\", \"none\" or \"every=N\""), std::string::npos) << r.out;
  }
  const Cli plots = redres("run configs/paper_r_mvn.toml --quiet --record none --plots --out '" + dir.string() + "'");
  EXPECT_EQ(plots.code, 2);
  EXPECT_NE(plots.out.find("--record none does not write"), std::string::npos) << plots.out;
  const Cli file = redres("validate configs/paper_r_mvn.toml --set output.record=every=0");
  EXPECT_EQ(file.code, 2);
  EXPECT_NE(file.out.find("--set output.record:1:"), std::string::npos) << file.out;
  std::filesystem::remove_all(dir);
}

TEST(CliScenario, SetOverridesValuesAndValidateChecksWithoutRunning) {
  const Cli ok = redres("validate configs/paper_r_tvcmm.toml --set solver.engine=newton --set objectives.1.p=1.5");
  ASSERT_EQ(ok.code, 0) << ok.out;
  EXPECT_NE(ok.out.find("engine newton"), std::string::npos) << ok.out;
  const Cli bad_engine = redres("validate configs/paper_r_tvcmm.toml --set solver.engine=simplex");
  EXPECT_EQ(bad_engine.code, 2);
  EXPECT_NE(bad_engine.out.find("--set solver.engine:1:"), std::string::npos) << bad_engine.out;
  EXPECT_NE(bad_engine.out.find("expected one of 'newton', 'nlopt', 'projection'"), std::string::npos)
      << bad_engine.out;
  const Cli bad_index = redres("validate configs/paper_r_tvcmm.toml --set objectives.7.p=1");
  EXPECT_EQ(bad_index.code, 2);
  EXPECT_NE(bad_index.out.find("out of range"), std::string::npos) << bad_index.out;
}

TEST(CliScenario, BadScenarioFilesReportFileLineColumn) {
  const auto dir = scratch_dir("bad");
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const std::string robot = robot_line("paper_pushrod_6dof.toml");
  const std::string base =
      robot + "duration = 4.0\nstep = 0.01\n[path]\ntype = \"letter_r\"\n" + objective_entry("min_velocity_norm");
  const std::string typo = write("typo.toml", base + constraint_entry("task_tracking", "gian = 8.0\n"));
  Cli r = redres("validate '" + typo + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out.rfind(typo + ":10:1: unknown key 'gian'", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("gain"), std::string::npos) << r.out;  // the known keys are listed
  const std::string step = write("step.toml", robot + "duration = 4.0\nstep = 0.03\n");
  r = redres("validate '" + step + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out.rfind(step + ":3:8:", 0), 0u) << r.out;
  const std::string theta = write("theta.toml", "theta0 = [0, 0, 0, 0, 0, 0]\n" + base);
  r = redres("validate '" + theta + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("joint 'joint2' = 0 is outside its limits"), std::string::npos) << r.out;
  r = redres("run '" + (dir / "missing.toml").string() + "' --out '" + (dir / "o").string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("missing.toml: TOML file does not exist"), std::string::npos) << r.out;
  std::filesystem::remove_all(dir);
}

TEST(CliScenario, FailedStepsGiveExitCodeOne) {
  const auto dir = scratch("fail");
  // The R in 0.5 s asks for more than the push-rod joints can give.
  const Cli r =
      redres("run configs/paper_r_tvcmm.toml --out '" + dir.string() + "' --quiet --set duration=0.5 --set step=0.01");
  EXPECT_EQ(r.code, 1) << r.out;
  const nlohmann::json s = read_summary(dir);
  EXPECT_GT(s["solver"]["failures"].get<int>(), 0);
  EXPECT_NE(s["solver"]["first_failure"].get<std::string>().find("infeasible"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(CliScenario, CompareWritesATableForEveryScenario) {
  const auto dir = scratch("compare");
  const Cli r = redres("compare configs/paper_r_mvn.toml configs/planar_4link_circle.toml --out '" + dir.string() +
                       "' --quiet --no-plots");
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream md(dir / "comparison.md");
  std::stringstream text;
  text << md.rdbuf();
  EXPECT_NE(text.str().find("| paper_r_mvn |"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("| planar_4link_circle |"), std::string::npos) << text.str();
  EXPECT_TRUE(std::filesystem::exists(dir / "comparison.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "paper_r_mvn" / "trajectory.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "planar_4link_circle" / "summary.json"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace redres

// Sweeps (sweep.hpp): the variations of crossed and zipped grids and of sampled theta0, tables that do not depend on
// the number of threads, shards that merge into the whole table, failed variations as rows, CSV quoting, and bad
// sweep files as ConfigErrors at file:line:col.

#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "redres/run/scenario.hpp"
#include "redres/run/sweep.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

std::size_t column(const SweepTable& t, const std::string& name) {
  const auto it = std::find(t.columns.begin(), t.columns.end(), name);
  EXPECT_NE(it, t.columns.end()) << name;
  return static_cast<std::size_t>(it - t.columns.begin());
}

TEST(Sweep, ACrossedGridVariesItsLastAxisFastest) {
  const SweepSpec spec = load_sweep(data_path("sweeps/small.toml"));
  ASSERT_EQ(spec.size(), 9u);
  EXPECT_EQ(spec.set, std::vector<std::string>{"solver.on_infeasible=stop"});
  const Variation v = variation(spec, 5);  // rotation index 1, p index 2
  EXPECT_EQ(v.values, (std::vector<std::string>{"0", "2.0"}));
  EXPECT_EQ(v.overrides,
            (std::vector<std::string>{"solver.on_infeasible=stop", "path.rotation_deg=0", "objectives.1.p=2.0"}));
  EXPECT_FALSE(v.theta0.has_value());
  EXPECT_THROW((void)variation(spec, 9), std::invalid_argument);
}

TEST(Sweep, AZippedGridWithSampledTheta0) {
  const SweepSpec spec = load_sweep(data_path("sweeps/zip_theta0.toml"));
  ASSERT_EQ(spec.size(), 6u) << "2 zipped values x 3 configurations";
  EXPECT_EQ(spec.axes[1].values, (std::vector<std::string>{"1", "2"}));
  const Scenario base = load_scenario(source_path("configs/planar_4link_circle.toml"));
  const RobotModel& robot = *base.robot;
  for (std::size_t i = 0; i < spec.size(); ++i) {
    const Variation v = variation(spec, i);
    EXPECT_EQ(v.values[0], i % 2 == 0 ? "0.02" : "0.03");
    EXPECT_EQ(v.values[1], i % 2 == 0 ? "1" : "2") << "zipped: side by side";
    ASSERT_TRUE(v.theta0.has_value());
    EXPECT_EQ(*v.theta0, spec.theta0[i / 2]) << "theta0 is the outermost level";
    for (int j = 0; j < robot.dof(); ++j) {
      const double lo = robot.lower_limits()(j), hi = robot.upper_limits()(j);
      EXPECT_GE((*v.theta0)(j), lo + 0.2 * (hi - lo));
      EXPECT_LE((*v.theta0)(j), hi - 0.2 * (hi - lo));
    }
  }
  EXPECT_EQ(load_sweep(data_path("sweeps/zip_theta0.toml")).theta0, spec.theta0) << "the same seed, the same samples";
  EXPECT_NE(spec.theta0[0], spec.theta0[1]);
}

TEST(Sweep, TheTableDoesNotDependOnTheThreadsAndFailuresAreRows) {
  const SweepSpec spec = load_sweep(data_path("sweeps/small.toml"));
  const auto dir = scratch_dir("sweep_threads");
  const SweepTable one = run_sweep(spec, {}, 1, dir);
  const SweepTable two = run_sweep(spec, {}, 2, dir);
  write_sweep_csv(one, dir / "one.csv");
  write_sweep_csv(two, dir / "two.csv");
  EXPECT_EQ(read_text(dir / "one.csv"), read_text(dir / "two.csv"));
  ASSERT_EQ(one.rows.size(), 9u);
  const std::size_t status = column(one, "status"), diagnosis = column(one, "diagnosis"), index = column(one, "index");
  for (std::size_t r = 0; r < 9; ++r) {
    EXPECT_EQ(one.rows[r][index], std::to_string(r));
    const bool bad_value = r % 3 == 1;
    if (bad_value) {
      EXPECT_EQ(one.rows[r][status], "error");
      EXPECT_NE(one.rows[r][diagnosis].find("--set objectives.1.p:1:"), std::string::npos) << one.rows[r][diagnosis];
    }
  }
  // psi = 180 deg is the paper's R and runs through; psi = 0 (upside down) cannot be written from theta(0).
  EXPECT_EQ(one.rows[0][status], "ok") << one.rows[0][diagnosis];
  EXPECT_EQ(one.rows[3][status], "failed_steps");
  EXPECT_NE(one.rows[3][diagnosis].find("infeasible"), std::string::npos);
  EXPECT_EQ(one.rows[3][column(one, "solver.stopped")], "true");
  EXPECT_EQ(one.rows[6][status], "ok") << one.rows[6][diagnosis];
  EXPECT_EQ(one.rows[8][status], "ok") << one.rows[8][diagnosis];
  EXPECT_EQ(one.failed(), 5u) << "3 errors and the 2 runs at psi = 0";
  // The row is the run's summary: the same final theta as the scenario run on its own.
  Scenario s = load_scenario(source_path("configs/paper_r_fast.toml"),
                             {"solver.on_infeasible=stop", "path.rotation_deg=180", "objectives.1.p=2.0"});
  const RunResult run = simulate(s);
  const std::size_t last = run.trajectory.size() - 1;
  char buf[64];
  const double theta1 = run.trajectory(last, run.trajectory.column("theta_1"));
  EXPECT_EQ(one.rows[2][column(one, "final_theta_1")], std::string(buf, std::to_chars(buf, buf + 64, theta1).ptr));
  std::filesystem::remove_all(dir);
}

TEST(Sweep, ShardsMergeIntoTheWholeTable) {
  const SweepSpec spec = load_sweep(data_path("sweeps/small.toml"));
  const auto dir = scratch_dir("sweep_shards");
  const SweepTable whole = run_sweep(spec, {}, 2, dir);
  std::vector<SweepTable> parts;
  for (std::size_t i : {2U, 0U, 1U}) {
    SweepTable part = run_sweep(spec, {i, 3}, 1, dir);
    for (const auto& row : part.rows) EXPECT_EQ(std::stoul(row[0]) % 3, i);
    write_sweep_csv(part, dir / ("part" + std::to_string(i) + ".csv"));
    parts.push_back(read_sweep_csv(dir / ("part" + std::to_string(i) + ".csv")));
  }
  write_sweep_csv(whole, dir / "whole.csv");
  write_sweep_csv(merge_sweep_tables(parts), dir / "merged.csv");
  EXPECT_EQ(read_text(dir / "merged.csv"), read_text(dir / "whole.csv"));
  parts.push_back(parts.front());
  EXPECT_THROW((void)merge_sweep_tables(parts), std::invalid_argument) << "a shard merged twice";
  std::filesystem::remove_all(dir);
}

TEST(Sweep, CsvCellsWithCommasQuotesAndNewlinesReadBack) {
  SweepTable t;
  t.columns = {"index", "status", "diagnosis"};
  t.rows = {{"0", "error", "a, \"quoted\" word\nand a second line"}, {"1", "ok", ""}};
  const auto file = std::filesystem::temp_directory_path() / "redres_sweep_quotes.csv";
  write_sweep_csv(t, file);
  const SweepTable back = read_sweep_csv(file);
  EXPECT_EQ(back.columns, t.columns);
  EXPECT_EQ(back.rows, t.rows);
  std::filesystem::remove(file);
}

TEST(Sweep, BadSweepFilesAreConfigErrorsAtTheirKey) {
  const auto message = [](const std::string& name) {
    try {
      (void)load_sweep(data_path("sweeps/" + name));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("bad_both.toml").find("bad_both.toml:"), std::string::npos);
  EXPECT_NE(message("bad_both.toml").find("either 'values'"), std::string::npos) << message("bad_both.toml");
  EXPECT_NE(message("bad_zip.toml").find("equal length"), std::string::npos) << message("bad_zip.toml");
  EXPECT_NE(message("bad_theta0.toml").find("bad_theta0.toml:3:"), std::string::npos) << message("bad_theta0.toml");
  EXPECT_NE(message("bad_theta0.toml").find("outside the joint limits"), std::string::npos);
  EXPECT_NE(message("bad_range.toml").find("key 'range'"), std::string::npos) << message("bad_range.toml");
  EXPECT_THROW((void)parse_shard("3/3"), std::invalid_argument);
  EXPECT_THROW((void)parse_shard("1"), std::invalid_argument);
  EXPECT_THROW((void)parse_shard("-1/2"), std::invalid_argument);
  EXPECT_EQ(parse_shard("1/4").shard, 1u);
}

}  // namespace
}  // namespace redres

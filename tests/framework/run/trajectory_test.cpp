// Trajectory: rows copied in bit for bit (the streaming copy included, at every alignment), storage kept by reset(),
// growth past the reserve; simulate() into a reused RunResult gives the run a fresh one gives.

#include <atomic>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "redres/run/run_summary.hpp"
#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

std::vector<std::string> names(std::size_t width) {
  std::vector<std::string> out;
  for (std::size_t c = 0; c < width; ++c) out.push_back("c" + std::to_string(c));
  return out;
}

// A row of arbitrary bit patterns (NaN payloads, denormals, -0 included).
std::vector<double> random_row(std::mt19937_64& rng, std::size_t width) {
  std::vector<double> row(width);
  for (double& v : row) {
    const std::uint64_t bits = rng();
    std::memcpy(&v, &bits, sizeof v);
  }
  if (width > 0) row[0] = -0.0;
  if (width > 1) row[1] = std::numeric_limits<double>::denorm_min();
  return row;
}

TEST(Trajectory, AppendRowCopiesEveryBitAtEveryWidthAndAlignment) {
  std::mt19937_64 rng(5);
  for (const std::size_t width : {1, 2, 3, 4, 5, 7, 52, 53}) {
    // Fewer rows reserved than appended: the table grows on the way.
    Trajectory table(names(width), 3);
    std::vector<std::vector<double>> rows;
    for (int r = 0; r < 11; ++r) {
      rows.push_back(random_row(rng, width));
      table.append_row(rows.back().data());
      if (r % 4 == 3) {
        double* zeroed = table.append_row();
        for (std::size_t c = 0; c < width; ++c) ASSERT_EQ(zeroed[c], 0.0) << "width " << width;
        zeroed[0] = 42.0;
        rows.emplace_back(width, 0.0);
        rows.back()[0] = 42.0;
      }
    }
    Trajectory::publish();
    ASSERT_EQ(table.size(), rows.size());
    ASSERT_EQ(table.values().size(), rows.size() * width);
    for (std::size_t r = 0; r < rows.size(); ++r) {
      ASSERT_EQ(std::memcmp(table.row(r), rows[r].data(), width * sizeof(double)), 0)
          << "width " << width << ", row " << r;
    }
  }
}

TEST(Trajectory, ResetEmptiesTheTableAndKeepsStorageThatIsLargeEnough) {
  Trajectory table(names(4), 100);
  const double one[4] = {1, 2, 3, 4};
  for (int r = 0; r < 10; ++r) table.append_row(one);
  const double* storage = table.row(0);
  table.reset(names(3), 120);  // 360 values fit in the 400 made
  EXPECT_EQ(table.size(), 0u);
  EXPECT_EQ(table.width(), 3u);
  EXPECT_EQ(table.columns(), names(3));
  EXPECT_TRUE(table.values().empty());
  double* row = table.append_row();
  EXPECT_EQ(row, storage);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(row[c], 0.0);  // the old values do not show through
  table.reset(names(4), 1000);                         // larger than the storage: new storage
  EXPECT_EQ(table.size(), 0u);
  table.append_row(one);
  EXPECT_EQ(table.at(0, "c3"), 4.0);
}

TEST(Trajectory, ARunIntoAReusedResultIsTheRunIntoAFreshOne) {
  Scenario paper = load_scenario(source_path("configs/paper_r_fast.toml"));
  Scenario other = load_scenario(source_path("configs/planar_4link_circle.toml"));
  const RunResult fresh = simulate(paper);
  // A result that held a different run (other columns, other lengths) and one that held this run.
  RunResult reused = simulate(other);
  ASSERT_NE(reused.trajectory.width(), fresh.trajectory.width());
  for (int pass = 0; pass < 2; ++pass) {
    simulate(paper, reused);
    ASSERT_EQ(reused.trajectory.columns(), fresh.trajectory.columns());
    ASSERT_EQ(reused.trajectory.size(), fresh.trajectory.size());
    EXPECT_EQ(std::memcmp(reused.trajectory.values().data(), fresh.trajectory.values().data(),
                          fresh.trajectory.values().size() * sizeof(double)),
              0);
    EXPECT_EQ(reused.failures, fresh.failures);
    EXPECT_EQ(reused.first_failure, fresh.first_failure);
    EXPECT_EQ(reused.engine(), fresh.engine());
    EXPECT_EQ(reused.stopped, fresh.stopped);
  }
}

// A stop request (the CLI sets it from SIGINT and SIGTERM) ends the run after the current step, with every row up to
// it recorded and the summary saying so.
TEST(Trajectory, AStopRequestEndsTheRunWithTheRowsUpToItAndSaysSo) {
  Scenario s = load_scenario(source_path("configs/paper_r_fast.toml"));
  std::atomic<bool> stop{false};
  RunResult run;
  simulate(
      s, run, [&stop](double fraction, double) { stop = stop || fraction >= 0.5; }, &stop);
  EXPECT_TRUE(run.interrupted);
  EXPECT_FALSE(run.stopped);
  const std::size_t full = static_cast<std::size_t>(s.steps()) + 1;
  EXPECT_GT(run.trajectory.size(), full / 2 - 1);
  EXPECT_LT(run.trajectory.size(), full / 2 + 20);  // the progress callback runs every steps / 200 steps
  const RunSummary summary = summarise(s, run);
  EXPECT_EQ(summary.status, "interrupted");
  EXPECT_NE(to_json(summary).find("\"status\": \"interrupted\""), std::string::npos);
  // The rows it has are the rows of the whole run.
  const RunResult whole = simulate(s);
  EXPECT_EQ(summarise(s, whole).status, "complete");
  EXPECT_EQ(std::memcmp(run.trajectory.values().data(), whole.trajectory.values().data(),
                        run.trajectory.values().size() * sizeof(double)),
            0);
}

}  // namespace
}  // namespace redres

// Sweeps at their limits: a grid whose size does not fit in 64 bits is refused with its factors (never wrapped to
// a small count), a duplicated axis is refused at its key, --jobs beyond what the system gives runs on the threads
// it gets, --merge refuses tables of different sweeps, Slurm arrays with a step map to their slices and a task id
// that is not a number is refused, and a shard count near 2^64 runs its one variation.

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_util.hpp"
#include "redres/common/error.hpp"
#include "redres/run/sweep.hpp"
#include "scenario_text.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

// A sweep file in `dir` over the fast R with the given [[vary]] tables.
std::filesystem::path sweep_file(const std::filesystem::path& dir, const std::string& name, const std::string& vary) {
  std::filesystem::create_directories(dir);
  const auto file = dir / (name + ".toml");
  std::ofstream(file) << "name = \"" << name << "\"\nscenario = \"" << source_path("configs/paper_r_fast.toml").string()
                      << "\"\n"
                      << vary;
  return file;
}

std::string range_axis(const std::string& key, int n) {
  return "[[vary]]\nkey = \"" + key + "\"\nrange = { start = 0.0, stop = " + std::to_string(n - 1) +
         ".0, step = 1.0 }\n";
}

TEST(SweepLimits, AGridOf2To64VariationsIsRefusedWithItsFactors) {
  const auto dir = scratch("sweep_huge");
  std::string vary;
  for (const char* key : {"path.rotation_deg", "objectives.1.p", "solver.gamma", "path.height"}) {
    vary += range_axis(key, 65536);
  }
  const auto file = sweep_file(dir, "huge", vary);
  try {
    (void)load_sweep(file);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_NE(
        std::string(e.what()).find("expected at most 1e7 variations, got 65536 x 65536 x 65536 x 65536 = 1.84e+19"),
        std::string::npos)
        << e.what();
  }
  const Cli cli = redres("sweep '" + file.string() + "' --out '" + (dir / "out").string() + "'");
  EXPECT_EQ(cli.code, 2) << cli.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "sweep.csv"));
  std::filesystem::remove_all(dir);
}

TEST(SweepLimits, ADuplicatedAxisIsRefusedAtItsKey) {
  const auto dir = scratch("sweep_dup");
  const auto file = sweep_file(dir, "dup",
                               "[[vary]]\nkey = \"objectives.1.p\"\nvalues = [1.0, 2.0]\n"
                               "[[vary]]\nkey = \"objectives.1.p\"\nvalues = [3.0]\n");
  try {
    (void)load_sweep(file);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("dup.toml:7:"), std::string::npos) << m;
    EXPECT_NE(m.find("'objectives.1.p' is varied by an earlier [[vary]] already"), std::string::npos) << m;
  }
  std::filesystem::remove_all(dir);
}

TEST(SweepLimits, MoreJobsThanTheSystemGivesThreadsRunOnTheThreadsItGets) {
  const auto dir = scratch("sweep_jobs");
  const std::string sweep = data_path("sweeps/small.toml").string();
  const Cli want = redres("sweep '" + sweep + "' --jobs 2 --quiet --out '" + (dir / "a").string() + "'");
  ASSERT_LE(want.code, 1) << want.out;
  // Every thread asks for a stack of ~95 GiB (the stack limit), more than this machine's memory and
  // swap: the kernel refuses the mapping and the thread cannot be created. (An address-space limit,
  // ulimit -v, would do the same but leaves no room for AddressSanitizer's shadow memory.)
  const Cli got = redres_env("ulimit -s 100000000; ",
                             "sweep '" + sweep + "' --jobs 1000 --quiet --out '" + (dir / "b").string() + "'");
  EXPECT_EQ(got.code, want.code) << got.out;
  EXPECT_EQ(read_text(dir / "b" / "sweep.csv").size(), read_text(dir / "a" / "sweep.csv").size());
  std::filesystem::remove_all(dir);
}

// A variation that runs out of memory (std::bad_alloc, as under ulimit -v with many jobs) is not a row saying so,
// nor the end of the process: its thread stops taking work and the variation runs again, alone, once the others
// are done, so the table is the one a sweep with memory to spare writes. One that runs out of memory even alone is
// an error row that says so. (The test plugin's objective throws on its first N contributions.)
TEST(SweepLimits, AVariationThatRunsOutOfMemoryRunsAgainAloneAndTheTableIsTheSame) {
  const auto dir = scratch_dir("sweep_memory");
  std::string text = shipped_scenario_text("paper_r_fast.toml");
  text = "plugins = [\"" + std::string(REDRES_TEST_PLUGIN_MEMORY) + "\"]\n" + text +
         "\n[[objectives]]\ntype = \"test_out_of_memory\"\n";
  std::ofstream(dir / "scenario.toml") << text;
  std::ofstream(dir / "sweep.toml")
      << "name = \"memory\"\nscenario = \"" << (dir / "scenario.toml").string()
      << "\"\n[[vary]]\nkey = \"path.rotation_deg\"\nvalues = [180, 0, 200, 190, 170, 185]\n";
  const std::string sweep = "sweep '" + (dir / "sweep.toml").string() + "' --quiet --out '";
  const Cli want = redres(sweep + (dir / "a").string() + "' --jobs 2");
  ASSERT_LE(want.code, 1) << want.out;
  const Cli got = redres_env("REDRES_TEST_OUT_OF_MEMORY=3 ", sweep + (dir / "b").string() + "' --jobs 4");
  EXPECT_EQ(got.code, want.code) << got.out;
  EXPECT_EQ(read_text(dir / "b" / "sweep.csv"), read_text(dir / "a" / "sweep.csv"));
  // Out of memory at every try: every row an error that says so, and the process ends normally (exit 1).
  const Cli none = redres_env("REDRES_TEST_OUT_OF_MEMORY=1000000 ", sweep + (dir / "c").string() + "' --jobs 4");
  EXPECT_EQ(none.code, 1) << none.out;
  const std::string table = read_text(dir / "c" / "sweep.csv");
  std::size_t rows = 0;
  for (std::size_t at = table.find("out of memory"); at != std::string::npos; at = table.find("out of memory", at + 1))
    ++rows;
  EXPECT_EQ(rows, 6U) << table;
  std::filesystem::remove_all(dir);
}

TEST(SweepLimits, MergeRefusesTablesOfDifferentSweeps) {
  const auto dir = scratch("sweep_mix");
  const auto a = sweep_file(dir, "mix", "[[vary]]\nkey = \"objectives.1.p\"\nvalues = [1.0, 2.0]\n");
  const auto b = sweep_file(dir / "other", "mix", "[[vary]]\nkey = \"objectives.1.p\"\nvalues = [1.0, 3.0]\n");
  ASSERT_EQ(redres("sweep '" + a.string() + "' --shard 0/2 --quiet --out '" + (dir / "s").string() + "'").code, 0);
  ASSERT_EQ(redres("sweep '" + b.string() + "' --shard 1/2 --quiet --out '" + (dir / "s").string() + "'").code, 0);
  const Cli mixed = redres("sweep --merge '" + (dir / "s").string() + "' --out '" + (dir / "m").string() + "'");
  EXPECT_EQ(mixed.code, 2) << mixed.out;
  EXPECT_NE(mixed.out.find("sweep-shard-1-of-2.csv belongs to another sweep than"), std::string::npos) << mixed.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "m" / "sweep.csv"));
  // The right shard merges, and the merged table carries the identity on.
  ASSERT_EQ(redres("sweep '" + a.string() + "' --shard 1/2 --quiet --out '" + (dir / "s").string() + "'").code, 0);
  const Cli ok = redres("sweep --merge '" + (dir / "s").string() + "' --out '" + (dir / "m").string() + "'");
  EXPECT_EQ(ok.code, 0) << ok.out;
  std::ifstream meta(dir / "m" / "sweep.json");
  const nlohmann::json merged = nlohmann::json::parse(meta);
  ASSERT_TRUE(merged.contains("identity") && merged["identity"].is_string()) << merged.dump();
  EXPECT_EQ(merged["identity"].get<std::string>(), sweep_identity(load_sweep(a)));
  // A table without its description cannot be told apart: refused.
  std::filesystem::remove(dir / "s" / "sweep-shard-0-of-2.json");
  const Cli blind = redres("sweep --merge '" + (dir / "s").string() + "' --out '" + (dir / "n").string() + "'");
  EXPECT_EQ(blind.code, 2) << blind.out;
  EXPECT_NE(blind.out.find("sweep-shard-0-of-2.json cannot be read"), std::string::npos) << blind.out;
  std::filesystem::remove_all(dir);
}

TEST(SweepLimits, SlurmArraysWithAStepAndBadTaskIds) {
  const auto dir = scratch("sweep_slurm_step");
  const std::string sweep = data_path("sweeps/small.toml").string();
  // sbatch --array=1-5:2: tasks 1, 3, 5 are slices 0, 1, 2 of 3.
  for (int id : {1, 3, 5}) {
    const Cli task = redres_env("SLURM_ARRAY_TASK_ID=" + std::to_string(id) +
                                    " SLURM_ARRAY_TASK_MIN=1 SLURM_ARRAY_TASK_STEP=2 SLURM_ARRAY_TASK_COUNT=3 ",
                                "sweep '" + sweep + "' --quiet --out '" + dir.string() + "'");
    EXPECT_LE(task.code, 1) << task.out;
    EXPECT_TRUE(std::filesystem::exists(dir / ("sweep-shard-" + std::to_string((id - 1) / 2) + "-of-3.csv")))
        << id << ": " << task.out;
  }
  for (const std::string env :
       {"SLURM_ARRAY_TASK_ID=1abc SLURM_ARRAY_TASK_COUNT=3 ", "SLURM_ARRAY_TASK_ID=-1 SLURM_ARRAY_TASK_COUNT=3 ",
        "SLURM_ARRAY_TASK_ID=2 SLURM_ARRAY_TASK_MIN=1 SLURM_ARRAY_TASK_STEP=2 "
        "SLURM_ARRAY_TASK_COUNT=3 ",
        "SLURM_ARRAY_TASK_ID=3 SLURM_ARRAY_TASK_COUNT=3 "}) {
    const Cli bad = redres_env(env, "sweep '" + sweep + "' --quiet --out '" + (dir / "bad").string() + "'");
    EXPECT_EQ(bad.code, 2) << env << ": " << bad.out;
    EXPECT_NE(bad.out.find("SLURM_ARRAY_TASK_ID="), std::string::npos) << bad.out;
  }
  std::filesystem::remove_all(dir);
}

TEST(SweepLimits, AShardCountNear2To64DoesNotWrap) {
  const auto dir = scratch("sweep_shard_wrap");
  const std::string sweep = data_path("sweeps/small.toml").string();
  const std::string n = std::to_string(std::numeric_limits<std::size_t>::max());
  const Cli last = redres("sweep '" + sweep + "' --shard 8/" + n + " --quiet --out '" + dir.string() + "'");
  EXPECT_LE(last.code, 1) << last.out;
  std::ifstream meta(dir / ("sweep-shard-8-of-" + n + ".json"));
  const nlohmann::json m = nlohmann::json::parse(meta);
  EXPECT_EQ(m["rows"], 1);  // variation 8 only, not 8 and then wrapped ones
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace redres

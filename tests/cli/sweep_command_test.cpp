// `redres sweep`: the whole grid into sweep.csv, slices by --shard or by a Slurm job array's environment into
// sweep-shard-i-of-N.csv, --merge of the slices (byte for byte the whole table; a missing slice is exit 1), and
// exit codes.

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_util.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

TEST(CliSweep, SlurmSlicesMergeIntoTheWholeTable) {
  const auto dir = scratch("sweep");
  const std::string sweep = data_path("sweeps/small.toml").string();
  const Cli whole = redres("sweep '" + sweep + "' --jobs 2 --out '" + (dir / "whole").string() + "'");
  EXPECT_EQ(whole.code, 1) << "some variations fail: " << whole.out;
  EXPECT_NE(whole.out.find("9 of 9 variations"), std::string::npos) << whole.out;
  // A job array of three tasks numbered from 1 (sbatch --array=1-3), all writing into one directory.
  for (int id = 1; id <= 3; ++id) {
    const Cli task =
        redres_env("SLURM_ARRAY_TASK_ID=" + std::to_string(id) + " SLURM_ARRAY_TASK_MIN=1 SLURM_ARRAY_TASK_COUNT=3 ",
                   "sweep '" + sweep + "' --quiet --out '" + (dir / "array").string() + "'");
    EXPECT_LE(task.code, 1) << task.out;
    const std::string name = "sweep-shard-" + std::to_string(id - 1) + "-of-3";
    ASSERT_TRUE(std::filesystem::exists(dir / "array" / (name + ".csv"))) << task.out;
    std::ifstream meta(dir / "array" / (name + ".json"));
    const nlohmann::json m = nlohmann::json::parse(meta);
    EXPECT_EQ(m["rows"], 3);
    EXPECT_EQ(m["variations"], 9);
  }
  const Cli merged =
      redres("sweep --merge '" + (dir / "array").string() + "' --out '" + (dir / "merged").string() + "'");
  EXPECT_EQ(merged.code, 1) << merged.out;
  EXPECT_NE(merged.out.find("9 of 9 variations"), std::string::npos) << merged.out;
  EXPECT_EQ(read_text(dir / "merged" / "sweep.csv"), read_text(dir / "whole" / "sweep.csv"));
  // A slice missing: exit 1 with the count.
  std::filesystem::remove(dir / "array" / "sweep-shard-1-of-3.csv");
  const Cli partial = redres("sweep --merge '" + (dir / "array").string() + "' --out '" + (dir / "p").string() + "'");
  EXPECT_EQ(partial.code, 1);
  EXPECT_NE(partial.out.find("3 of 9 variations are missing"), std::string::npos) << partial.out;
  std::filesystem::remove_all(dir);
}

TEST(CliSweep, BadArgumentsAreExitTwo) {
  const auto dir = scratch("sweep_bad");
  const std::string sweep = data_path("sweeps/small.toml").string();
  const Cli shard = redres("sweep '" + sweep + "' --shard 3/3 --out '" + dir.string() + "'");
  EXPECT_EQ(shard.code, 2);
  EXPECT_NE(shard.out.find("expected i/N with 0 <= i < N"), std::string::npos) << shard.out;
  const Cli slurm = redres_env("SLURM_ARRAY_TASK_ID=x SLURM_ARRAY_TASK_COUNT=2 ",
                               "sweep '" + sweep + "' --out '" + dir.string() + "'");
  EXPECT_EQ(slurm.code, 2);
  EXPECT_NE(slurm.out.find("SLURM_ARRAY_TASK_ID=x"), std::string::npos) << slurm.out;
  const Cli file = redres("sweep '" + data_path("sweeps/bad_zip.toml").string() + "' --out '" + dir.string() + "'");
  EXPECT_EQ(file.code, 2);
  EXPECT_NE(file.out.find("bad_zip.toml:"), std::string::npos) << file.out;
  const Cli nothing = redres("sweep --merge '" + dir.string() + "' --out '" + dir.string() + "'");
  EXPECT_EQ(nothing.code, 2) << nothing.out;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace redres

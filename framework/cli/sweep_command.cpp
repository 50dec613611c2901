// `redres sweep`: a scenario over a grid of variations on a thread pool, one slice of it (--shard, or a Slurm job
// array), and the merge of the slices' tables.

#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "progress.hpp"
#include "redres/common/output_file.hpp"
#include "redres/run/run_output.hpp"
#include "redres/run/sweep.hpp"
#include "stop_signals.hpp"

namespace redres::cli {
namespace {

struct SweepOptions {
  std::string file, out, shard;
  std::vector<std::string> merge;
  unsigned jobs = 0;
  bool runs = false, quiet = false;
};

// A Slurm variable's value: decimal digits only (no sign, no suffix: "1abc" is refused), as a count that cannot
// wrap.
std::size_t slurm_number(const char* name, const char* text) {
  std::size_t out = 0;
  const std::string_view t(text);
  const auto res = std::from_chars(t.data(), t.data() + t.size(), out);
  if (t.empty() || res.ec != std::errc() || res.ptr != t.data() + t.size()) {
    throw std::invalid_argument(std::string(name) + "=" + text + ": expected a whole number of at most " +
                                std::to_string(std::numeric_limits<std::size_t>::max()));
  }
  return out;
}

// The slice this process runs: --shard, else a Slurm job array's task, else everything. A job array
// (sbatch --array=MIN-MAX[:STEP]) runs its tasks with SLURM_ARRAY_TASK_ID = MIN, MIN + STEP, ...; task k of
// SLURM_ARRAY_TASK_COUNT runs slice k = (ID - MIN) / STEP (MIN defaults to 0, STEP to 1).
SweepShard shard_of(const SweepOptions& o) {
  if (!o.shard.empty()) return parse_shard(o.shard);
  const char* id = std::getenv("SLURM_ARRAY_TASK_ID");
  const char* count = std::getenv("SLURM_ARRAY_TASK_COUNT");
  if (id == nullptr || count == nullptr) return {};
  const char* min = std::getenv("SLURM_ARRAY_TASK_MIN");
  const char* step = std::getenv("SLURM_ARRAY_TASK_STEP");
  std::string where = std::string("SLURM_ARRAY_TASK_ID=") + id + ", SLURM_ARRAY_TASK_COUNT=" + count;
  if (min != nullptr) where += std::string(", SLURM_ARRAY_TASK_MIN=") + min;
  if (step != nullptr) where += std::string(", SLURM_ARRAY_TASK_STEP=") + step;
  try {
    const std::size_t i = slurm_number("SLURM_ARRAY_TASK_ID", id);
    const std::size_t n = slurm_number("SLURM_ARRAY_TASK_COUNT", count);
    const std::size_t lo = min != nullptr ? slurm_number("SLURM_ARRAY_TASK_MIN", min) : 0;
    const std::size_t by = step != nullptr ? slurm_number("SLURM_ARRAY_TASK_STEP", step) : 1;
    if (by == 0) throw std::invalid_argument("the step is 0");
    if (i < lo) throw std::invalid_argument("the task id is below the array's first");
    if ((i - lo) % by != 0) throw std::invalid_argument("the task id is not the first plus a multiple of the step");
    const std::size_t k = (i - lo) / by;
    if (n == 0 || k >= n) {
      throw std::invalid_argument("task " + std::to_string(k) + " of an array of " + std::to_string(n) +
                                  " tasks (expected 0 <= (ID - MIN) / STEP < COUNT)");
    }
    return {k, n};
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(where + ": " + e.what());
  }
}

// sweep.csv, or sweep-shard-<i>-of-<N>.csv for a slice (so that every task of a job array can share one --out).
std::string table_name(const SweepShard& s) {
  return s.count == 1 ? "sweep" : "sweep-shard-" + std::to_string(s.shard) + "-of-" + std::to_string(s.count);
}

// TABLE.csv and TABLE.json together: both are staged and finished before either is renamed into place, so that a
// full disk (or any failed write) leaves the old pair, never a new table beside an old description.
void write_table_and_meta(const SweepTable& table, const std::filesystem::path& csv, const nlohmann::json& meta) {
  StagedFile table_file(csv);
  write_sweep_csv(table, table_file);
  StagedFile meta_file(std::filesystem::path(csv).replace_extension(".json"));
  meta_file.write(meta.dump(2) + "\n");
  meta_file.finish();
  table_file.install();
  meta_file.install();
}

int run(const SweepOptions& o) {
  const SweepSpec spec = load_sweep(o.file);
  SweepSpec with_runs = spec;
  with_runs.write_runs = spec.write_runs || o.runs;
  const SweepShard shard = shard_of(o);
  prepare_output_dir(o.out);
  // The table's own names too, before the first variation: a sweep is never run only to be refused at its end.
  for (const char* ext : {".csv", ".json"}) {
    require_replaceable(std::filesystem::path(o.out) / (table_name(shard) + ext), "--out: redres cannot write");
  }
  const auto start = std::chrono::steady_clock::now();
  SweepTable table;
  {
    ProgressBar bar(spec.name, o.quiet);
    const StopOnSignals signals;
    table = run_sweep(
        with_runs, shard, o.jobs, o.out,
        [&bar](std::size_t done, std::size_t total) {
          char where[48];
          std::snprintf(where, sizeof where, "%zu/%zu runs", done, total);
          bar.update(static_cast<double>(done) / static_cast<double>(total), where);
        },
        &g_stop_requested);
  }
  const bool interrupted = g_stop_requested.load();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string name = table_name(shard);
  write_table_and_meta(table, std::filesystem::path(o.out) / (name + ".csv"),
                       {{"name", spec.name},
                        {"identity", sweep_identity(spec)},
                        {"sweep", spec.source},
                        {"scenario", spec.scenario.string()},
                        {"variations", spec.size()},
                        {"shard", std::to_string(shard.shard) + "/" + std::to_string(shard.count)},
                        {"rows", table.rows.size()},
                        {"failed", table.failed()},
                        {"interrupted", interrupted}});
  if (interrupted) {
    std::cerr << spec.name << ": interrupted after " << table.rows.size() << " of " << spec.size() << " variations; "
              << (std::filesystem::path(o.out) / (name + ".csv")).string()
              << " holds those (a run cut short has status \"interrupted\")\n";
    return kExitInterrupted;
  }
  if (!o.quiet) {
    std::cout << spec.name << ": " << table.rows.size() << " of " << spec.size() << " variations in " << seconds
              << " s, " << table.failed() << " not ok -> " << (std::filesystem::path(o.out) / (name + ".csv")).string()
              << "\n";
  }
  return table.failed() > 0 ? kExitFailedSteps : kExitOk;
}

int merge(const SweepOptions& o) {
  std::vector<SweepTable> tables;
  std::size_t expected = 0;
  std::string identity, name;
  std::filesystem::path first;  // the table that set `identity`
  for (const auto& dir : o.merge) {
    if (!std::filesystem::is_directory(dir)) throw std::invalid_argument("--merge: " + dir + " is not a directory");
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
      const std::string stem = e.path().stem().string();
      if (e.path().extension() == ".csv" && (stem == "sweep" || stem.rfind("sweep-shard-", 0) == 0)) {
        files.push_back(e.path());
      }
    }
    if (files.empty()) throw std::invalid_argument("--merge: no sweep.csv or sweep-shard-*.csv in " + dir);
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      // Each table's .json says which sweep it belongs to: tables of different sweeps (another grid, another base
      // scenario) are never mixed.
      const std::filesystem::path meta_file = std::filesystem::path(f).replace_extension(".json");
      nlohmann::json meta;
      try {
        if (!std::filesystem::is_regular_file(meta_file)) throw std::runtime_error("not a regular file");
        std::ifstream in(meta_file);
        meta = nlohmann::json::parse(in);
      } catch (const std::exception& e) {
        throw std::invalid_argument("--merge: " + f.string() + ": its description " + meta_file.filename().string() +
                                    " cannot be read (" + e.what() + "), so its sweep cannot be told");
      }
      const std::string id = meta.value("identity", "");
      if (id.empty()) {
        throw std::invalid_argument("--merge: " + meta_file.string() +
                                    " has no \"identity\" (written by an older redres): run that shard again");
      }
      if (identity.empty()) {
        identity = id;
        first = f;
        name = meta.value("name", "");
      } else if (id != identity) {
        throw std::invalid_argument("--merge: " + f.string() + " belongs to another sweep than " + first.string() +
                                    " (identity " + id + " against " + identity +
                                    "; a different grid, name, overrides or base scenario)");
      }
      tables.push_back(read_sweep_csv(f));
      expected = std::max<std::size_t>(expected, meta.value("variations", std::size_t{0}));
    }
  }
  const SweepTable merged = merge_sweep_tables(tables);
  std::filesystem::create_directories(o.out);
  write_table_and_meta(merged, std::filesystem::path(o.out) / "sweep.csv",
                       {{"merged_from", o.merge},
                        {"name", name},
                        {"identity", identity},
                        {"variations", expected},
                        {"shard", "0/1"},
                        {"rows", merged.rows.size()},
                        {"failed", merged.failed()}});
  if (!o.quiet) {
    std::cout << "merged " << tables.size() << " tables: " << merged.rows.size() << " of " << expected
              << " variations, " << merged.failed() << " not ok -> "
              << (std::filesystem::path(o.out) / "sweep.csv").string() << "\n";
  }
  if (expected != 0 && merged.rows.size() < expected) {
    std::cerr << "merge: " << expected - merged.rows.size() << " of " << expected
              << " variations are missing (a shard not run, or not given)\n";
    return kExitFailedSteps;
  }
  return merged.failed() > 0 ? kExitFailedSteps : kExitOk;
}

}  // namespace

void add_sweep_command(CLI::App& app, Action& action) {
  auto o = std::make_shared<SweepOptions>();
  CLI::App* sweep = app.add_subcommand("sweep", "Run a scenario over a grid of variations; write one sweep.csv");
  sweep->add_option("SWEEP", o->file, "sweep TOML file (docs/sweeps.md)");
  sweep->add_option("--out", o->out, "output directory")->required();
  sweep->add_option("--jobs", o->jobs, "threads (default: one per core)");
  sweep->add_option("--shard", o->shard,
                    "i/N: run only the variations whose index % N == i, into sweep-shard-i-of-N.csv (default: the "
                    "Slurm array task from SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT, else all)");
  sweep->add_option("--merge", o->merge, "merge the sweep tables found in these directories into --out/sweep.csv")
      ->expected(1, -1);
  sweep->add_flag("--runs", o->runs, "also write each run's directory, runs/<index>/ ([output] record rows)");
  sweep->add_flag("--quiet", o->quiet, "no progress bar and no summary line");
  sweep->callback([o, &action] {
    action = [o] {
      if (!o->merge.empty()) {
        if (!o->file.empty()) throw std::invalid_argument("sweep --merge takes directories, not a sweep file");
        return merge(*o);
      }
      if (o->file.empty()) throw std::invalid_argument("sweep: give a sweep file, or --merge DIR...");
      return run(*o);
    };
  });
}

}  // namespace redres::cli

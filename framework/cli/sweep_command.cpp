// `redres sweep`: a scenario over a grid of variations on a thread pool, one slice of it (--shard, or a Slurm job
// array), and the merge of the slices' tables.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "progress.hpp"
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

// The slice this process runs: --shard, else a Slurm job array's task (SLURM_ARRAY_TASK_ID counted from
// SLURM_ARRAY_TASK_MIN, which defaults to 0, out of SLURM_ARRAY_TASK_COUNT), else everything.
SweepShard shard_of(const SweepOptions& o) {
  if (!o.shard.empty()) return parse_shard(o.shard);
  const char* id = std::getenv("SLURM_ARRAY_TASK_ID");
  const char* count = std::getenv("SLURM_ARRAY_TASK_COUNT");
  if (id == nullptr || count == nullptr) return {};
  const char* min = std::getenv("SLURM_ARRAY_TASK_MIN");
  try {
    const long i = std::stol(id) - (min != nullptr ? std::stol(min) : 0L);
    return parse_shard(std::to_string(i) + "/" + count);
  } catch (const std::exception& e) {
    throw std::invalid_argument(std::string("SLURM_ARRAY_TASK_ID=") + id + ", SLURM_ARRAY_TASK_COUNT=" + count +
                                (min != nullptr ? std::string(", SLURM_ARRAY_TASK_MIN=") + min : std::string()) + ": " +
                                e.what());
  }
}

// sweep.csv, or sweep-shard-<i>-of-<N>.csv for a slice (so that every task of a job array can share one --out).
std::string table_name(const SweepShard& s) {
  return s.count == 1 ? "sweep" : "sweep-shard-" + std::to_string(s.shard) + "-of-" + std::to_string(s.count);
}

void write_meta(const std::filesystem::path& file, const nlohmann::json& meta) {
  write_text_file(file, meta.dump(2) + "\n");
}

int run(const SweepOptions& o) {
  const SweepSpec spec = load_sweep(o.file);
  SweepSpec with_runs = spec;
  with_runs.write_runs = spec.write_runs || o.runs;
  const SweepShard shard = shard_of(o);
  prepare_output_dir(o.out);
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
  write_sweep_csv(table, std::filesystem::path(o.out) / (name + ".csv"));
  write_meta(std::filesystem::path(o.out) / (name + ".json"),
             {{"name", spec.name},
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
      tables.push_back(read_sweep_csv(f));
      std::ifstream meta(std::filesystem::path(f).replace_extension(".json"));
      if (meta) expected = std::max<std::size_t>(expected, nlohmann::json::parse(meta).value("variations", 0UL));
    }
  }
  const SweepTable merged = merge_sweep_tables(tables);
  std::filesystem::create_directories(o.out);
  write_sweep_csv(merged, std::filesystem::path(o.out) / "sweep.csv");
  write_meta(std::filesystem::path(o.out) / "sweep.json", {{"merged_from", o.merge},
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

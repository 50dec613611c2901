#include "redres/run/sweep.hpp"

#include "run/sweep_cells.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <mutex>
#include <new>
#include <optional>
#include <system_error>
#include <thread>

#include <nlohmann/json.hpp>

#include "common/text.hpp"
#include "redres/common/error.hpp"
#include "redres/run/run_output.hpp"
#include "redres/run/run_summary.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"

namespace redres {

using sweep_detail::Cells;
using sweep_detail::shortest;
using sweep_detail::to_table;

namespace {

// How a value is shown in sweep.csv: TOML text, strings without their quotes.
std::string cell_text(const std::string& toml) {
  if (toml.size() >= 2 && toml.front() == '"' && toml.back() == '"') return toml.substr(1, toml.size() - 2);
  return toml;
}

// The summary's figures as cells: objects flattened with dots, arrays as key_1, key_2, ... (1-based).
void flatten(const nlohmann::json& j, const std::string& key, Cells& out) {
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) flatten(v, key.empty() ? k : key + "." + k, out);
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) flatten(j[i], key + "_" + std::to_string(i + 1), out);
  } else if (j.is_number_float()) {
    out.emplace_back(key, shortest(j.get<double>()));
  } else if (j.is_number()) {
    out.emplace_back(key, j.dump());
  } else if (j.is_boolean()) {
    out.emplace_back(key, j.get<bool>() ? "true" : "false");
  } else if (j.is_string()) {
    out.emplace_back(key, j.get<std::string>());
  } else {
    out.emplace_back(key, "");
  }
}

// The cells that name variation v: its index, its value on each axis and its theta0.
Cells variation_cells(const SweepSpec& spec, const Variation& v) {
  Cells cells;
  cells.emplace_back("index", std::to_string(v.index));
  for (std::size_t a = 0; a < spec.axes.size(); ++a) cells.emplace_back(spec.axes[a].key, cell_text(v.values[a]));
  if (v.theta0) {
    for (Eigen::Index j = 0; j < v.theta0->size(); ++j) {
      cells.emplace_back("theta0_" + std::to_string(j + 1), shortest((*v.theta0)(j)));
    }
  }
  return cells;
}

Cells run_variation(const SweepSpec& spec, const Variation& v, const std::filesystem::path& out_dir,
                    std::mutex& load_lock, const std::atomic<bool>* stop) {
  Cells cells = variation_cells(spec, v);
  std::string status = "error", diagnosis;
  Cells figures;
  try {
    std::optional<Scenario> s;
    {
      // Loading may load plugin libraries into the process-wide registries: one at a time.
      const std::lock_guard<std::mutex> guard(load_lock);
      s.emplace(load_scenario(spec.scenario, v.overrides));
    }
    RunResult run;
    simulate(*s, run, {}, stop);
    const RunSummary summary = summarise(*s, run);
    if (spec.write_runs) write_run(*s->robot, run, summary, out_dir / "runs" / std::to_string(v.index), spec.record);
    status = run.interrupted               ? "interrupted"
             : run.failures > 0            ? "failed_steps"
             : summary.task_error_exceeded ? "task_error_exceeded"
                                           : "ok";
    diagnosis = run.first_failure;
    if (run.failures == 0 && summary.task_error_exceeded) {
      diagnosis = "max position error " + num(summary.max_position_error) +
                  " m > [solver] max_task_error = " + num(summary.max_task_error) + " m";
    }
    nlohmann::json j = nlohmann::json::parse(to_json(summary));
    // (The run's own "status" is the sweep's status column and solver.stopped.)
    for (const char* skip : {"wall_time_s", "source", "robot", "obstacles", "name", "label", "status"}) j.erase(skip);
    flatten(j, "", figures);
  } catch (const std::bad_alloc&) {
    throw;  // not the variation's fault: run_sweep runs it again, alone
  } catch (const std::exception& e) {
    diagnosis = e.what();
  }
  cells.emplace_back("status", status);
  cells.emplace_back("diagnosis", diagnosis);
  cells.insert(cells.end(), figures.begin(), figures.end());
  return cells;
}

}  // namespace

Variation variation(const SweepSpec& spec, std::size_t index) {
  REDRES_REQUIRE(index < spec.size(), "variation", "index < spec.size() = " + std::to_string(spec.size()));
  Variation v;
  v.index = index;
  std::size_t grid = spec.size() / std::max<std::size_t>(1, spec.theta0.size());
  std::size_t k = index % grid;
  v.values.resize(spec.axes.size());
  v.overrides = spec.set;
  if (spec.zip) {
    for (std::size_t a = 0; a < spec.axes.size(); ++a) v.values[a] = spec.axes[a].values[k];
  } else {
    for (std::size_t a = spec.axes.size(); a-- > 0;) {  // the last axis varies fastest
      const std::size_t size = spec.axes[a].values.size();
      v.values[a] = spec.axes[a].values[k % size];
      k /= size;
    }
  }
  for (std::size_t a = 0; a < spec.axes.size(); ++a) v.overrides.push_back(spec.axes[a].key + "=" + v.values[a]);
  if (!spec.theta0.empty()) {
    const Eigen::VectorXd& q = spec.theta0[index / grid];
    v.theta0 = q;
    std::string text = "theta0=[";
    for (Eigen::Index j = 0; j < q.size(); ++j) text += (j ? ", " : "") + shortest(q(j));
    v.overrides.push_back(text + "]");
  }
  return v;
}

SweepShard parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  SweepShard s;
  const auto number = [](const std::string& digits, std::size_t& out) {
    const auto res = std::from_chars(digits.data(), digits.data() + digits.size(), out);
    return res.ec == std::errc() && res.ptr == digits.data() + digits.size() && !digits.empty();
  };
  if (slash == std::string::npos || !number(text.substr(0, slash), s.shard) ||
      !number(text.substr(slash + 1), s.count) || s.count == 0 || s.shard >= s.count) {
    throw std::invalid_argument("shard: expected i/N with 0 <= i < N, got \"" + text + "\"");
  }
  return s;
}

SweepTable run_sweep(const SweepSpec& spec, const SweepShard& shard, unsigned jobs,
                     const std::filesystem::path& out_dir, const SweepProgress& progress,
                     const std::atomic<bool>* stop) {
  REDRES_REQUIRE(shard.count >= 1 && shard.shard < shard.count, "run_sweep", "0 <= shard < count");
  std::vector<std::size_t> mine;
  const std::size_t total = spec.size();
  for (std::size_t i = shard.shard; i < total; i += shard.count) {  // (no wrap: i + count is formed only below total)
    mine.push_back(i);
    if (total - i <= shard.count) break;
  }
  std::vector<Cells> rows(mine.size());
  std::atomic<std::size_t> next{0};
  std::size_t done = 0;
  std::mutex load_lock, progress_lock;
  const auto stopped = [stop] { return stop != nullptr && stop->load(std::memory_order_relaxed); };
  const auto run_one = [&](std::size_t k) {
    rows[k] = run_variation(spec, variation(spec, mine[k]), out_dir, load_lock, stop);
    const std::lock_guard<std::mutex> guard(progress_lock);
    ++done;
    if (progress) progress(done, mine.size());
  };
  // A thread whose variation runs out of memory stops taking work: its row stays empty, to be run again below,
  // alone, once the other threads have finished and given their memory back (the sweep runs on the memory it gets,
  // with the same table).
  const auto work = [&] {
    for (std::size_t k = next++; k < mine.size(); k = next++) {
      if (stopped()) return;  // the rows not started stay empty
      try {
        run_one(k);
      } catch (const std::bad_alloc&) {
        rows[k].clear();
        return;
      }
    }
  };
  if (jobs == 0) jobs = std::max(1U, std::thread::hardware_concurrency());
  const std::size_t threads = std::min<std::size_t>(jobs, std::max<std::size_t>(1, mine.size()));
  std::vector<std::thread> pool;
  try {
    for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(work);
  } catch (const std::system_error&) {
    // The system gives no more threads (a process or memory limit): the ones running, and this one, do the work.
  }
  work();
  for (auto& t : pool) t.join();
  for (std::size_t k = 0; k < mine.size() && !stopped(); ++k) {
    if (!rows[k].empty()) continue;
    try {
      run_one(k);
    } catch (const std::bad_alloc&) {
      rows[k] = variation_cells(spec, variation(spec, mine[k]));
      rows[k].emplace_back("status", "error");
      rows[k].emplace_back("diagnosis", "out of memory: the variation could not run even alone (std::bad_alloc)");
    }
  }
  rows.erase(std::remove_if(rows.begin(), rows.end(), [](const Cells& c) { return c.empty(); }), rows.end());
  return to_table(rows);
}

}  // namespace redres

#include "redres/run/sweep.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <new>
#include <random>
#include <sstream>
#include <system_error>
#include <thread>

#include <nlohmann/json.hpp>

#include "common/input_file.hpp"
#include "common/text.hpp"
#include "redres/common/csv.hpp"
#include "redres/common/error.hpp"
#include "redres/config/config.hpp"
#include "redres/run/run_summary.hpp"
#include "redres/run/scenario.hpp"

namespace redres {

namespace {

std::string shortest(double v) {
  char buf[64];
  return std::string(buf, std::to_chars(buf, buf + sizeof(buf), v).ptr);
}

// How a value is shown in sweep.csv: TOML text, strings without their quotes.
std::string cell_text(const std::string& toml) {
  if (toml.size() >= 2 && toml.front() == '"' && toml.back() == '"') return toml.substr(1, toml.size() - 2);
  return toml;
}

// A [vary] range: start, stop and step of an arithmetic sequence.
struct RangeTable {
  double start = 0.0, stop = 0.0, step = 0.0;
  static const Schema<RangeTable>& schema() {
    using C = RangeTable;
    static const Schema<C> s{
        {field("start", &C::start, "", "the first value").required(),
         field("stop", &C::stop, "", "the last value (included when the steps reach it)").required(),
         field("step", &C::step, "", "the difference between values, towards stop").required()}};
    return s;
  }
};

// A [[vary]] entry: one axis of the grid.
struct VaryEntry {
  SweepAxis axis;
  static const Schema<VaryEntry>& schema() {
    using C = VaryEntry;
    static const Schema<C> s{{
        entry<C>("key", "string", "", "", "the scenario key the axis varies, as --set names it (\"objectives.1.p\")",
                 [](const TableReader& t, C& c) {
                   c.axis.key = t.string("key");
                   if (c.axis.key.empty()) t.fail("key", "expected a scenario key such as \"objectives.1.p\"");
                 })
            .required(),
        entry<C>("values", "array", "", "", "the values (give `values` or `range`)",
                 [](const TableReader& t, C& c) {
                   const bool has_values = t.has("values"), has_range = t.has("range");
                   if (has_values == has_range) {
                     t.fail("give either 'values' (an array) or 'range' ({ start, stop, step })");
                   }
                   if (!has_values) return;
                   const toml::array* values = t.raw().get("values")->as_array();
                   if (values == nullptr || values->empty()) t.fail("values", "expected a non-empty array of values");
                   for (const auto& v : *values) c.axis.values.push_back(toml_value_text(v));
                 })
            .in_group("values or range"),
        entry<C>(
            "range", "table {start, stop, step}", "", "", "the values start, start + step, ... up to stop",
            [](const TableReader& t, C& c) {
              if (!t.has("range")) return;
              const TableReader range = t.table("range");
              RangeTable x;
              read_config(range, RangeTable::schema(), x);
              range.finish();
              const double start = x.start, stop = x.stop, step = x.step;
              if (!(std::isfinite(start) && std::isfinite(stop) && std::isfinite(step)) || step == 0.0 ||
                  (stop - start) / step < 0.0) {
                t.fail("range", "expected finite start, stop and a step != 0 that goes from start towards stop");
              }
              const double n = std::floor((stop - start) / step * (1.0 + 1e-12) + 1e-9) + 1.0;
              if (n > 1e6) t.fail("range", "expected at most 1e6 values, got " + shortest(n));
              for (long k = 0; k < static_cast<long>(n); ++k) {
                c.axis.values.push_back(shortest(start + static_cast<double>(k) * step));
              }
            },
            "at most 1e6 values")
            .in_group("values or range"),
    }};
    return s;
  }
};

SweepAxis read_axis(const TableReader& t) {
  VaryEntry v;
  read_config(t, VaryEntry::schema(), v);
  t.finish();
  return std::move(v.axis);
}

// The [theta0] table: the initial configurations, listed or sampled within the base scenario's robot's limits.
struct Theta0Table {
  const RobotModel* robot = nullptr;  // set before the table is read
  std::int64_t samples = 0;
  std::int64_t seed = 1;
  double margin = 0.0;
  std::vector<Eigen::VectorXd> list;
  static const Schema<Theta0Table>& schema();
};

const Schema<Theta0Table>& Theta0Table::schema() {
  using C = Theta0Table;
  static const Schema<C> s{{
      entry<C>("list", "array of configurations (arrays of numbers or formulas)", "rad or m", "",
               "the configurations, each within the joint limits (give `list` or `samples`)",
               [](const TableReader& t, C& c) {
                 if (!t.has("list")) return;
                 if (t.has("samples")) t.fail("samples", "give either 'list' or 'samples', not both");
                 const RobotModel& robot = *c.robot;
                 const int n = robot.dof();
                 const toml::array* list = t.raw().get("list")->as_array();
                 if (list == nullptr || list->empty()) t.fail("list", "expected a non-empty array of configurations");
                 for (const auto& entry : *list) {
                   const toml::array* q = entry.as_array();
                   if (q == nullptr || static_cast<int>(q->size()) != n) {
                     throw ConfigError(location_of(t.file(), entry), "key 'list': expected configurations of " +
                                                                         std::to_string(n) + " joint positions");
                   }
                   Eigen::VectorXd theta(n);
                   for (int j = 0; j < n; ++j) {
                     const toml::node& el = (*q)[static_cast<std::size_t>(j)];
                     try {
                       double v = 0.0;
                       if (!read_number_or_formula(el, v)) {
                         throw std::invalid_argument("expected a number or a formula, got " + describe_type(el));
                       }
                       theta(j) = v;
                     } catch (const std::invalid_argument& e) {
                       throw ConfigError(location_of(t.file(), el), "key 'list': " + std::string(e.what()));
                     }
                   }
                   const bool inside = (theta.array() >= robot.lower_limits().array()).all() &&
                                       (theta.array() <= robot.upper_limits().array()).all();
                   if (!inside) throw ConfigError(location_of(t.file(), entry), "key 'list': outside the joint limits");
                   c.list.push_back(theta);
                 }
               })
          .in_group("list or samples"),
      entry<C>(
          "samples", "integer", "", "", "the number of configurations drawn uniformly within the limits",
          [](const TableReader& t, C& c) {
            if (!c.list.empty()) return;
            c.samples = t.integer("samples");
            if (c.samples < 1 || c.samples > 1000000) t.fail("samples", "expected 1 to 1000000 configurations");
          },
          "1 to 1000000")
          .in_group("list or samples"),
      entry<C>("seed", "integer", "", "1",
               "the seed of the draw (a 64-bit Mersenne twister: the same on every machine)",
               [](const TableReader& t, C& c) {
                 if (c.list.empty()) c.seed = t.integer("seed", 1);
               }),
      entry<C>(
          "margin", "number", "", "0", "the fraction of each joint's range left out at both ends of the draw",
          [](const TableReader& t, C& c) {
            if (!c.list.empty()) return;
            c.margin = t.number("margin", 0.0);
            if (!(c.margin >= 0.0 && c.margin < 0.5)) {
              t.fail("margin", "expected a fraction 0 <= margin < 0.5 of each range");
            }
          },
          "0 <= margin < 0.5"),
  }};
  return s;
}

std::vector<Eigen::VectorXd> read_theta0(const TableReader& t, const RobotModel& robot) {
  Theta0Table x;
  x.robot = &robot;
  read_config(t, Theta0Table::schema(), x);
  t.finish();
  if (!x.list.empty()) return x.list;
  // Uniform in [lo + margin (hi - lo), hi - margin (hi - lo)], from a 64-bit Mersenne twister: the same
  // configurations on every machine.
  std::vector<Eigen::VectorXd> out;
  const int n = robot.dof();
  std::mt19937_64 rng(static_cast<std::uint64_t>(x.seed));
  for (std::int64_t k = 0; k < x.samples; ++k) {
    Eigen::VectorXd theta(n);
    for (int j = 0; j < n; ++j) {
      const double lo = robot.lower_limits()(j), hi = robot.upper_limits()(j);
      const double u = static_cast<double>(rng() >> 11) / 9007199254740992.0;  // [0, 1)
      theta(j) = lo + (x.margin + (1.0 - 2.0 * x.margin) * u) * (hi - lo);
    }
    out.push_back(theta);
  }
  return out;
}

// [output] of a sweep.
struct SweepOutput {
  bool runs = false;
  RecordOptions record{1, true};
  static const Schema<SweepOutput>& schema() {
    using C = SweepOutput;
    static const Schema<C> s{{
        field("runs", &C::runs, "", "write runs/<index>/ (trajectory.csv, summary.json) for every variation"),
        entry<C>("record", "\"all\", \"none\" or \"every=N\"", "", "\"none\"",
                 "the rows of each run's trajectory.csv (with runs = true)",
                 [](const TableReader& r, C& c) { c.record = read_record(r, "record", "none"); }),
    }};
    return s;
  }
};

// A sweep file's top level, read key by key in this order.
struct SweepReading {
  SweepSpec spec;
  SweepOutput output;
  static const Schema<SweepReading>& schema();
};

const Schema<SweepReading>& SweepReading::schema() {
  using C = SweepReading;
  static const Schema<C> s{{
      entry<C>("name", "string", "", "the file's stem", "the sweep's name",
               [](const TableReader& r, C& c) { c.spec.name = r.string("name", c.spec.name); }),
      entry<C>("scenario", "path", "", "", "the base scenario file, relative to this file",
               [](const TableReader& r, C& c) { c.spec.scenario = r.path("scenario"); })
          .required(),
      entry<C>("set", "array of strings", "", "[]", "overrides (\"key=value\", as --set) of every variation",
               [](const TableReader& r, C& c) {
                 if (r.has("set")) c.spec.set = r.strings("set");
               }),
      entry<C>("combine", "one of 'cross', 'zip'", "", "\"cross\"",
               "cross: every combination of the axes' values; zip: the k-th values together",
               [](const TableReader& r, C& c) {
                 c.spec.zip = r.choice("combine", {"cross", "zip"}, "cross") == "zip";
               }),
      entry<C>("vary", "array of tables [[vary]] (below)", "", "none", "the axes of the grid",
               [](const TableReader& r, C& c) {
                 SweepSpec& spec = c.spec;
                 if (r.has("vary")) {
                   for (const TableReader& t : r.tables("vary")) {
                     SweepAxis axis = read_axis(t);
                     for (const auto& earlier : spec.axes) {
                       if (earlier.key == axis.key) {
                         t.fail("key", "'" + axis.key +
                                           "' is varied by an earlier [[vary]] already; one axis per key (a second "
                                           "would override the first one's values)");
                       }
                     }
                     spec.axes.push_back(std::move(axis));
                   }
                 }
                 if (!spec.zip) return;
                 for (const auto& a : spec.axes) {
                   if (a.values.size() != spec.axes.front().values.size()) {
                     r.fail("combine", "\"zip\" needs axes of equal length: '" + spec.axes.front().key + "' has " +
                                           std::to_string(spec.axes.front().values.size()) + " values, '" + a.key +
                                           "' has " + std::to_string(a.values.size()));
                   }
                 }
               }),
      entry<C>("theta0", "table [theta0] (below)", "", "the scenario's theta0",
               "initial configurations; each variation runs from each of them",
               [](const TableReader& r, C& c) {
                 // The base scenario must load; its robot bounds the configurations.
                 const Scenario base = load_scenario(c.spec.scenario, c.spec.set);
                 if (!r.has("theta0")) return;
                 const TableReader t = r.table("theta0");
                 c.spec.theta0 = read_theta0(TableReader(t.file_ptr(), t.raw(), "theta0"), *base.robot);
               }),
      field("output", &C::output, "", "what the sweep writes besides sweep.csv (below)").listed_default("runs = false"),
  }};
  return s;
}

// A variation's cells, named.
using Cells = std::vector<std::pair<std::string, std::string>>;

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

SweepTable to_table(const std::vector<Cells>& rows) {
  SweepTable t;
  std::map<std::string, std::size_t> index;
  for (const Cells& row : rows) {
    for (const auto& [k, v] : row) {
      if (index.emplace(k, t.columns.size()).second) t.columns.push_back(k);
    }
  }
  for (const Cells& row : rows) {
    std::vector<std::string> cells(t.columns.size());
    for (const auto& [k, v] : row) cells[index.at(k)] = v;
    t.rows.push_back(std::move(cells));
  }
  return t;
}

}  // namespace

std::size_t SweepSpec::size() const {
  // Saturating: a product that does not fit is SIZE_MAX, far above kMaxSweepVariations, never a wrapped count.
  const auto times = [](std::size_t a, std::size_t b) {
    std::size_t out = 0;
    return __builtin_mul_overflow(a, b, &out) ? std::numeric_limits<std::size_t>::max() : out;
  };
  std::size_t grid = 1;
  if (zip) {
    grid = axes.empty() ? 1 : axes.front().values.size();
  } else {
    for (const auto& a : axes) grid = times(grid, a.values.size());
  }
  return times(grid, std::max<std::size_t>(1, theta0.size()));
}

namespace {

// "65536 x 65536 x ... = 1.8e19 variations", for the message of a grid that is too large.
std::string grid_size_text(const SweepSpec& spec) {
  std::string text;
  double product = 1;
  const auto factor = [&](std::size_t k) {
    text += (text.empty() ? "" : " x ") + std::to_string(k);
    product *= static_cast<double>(k);
  };
  if (spec.zip) {
    factor(spec.axes.empty() ? 1 : spec.axes.front().values.size());
  } else {
    for (const auto& a : spec.axes) factor(a.values.size());
  }
  if (!spec.theta0.empty()) factor(spec.theta0.size());
  char total[32];
  std::snprintf(total, sizeof total, "%.3g", product);
  return text + " = " + total;
}

}  // namespace

SweepSpec load_sweep(const std::filesystem::path& file) {
  const TableReader r = TableReader::root(parse_toml_file(file), "sweep");
  SweepReading reading;
  reading.spec.source = file.string();
  reading.spec.name = file.stem().string();
  read_config(r, SweepReading::schema(), reading);
  r.finish();
  SweepSpec spec = std::move(reading.spec);
  spec.write_runs = reading.output.runs;
  spec.record = reading.output.record;
  if (spec.size() > kMaxSweepVariations) {
    r.fail("vary", "expected at most 1e7 variations, got " + grid_size_text(spec));
  }
  return spec;
}

std::string sweep_identity(const SweepSpec& spec) {
  std::uint64_t h = 14695981039346656037ULL;
  const auto mix = [&h](std::string_view part) {
    for (const char c : part) {
      h ^= static_cast<unsigned char>(c);
      h *= 1099511628211ULL;
    }
    h ^= 0xff;  // a separator no text ends with, so that ("ab", "c") and ("a", "bc") differ
    h *= 1099511628211ULL;
  };
  mix(spec.name);
  mix(spec.zip ? "zip" : "cross");
  for (const auto& a : spec.axes) {
    mix(a.key);
    for (const auto& v : a.values) mix(v);
  }
  for (const auto& q : spec.theta0) {
    for (Eigen::Index j = 0; j < q.size(); ++j) mix(shortest(q(j)));
  }
  for (const auto& o : spec.set) mix(o);
  mix(read_input_file(spec.scenario, "scenario file"));
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

const std::vector<KeyTable>& sweep_key_tables() {
  static const std::vector<KeyTable> tables = {
      {"sweep", "", "a sweep file's top level", describe_keys(SweepReading::schema())},
      {"sweep", "[[vary]]", "one axis of the grid", describe_keys(VaryEntry::schema())},
      {"sweep", "[vary.range]", "an axis's values as a range", describe_keys(RangeTable::schema())},
      {"sweep", "[theta0]", "the initial configurations", describe_keys(Theta0Table::schema())},
      {"sweep", "[output]", "what the sweep writes besides sweep.csv", describe_keys(SweepOutput::schema())},
  };
  return tables;
}

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

std::size_t SweepTable::failed() const {
  const auto it = std::find(columns.begin(), columns.end(), "status");
  if (it == columns.end()) return 0;
  const auto c = static_cast<std::size_t>(it - columns.begin());
  return static_cast<std::size_t>(
      std::count_if(rows.begin(), rows.end(), [c](const auto& row) { return row[c] != "ok"; }));
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

void write_sweep_csv(const SweepTable& table, StagedFile& file) {
  std::string text;
  const auto flush = [&] {
    file.write(text);
    text.clear();
  };
  for (std::size_t c = 0; c < table.columns.size(); ++c) (text += c ? "," : "") += csv_field(table.columns[c]);
  text += "\n";
  for (const auto& row : table.rows) {
    for (std::size_t c = 0; c < row.size(); ++c) (text += c ? "," : "") += csv_field(row[c]);
    text += "\n";
    if (text.size() >= (std::size_t{1} << 16)) flush();
  }
  flush();
  file.finish();
}

void write_sweep_csv(const SweepTable& table, const std::filesystem::path& file) {
  StagedFile out(file);
  write_sweep_csv(table, out);
  out.install();
}

SweepTable read_sweep_csv(const std::filesystem::path& file) {
  const std::string text = read_input_file(file, "sweep CSV file");
  std::vector<std::vector<std::string>> records(1);
  std::string cell;
  bool quoted_cell = false, at_start = true;
  std::uint32_t line = 1;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted_cell) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        quoted_cell = false;
      } else {
        if (c == '\n') ++line;
        cell += c;
      }
    } else if (c == '"' && at_start) {
      quoted_cell = true;
      at_start = false;
    } else if (c == ',') {
      records.back().push_back(std::move(cell));
      cell.clear();
      at_start = true;
    } else if (c == '\n') {
      records.back().push_back(std::move(cell));
      cell.clear();
      records.emplace_back();
      at_start = true;
      ++line;
    } else if (c != '\r') {
      cell += c;
      at_start = false;
    }
  }
  if (quoted_cell) throw ConfigError({file.string(), line, 0}, "a quoted cell is not closed");
  if (!cell.empty() || !records.back().empty()) records.back().push_back(std::move(cell));
  if (records.back().empty()) records.pop_back();
  if (records.empty()) throw ConfigError({file.string(), 1, 1}, "expected a header line");
  SweepTable t;
  t.columns = std::move(records.front());
  if (std::find(t.columns.begin(), t.columns.end(), "index") == t.columns.end()) {
    throw ConfigError({file.string(), 1, 1}, "expected a column 'index' (is this a sweep.csv?)");
  }
  for (std::size_t r = 1; r < records.size(); ++r) {
    if (records[r].size() != t.columns.size()) {
      throw ConfigError(
          {file.string(), static_cast<std::uint32_t>(r + 1), 1},
          "expected " + std::to_string(t.columns.size()) + " cells, got " + std::to_string(records[r].size()));
    }
    t.rows.push_back(std::move(records[r]));
  }
  return t;
}

SweepTable merge_sweep_tables(const std::vector<SweepTable>& tables) {
  std::vector<std::pair<std::size_t, Cells>> all;
  std::map<std::size_t, bool> seen;
  for (const SweepTable& t : tables) {
    const auto c_index =
        static_cast<std::size_t>(std::find(t.columns.begin(), t.columns.end(), "index") - t.columns.begin());
    REDRES_REQUIRE(c_index < t.columns.size(), "merge_sweep_tables", "every table has an 'index' column");
    for (const auto& row : t.rows) {
      std::size_t index = 0;
      const std::string& text = row[c_index];
      const auto res = std::from_chars(text.data(), text.data() + text.size(), index);
      if (res.ec != std::errc() || res.ptr != text.data() + text.size()) {
        throw std::invalid_argument("merge: a row has index '" + text + "', expected a number");
      }
      if (!seen.emplace(index, true).second) {
        throw std::invalid_argument("merge: variation " + text + " appears in two tables (a shard merged twice?)");
      }
      Cells cells;
      for (std::size_t c = 0; c < t.columns.size(); ++c) {
        if (!row[c].empty() || c == c_index) cells.emplace_back(t.columns[c], row[c]);
      }
      all.emplace_back(index, std::move(cells));
    }
  }
  // Columns in order of first appearance over the tables, rows by index.
  std::vector<Cells> header_order;
  for (const SweepTable& t : tables) {
    Cells names;
    for (const auto& c : t.columns) names.emplace_back(c, "");
    header_order.push_back(std::move(names));
  }
  SweepTable columns = to_table(header_order);
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  SweepTable out;
  out.columns = columns.columns;
  std::map<std::string, std::size_t> at;
  for (std::size_t c = 0; c < out.columns.size(); ++c) at[out.columns[c]] = c;
  for (const auto& [index, cells] : all) {
    std::vector<std::string> row(out.columns.size());
    for (const auto& [k, v] : cells) row[at.at(k)] = v;
    out.rows.push_back(std::move(row));
  }
  return out;
}

}  // namespace redres

// Reading a sweep file (its [[vary]] axes, [theta0] and [output]), its identity and its keys (redres/run/sweep.hpp).

#include "redres/run/sweep.hpp"

#include "run/sweep_cells.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string_view>
#include <utility>

#include "common/input_file.hpp"
#include "redres/config/config.hpp"
#include "redres/run/record.hpp"
#include "redres/run/scenario.hpp"

namespace redres {

using sweep_detail::shortest;

namespace {

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
                 const RobotModel& model = *c.robot;
                 const int n = model.dof();
                 const toml::array* configurations = t.raw().get("list")->as_array();
                 if (configurations == nullptr || configurations->empty())
                   t.fail("list", "expected a non-empty array of configurations");
                 for (const auto& entry : *configurations) {
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
                   const bool inside = (theta.array() >= model.lower_limits().array()).all() &&
                                       (theta.array() <= model.upper_limits().array()).all();
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
                 SweepSpec& sweep = c.spec;
                 if (r.has("vary")) {
                   for (const TableReader& t : r.tables("vary")) {
                     SweepAxis axis = read_axis(t);
                     for (const auto& earlier : sweep.axes) {
                       if (earlier.key == axis.key) {
                         t.fail("key", "'" + axis.key +
                                           "' is varied by an earlier [[vary]] already; one axis per key (a second "
                                           "would override the first one's values)");
                       }
                     }
                     sweep.axes.push_back(std::move(axis));
                   }
                 }
                 if (!sweep.zip) return;
                 for (const auto& a : sweep.axes) {
                   if (a.values.size() != sweep.axes.front().values.size()) {
                     r.fail("combine", "\"zip\" needs axes of equal length: '" + sweep.axes.front().key + "' has " +
                                           std::to_string(sweep.axes.front().values.size()) + " values, '" + a.key +
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

}  // namespace redres

// libFuzzer target: the scenario loader and a short run (docs/fuzzing.md).
//
// The input is a scenario TOML file. It is written into the scratch directory (fuzz_util.hpp), where the configs'
// `robot = "../robots/..."` and the test corpora's "../../../robots/..." resolve, and loaded with
// load_scenario(path), the entry point of `redres run` and `redres validate`. A scenario that loads runs briefly
// (run_briefly: at most 20 control steps, 2,000 solver iterations per solve, 0.2 s), and the run is summarised and
// serialised as summary.json would be.
//
// Exceptions derived from std::exception are the loader's answers to bad input and are expected; a run's failed
// steps are results, not errors. Crashes, sanitizer reports, leaks, timeouts and out-of-memory are findings.

#include <cstdint>
#include <exception>

#include "fuzz_util.hpp"
#include "redres/run/run_summary.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"

namespace {
constexpr int kMaxSteps = 20;
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = redres::fuzz::scratch().write("input.toml", data, size);
  try {
    redres::Scenario scenario = redres::load_scenario(file);
    const redres::RunResult run = redres::fuzz::run_briefly(scenario, kMaxSteps);
    const redres::RunSummary summary = redres::summarise(scenario, run);
    (void)redres::to_json(summary);
  } catch (const std::exception&) {
    // Bad input, reported as a ConfigError, std::invalid_argument, ...
  }
  return 0;
}

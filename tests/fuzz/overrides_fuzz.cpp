// libFuzzer target: the `--set key.path=value` override parser (docs/fuzzing.md).
//
// The input is a list of overrides, one per line ('\n'; a '\r' stays in its line, as it would in an argument). They
// are applied, in order, to a fixed valid scenario, configs/paper_r_tvcmm.toml, through load_scenario(file,
// overrides): the path `redres run --set ...` takes (apply_overrides on the parsed file, then the strict readers).
// A scenario that loads runs briefly (run_briefly: at most 5 control steps), so that values the overrides change
// reach the plugins and the solver.
//
// Exceptions derived from std::exception are the answers to bad overrides and are expected. Crashes, sanitizer
// reports, leaks, timeouts and out-of-memory are findings.

#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include "fuzz_util.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"

namespace {
constexpr int kMaxSteps = 5;
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const redres::fuzz::fs::path base = redres::fuzz::source_dir() / "configs/paper_r_tvcmm.toml";
  std::vector<std::string> overrides;
  const std::string text(reinterpret_cast<const char*>(data), size);
  for (std::size_t begin = 0; begin <= text.size();) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    if (end > begin) overrides.push_back(text.substr(begin, end - begin));  // empty lines are not arguments
    begin = end + 1;
  }
  try {
    redres::Scenario scenario = redres::load_scenario(base, overrides);
    (void)redres::fuzz::run_briefly(scenario, kMaxSteps);
  } catch (const std::exception&) {
    // A malformed override or a value the scenario refuses: a ConfigError, std::invalid_argument, ...
  }
  return 0;
}

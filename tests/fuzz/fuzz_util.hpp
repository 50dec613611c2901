#pragma once
/// @file
/// Shared by the libFuzzer targets (docs/fuzzing.md): a per-process scratch directory laid out so that the
/// relative paths of the repository's robot and scenario files resolve, and writing an input into it, so that every
/// target goes through the file loaders users hit (read_input_file, the pre-parse scan, TOML++, the strict readers);
/// and a brief, bounded run of a scenario that loaded.
///
/// Layout, created once per process under $TMPDIR (default /tmp) and removed at exit; inputs are written into
/// <scratch>/tests/data/in/, the depth of the repository's tests/data/<corpus>/, so that both the configs'
/// "../robots/x.toml" and the test corpora's "../../../robots/x.toml" resolve:
///   <scratch>/robots            -> <source>/robots       ("../../../robots/x.toml")
///   <scratch>/tests/data/robots -> <source>/robots       ("../robots/x.toml")
///   <scratch>/tests/data/paths  -> <source>/tests/data/paths
///   <scratch>/tests/data/in/urdf -> <source>/robots/urdf ("urdf/franka_panda.urdf", as beside robots/)
///   <scratch>/tests/data/in/{good,bad}_table.csv, zigzag.csv -> the test data's CSV files

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"

#ifndef REDRES_SOURCE_DIR
#error "REDRES_SOURCE_DIR must name the source tree (tests/fuzz/CMakeLists.txt defines it)"
#endif

namespace redres::fuzz {

namespace fs = std::filesystem;

/// The source tree (REDRES_FUZZ_SOURCE_DIR overrides the path compiled in).
inline const fs::path& source_dir() {
  static const fs::path dir = [] {
    const char* env = std::getenv("REDRES_FUZZ_SOURCE_DIR");
    return fs::path(env != nullptr && *env != '\0' ? env : REDRES_SOURCE_DIR);
  }();
  return dir;
}

/// A setup failure is not a finding: say what went wrong and stop.
[[noreturn]] inline void setup_failed(const std::string& what) {
  std::fprintf(stderr, "redres fuzz setup: %s\n", what.c_str());
  std::_Exit(3);
}

class Scratch {
 public:
  Scratch() {
    const char* tmp = std::getenv("TMPDIR");
    std::string templ = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/redres-fuzz.XXXXXX";
    if (::mkdtemp(templ.data()) == nullptr) setup_failed("cannot create a scratch directory from " + templ);
    root_ = templ;
    const fs::path& src = source_dir();
    fs::create_directories(in_dir());
    link(src / "robots", root_ / "robots");
    link(src / "robots", root_ / "tests/data/robots");
    link(src / "tests/data/paths", root_ / "tests/data/paths");
    link(src / "robots/urdf", in_dir() / "urdf");
    for (const char* csv : {"good_table.csv", "bad_table.csv"}) {
      link(src / "tests/data/robot_corpus" / csv, in_dir() / csv);
    }
    link(src / "tests/data/paths/zigzag.csv", in_dir() / "zigzag.csv");
  }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(root_, ec);  // does not follow the symlinks
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;

  [[nodiscard]] fs::path in_dir() const { return root_ / "tests/data/in"; }

  /// Writes the input into in_dir()/<name> and returns its path.
  [[nodiscard]] fs::path write(const std::string& name, const std::uint8_t* data, std::size_t size) const {
    const fs::path p = in_dir() / name;
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.close();
    if (!out) setup_failed("cannot write " + p.string() + ": " + std::strerror(errno));
    return p;
  }

 private:
  static void link(const fs::path& target, const fs::path& name) {
    std::error_code ec;
    if (!fs::exists(target, ec)) setup_failed(target.string() + " does not exist (REDRES_FUZZ_SOURCE_DIR?)");
    fs::create_symlink(target, name, ec);
    if (ec) setup_failed("cannot link " + name.string() + ": " + ec.message());
  }

  fs::path root_;
};

/// The process's scratch directory (a function-local static: destroyed, and removed, at exit).
inline const Scratch& scratch() {
  static const Scratch s;
  return s;
}

/// The most solver iterations per solve in a fuzzed run. A step that fails (the arm starts in collision, the rows
/// cannot be met) costs the engine's whole iteration cap, 20,000 by default, and under the fuzzing instrumentation
/// that is most of a second; a cap of 2,000 keeps a run of failing steps to some 0.1 s per step.
inline constexpr int kMaxSolverIterations = 2000;
/// The wall-clock time after which a fuzzed run stops (at the end of the current step; the `stop` flag of
/// simulate(), as SIGINT in the CLI): inputs stay well inside libFuzzer's -timeout unless one step or the loading
/// alone is slow, which is then the finding. (A failing step also pays for its diagnosis, some 0.1 s here.)
inline constexpr std::chrono::milliseconds kRunBudget{200};

/// Runs a loaded scenario briefly: at most `max_steps` control steps (its duration cut after loading, so the path,
/// the scheme and the solver are the ones the file asked for), kMaxSolverIterations per solve, and kRunBudget.
inline RunResult run_briefly(Scenario& scenario, int max_steps) {
  scenario.duration = std::min(scenario.duration, max_steps * scenario.tau);
  // Before simulate(): each run's engine, and its fallbacks, are made from the scenario's settings.
  scenario.engine.settings.max_iterations = std::min(scenario.engine.settings.max_iterations, kMaxSolverIterations);
  std::atomic<bool> stop{false};
  const auto start = std::chrono::steady_clock::now();
  RunResult run;
  simulate(
      scenario, run,
      [&](double, double) {
        if (std::chrono::steady_clock::now() - start > kRunBudget) stop.store(true);
      },
      &stop);
  return run;
}

}  // namespace redres::fuzz

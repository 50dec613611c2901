#pragma once
/// @file
/// The registry of LVI engines and the factories that build an engine from a scenario's [solver] table or by name.
/// The solver itself (qp/lvi.hpp) knows no registry: choosing an engine by name is the control layer's business.

#include <any>
#include <memory>
#include <string>
#include <vector>

#include "redres/config/registry.hpp"
#include "redres/qp/lvi.hpp"

namespace redres {

/// The registry of engines. An engine is a plugin with its own Config (engine-specific keys in the [solver]
/// table; the built-in engines have none) and receives the common SolverSettings.
using EngineRegistry = Registry<LviEngine, const SolverSettings&>;
/// The process-wide engine registry.
EngineRegistry& engine_registry();

/// An engine as a file chose it: its type, its own Config and the common settings. A value: make() builds a fresh
/// engine (with its own warm start) each time, so that every controller of one scenario solves with its own.
struct EngineSpec {
  std::string type = "projection";  //!< the registered engine's name
  std::any config;                  //!< its own Config (empty: the type's defaults)
  SolverSettings settings;          //!< the common settings
  /// A new engine of this type, Config and settings (allocates).
  [[nodiscard]] std::unique_ptr<LviEngine> make() const;
};

/// Reads the [solver] table's common keys (`engine`, `tolerance`, `varpi`, `max_iterations`, `warm_start`) and the
/// engine's own, and builds one engine from them to check them; unknown keys are ConfigErrors.
[[nodiscard]] EngineSpec read_engine_spec(const TableReader& solver);

/// Reads the [solver] table's common keys (`engine`, `tolerance`, `varpi`, `max_iterations`, `warm_start`) and
/// builds the engine; unknown keys are ConfigErrors.
[[nodiscard]] std::unique_ptr<LviEngine> make_engine(const TableReader& solver);

/// Builds an engine by name with the given settings and its default Config (for code that does not read TOML).
[[nodiscard]] std::unique_ptr<LviEngine> make_engine(const std::string& name, const SolverSettings& settings = {});

/// The [solver] table's `engine` key and the common settings, for the listing.
[[nodiscard]] const std::vector<KeyInfo>& solver_common_keys();

}  // namespace redres

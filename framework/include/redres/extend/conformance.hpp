#pragma once
/// @file
/// Registry conformance checks: what every plugin, built-in or loaded from a library, must satisfy. `redres plugins
/// --check` runs them; the test suite runs them on the built-in plugins. Per registered type:
/// - objectives and constraints, on a planar 6-joint arm (position task), a planar 4-joint arm (pose task) and a
///   spatial 7-joint arm (pose task): built from the default Config ("defaults"); config() read back gives the
///   same config ("round trip"); every key config() writes is documented in the schema ("documented keys");
///   contributions at random configurations and times are finite, W symmetric, bounds not NaN ("finite");
///   objectives with potential(): zeta per unit weight matches central differences of the potential ("gradient");
/// - velocity-limit laws: the default Config builds (or, with required keys, is rejected naming one), and the built
///   law's config round-trips; engines: the default Config builds and solves a small feasible QP to tolerance;
/// - paths: built from defaults in the dimensions they support; r_d(0) is the path origin; r_d_dot matches central
///   differences of r_d.

#include <ostream>
#include <string>
#include <vector>

namespace redres {

/// The outcome of one check.
struct ConformanceResult {
  std::string kind;    //!< "objective", "constraint", ...
  std::string type;    //!< registry type
  std::string check;   //!< "defaults", "round trip", ...
  bool ok = false;     //!< passed
  std::string detail;  //!< what failed (or what was checked)
};

/// Runs every check on every registered plugin (of every registry).
[[nodiscard]] std::vector<ConformanceResult> check_registries();

/// Runs the checks on the registered plugins whose origin is `origin` ("built-in" or a library path); "" for all.
[[nodiscard]] std::vector<ConformanceResult> check_registries(const std::string& origin);

}  // namespace redres

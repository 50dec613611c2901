#pragma once
/// @file
/// `newton`: semismooth Newton on the reduced eq. 14 (exact; diagonal W, equality rows and bounds; otherwise it
/// falls back to projection). Build it with engine_registry().create("newton", NewtonConfig{}, settings).

#include "redres/lvi.hpp"

namespace redres {

/// The engine's own keys in the [solver] table (none: it uses the common SolverSettings only).
struct NewtonConfig {
  static const Schema<NewtonConfig>& schema() {
    static const Schema<NewtonConfig> s{};
    return s;
  }
};

}  // namespace redres

#pragma once
/// @file
/// `newton`: semismooth Newton on eq. 14, exact: on the reduced dual for diagonal W with equality rows and bounds,
/// on the whole LVI (globalised by the method of multipliers) with inequality rows or a dense W; an infeasible step
/// falls back to projection. Build it with engine_registry().create("newton", NewtonConfig{}, settings).

#include "redres/qp/lvi.hpp"

namespace redres {

/// The engine's own keys in the [solver] table (none: it uses the common SolverSettings only).
struct NewtonConfig {
  static const Schema<NewtonConfig>& schema() {
    static const Schema<NewtonConfig> s{};
    return s;
  }
};

}  // namespace redres

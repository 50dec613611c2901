#pragma once
/// @file
/// `nlopt`: NLopt's SLSQP on the QP itself, an independent cross-check (NLopt allocates its work array in every
/// solve). Build it with engine_registry().create("nlopt", NloptConfig{}, settings).

#include "redres/qp/lvi.hpp"

namespace redres {

/// The engine's own keys in the [solver] table (none: it uses the common SolverSettings only).
struct NloptConfig {
  static const Schema<NloptConfig>& schema() {
    static const Schema<NloptConfig> s{};
    return s;
  }
};

}  // namespace redres

#pragma once
/// @file
/// `projection`: the paper's eq. 15, u <- u - (||e||^2 / ||phi||^2) phi with phi = (M' + I) e (linear
/// convergence; the reference for fidelity). Build it with
///   engine_registry().create("projection", ProjectionConfig{}, SolverSettings{.tolerance = 1e-6});

#include "redres/qp/lvi.hpp"

namespace redres {

/// The engine's own keys in the [solver] table (none: it uses the common SolverSettings only).
struct ProjectionConfig {
  static const Schema<ProjectionConfig>& schema() {
    static const Schema<ProjectionConfig> s{};
    return s;
  }
};

}  // namespace redres

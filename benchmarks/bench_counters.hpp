#pragma once
// Counters shared by the benchmarks.

#include <benchmark/benchmark.h>

namespace redres {

/// Sets the "per_step" counter to the time of one step when each iteration runs `steps` steps (printed with an SI
/// prefix, e.g. 1.25u = 1.25 us).
inline void set_per_step(benchmark::State& state, double steps) {
  state.counters["per_step"] =
      benchmark::Counter(steps, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace redres

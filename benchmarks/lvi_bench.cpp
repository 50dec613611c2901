// Per-solve time of each LVI engine on the paper-like QP family (the paper's arm and TVCMM scheme: 6 joints,
// 2 task rows, bounds active at the solution in about a third of the problems), cold and warm.
//
// - cold: 512 independent random feasible problems, each solved from u = 0;
// - warm: chains of consecutive control steps (tau = 10 ms) from random states of the family, each solve
//   warm-started from the previous step, as in a control loop. Reported per warm solve (see solve_warm).
// Compare the engines as ratios within one run: the machine is noisy.

#include <chrono>
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

#include "qp_util.hpp"
#include "redres/control/engine_registry.hpp"
#include "test_util.hpp"

namespace {

using redres::QpProblem;

const std::vector<QpProblem>& cold_family() {
  static const std::vector<QpProblem> family = [] {
    std::vector<QpProblem> out;
    std::mt19937 rng(12345);
    auto step = redres::testing::make_paper_step();
    auto engine = redres::make_engine("newton");
    redres::SolverResult r;
    engine->setup(6, 2, 0, r);
    while (out.size() < 512) {
      redres::testing::paper_family_qp(rng, *step);
      engine->reset();
      engine->solve(step->qp, r);
      if (r.info.status == redres::SolverStatus::kSolved) out.push_back(step->qp);  // feasible problems only
    }
    return out;
  }();
  return family;
}

// Warm-start chains: from each of 64 random feasible base states of the family, 32 consecutive control steps
// (tau = 10 ms) with the base state's desired velocity, theta integrated with the solution. Consecutive problems
// differ by one step of motion, as in a control loop.
constexpr int kChain = 32;

const std::vector<QpProblem>& warm_family() {
  static const std::vector<QpProblem> family = [] {
    std::vector<QpProblem> out;
    std::mt19937 rng(54321);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto step = redres::testing::make_paper_step();
    auto engine = redres::make_engine("newton");
    redres::SolverResult r;
    engine->setup(6, 2, 0, r);
    while (out.size() < 64 * kChain) {
      redres::testing::paper_family_qp(rng, *step);
      Eigen::VectorXd theta = step->kin->theta;
      const double t0 = step->ctx.t;
      const Eigen::Vector2d v = step->r_d_dot;
      const Eigen::Vector2d dr = step->r_d - step->kin->f;
      std::vector<QpProblem> chain;
      engine->reset();
      for (int k = 0; k < kChain; ++k) {
        step->build(theta, std::min(40.0, t0 + 0.01 * k), v, dr);
        engine->solve(step->qp, r);
        if (r.info.status != redres::SolverStatus::kSolved) break;
        chain.push_back(step->qp);
        theta += 0.01 * r.x;
      }
      if (static_cast<int>(chain.size()) == kChain) out.insert(out.end(), chain.begin(), chain.end());
    }
    return out;
  }();
  return family;
}

// Share of `family` with a bound active at the solution (measured once, outside the timing).
double bounds_active(redres::LviEngine& engine, redres::SolverResult& r, const std::vector<QpProblem>& family) {
  long active = 0;
  for (const QpProblem& qp : family) {
    engine.reset();
    engine.solve(qp, r);
    active += ((r.x - qp.lo).array().abs() < 1e-9).any() || ((qp.hi - r.x).array().abs() < 1e-9).any();
  }
  engine.reset();
  return static_cast<double>(active) / static_cast<double>(family.size());
}

// Cold: one solve from u = 0 per benchmark iteration.
void solve_cold(benchmark::State& state, const char* name) {
  const std::vector<QpProblem>& family = cold_family();
  auto engine = redres::make_engine(name);
  redres::SolverResult r;
  engine->setup(6, 2, 0, r);
  state.counters["bounds_active"] = bounds_active(*engine, r, family);
  std::size_t k = 0;
  long iterations = 0, solves = 0;
  for (auto _ : state) {
    engine->reset();
    engine->solve(family[k], r);
    benchmark::DoNotOptimize(r.x.data());
    iterations += r.info.iterations;
    ++solves;
    if (++k == family.size()) k = 0;
  }
  state.counters["iterations"] = static_cast<double>(iterations) / static_cast<double>(solves);
}

// Warm: one chain per benchmark iteration. Its first problem is solved cold and untimed; the clock then runs over
// the chain's kChain - 1 warm solves, and the iteration's time is their mean, so the reported time is per warm
// solve. (Pausing the automatic timer per chain instead would add ~25 ns per solve on this machine.)
void solve_warm(benchmark::State& state, const char* name) {
  using Clock = std::chrono::steady_clock;
  const std::vector<QpProblem>& family = warm_family();
  auto engine = redres::make_engine(name);
  redres::SolverResult r;
  engine->setup(6, 2, 0, r);
  state.counters["bounds_active"] = bounds_active(*engine, r, family);
  const std::size_t chains = family.size() / kChain;
  std::size_t c = 0;
  long iterations = 0, solves = 0;
  for (auto _ : state) {
    const QpProblem* chain = family.data() + c * kChain;
    engine->reset();
    engine->solve(chain[0], r);
    const auto start = Clock::now();
    for (int k = 1; k < kChain; ++k) {
      engine->solve(chain[k], r);
      benchmark::DoNotOptimize(r.x.data());
      iterations += r.info.iterations;
    }
    const auto stop = Clock::now();
    solves += kChain - 1;
    state.SetIterationTime(std::chrono::duration<double>(stop - start).count() / (kChain - 1));
    if (++c == chains) c = 0;
  }
  state.counters["iterations"] = static_cast<double>(iterations) / static_cast<double>(solves);
}

// The reported (manual) time is per warm solve while each benchmark iteration runs a whole chain, so Google
// Benchmark's iteration count would scale with kChain - 1; this minimum keeps a warm repetition at ~1 s of real
// time, like the cold ones. (It takes precedence over --benchmark_min_time.)
constexpr double kWarmMinTime = 1.0 / (kChain - 1);

void BM_Projection_Cold(benchmark::State& s) { solve_cold(s, "projection"); }
void BM_Projection_Warm(benchmark::State& s) { solve_warm(s, "projection"); }
void BM_Newton_Cold(benchmark::State& s) { solve_cold(s, "newton"); }
void BM_Newton_Warm(benchmark::State& s) { solve_warm(s, "newton"); }
void BM_NloptSlsqp_Cold(benchmark::State& s) { solve_cold(s, "nlopt"); }
void BM_NloptSlsqp_Warm(benchmark::State& s) { solve_warm(s, "nlopt"); }

BENCHMARK(BM_Projection_Cold);
BENCHMARK(BM_Projection_Warm)->UseManualTime()->MinTime(kWarmMinTime);
BENCHMARK(BM_Newton_Cold);
BENCHMARK(BM_Newton_Warm)->UseManualTime()->MinTime(kWarmMinTime);
BENCHMARK(BM_NloptSlsqp_Cold);
BENCHMARK(BM_NloptSlsqp_Warm)->UseManualTime()->MinTime(kWarmMinTime);

}  // namespace

BENCHMARK_MAIN();

// Per-solve time of each LVI engine on the paper-like QP family (the paper's arm and TVCMM scheme: 6 joints,
// 2 task rows, bounds active at the solution in about a third of the problems), cold and warm.
//
// - cold: 512 independent random feasible problems, each solved from u = 0;
// - warm: chains of consecutive control steps (tau = 10 ms) from random states of the family, each solve
//   warm-started from the previous step, as in a control loop.
// Compare the engines as ratios within one run: the machine is noisy.

#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

#include "qp_util.hpp"
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

void solve_family(benchmark::State& state, const char* name, bool warm) {
  const std::vector<QpProblem>& family = warm ? warm_family() : cold_family();
  auto engine = redres::make_engine(name);
  redres::SolverResult r;
  engine->setup(6, 2, 0, r);
  // Share of the family with a bound active at the solution (measured once, outside the timing).
  long active = 0;
  for (const QpProblem& qp : family) {
    engine->reset();
    engine->solve(qp, r);
    active += ((r.x - qp.lo).array().abs() < 1e-9).any() || ((qp.hi - r.x).array().abs() < 1e-9).any();
  }
  engine->reset();
  std::size_t k = 0;
  long iterations = 0, solves = 0;
  for (auto _ : state) {
    if (!warm) {
      engine->reset();
    } else if (k % kChain == 0) {
      // The first problem of a chain is solved cold, outside the timing, so only warm solves are timed.
      state.PauseTiming();
      engine->reset();
      engine->solve(family[k], r);
      ++k;
      state.ResumeTiming();
    }
    const QpProblem& qp = family[k];
    engine->solve(qp, r);
    benchmark::DoNotOptimize(r.x.data());
    iterations += r.info.iterations;
    ++solves;
    if (++k == family.size()) k = 0;
  }
  state.counters["iterations"] = benchmark::Counter(static_cast<double>(iterations) / static_cast<double>(solves));
  state.counters["bounds_active"] =
      benchmark::Counter(static_cast<double>(active) / static_cast<double>(family.size()));
}

void BM_Projection_Cold(benchmark::State& s) { solve_family(s, "projection", false); }
void BM_Projection_Warm(benchmark::State& s) { solve_family(s, "projection", true); }
void BM_Newton_Cold(benchmark::State& s) { solve_family(s, "newton", false); }
void BM_Newton_Warm(benchmark::State& s) { solve_family(s, "newton", true); }
void BM_NloptSlsqp_Cold(benchmark::State& s) { solve_family(s, "nlopt", false); }
void BM_NloptSlsqp_Warm(benchmark::State& s) { solve_family(s, "nlopt", true); }

BENCHMARK(BM_Projection_Cold);
BENCHMARK(BM_Projection_Warm);
BENCHMARK(BM_Newton_Cold);
BENCHMARK(BM_Newton_Warm);
BENCHMARK(BM_NloptSlsqp_Cold);
BENCHMARK(BM_NloptSlsqp_Warm);

}  // namespace

BENCHMARK_MAIN();

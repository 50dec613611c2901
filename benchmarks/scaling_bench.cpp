// Time per control step against the number of joints, for each engine: planar chains of 3 to 192 joints and spatial
// chains of 7 to 28 (an iiwa-like module repeated), with the TVCMM scheme (min velocity norm, det manipulability
// with p = 1, task tracking with K = 8, joint-angle margin, velocity limits) following a 2 cm circle for 100 steps
// of 10 ms from a bent configuration. BM_Scaling/<engine>/<planar|spatial>/<n>; per_step is the time per step (s),
// iterations_per_step the engine's iterations per step.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench_counters.hpp"
#include "random_chain.hpp"
#include "redres/constraints/joint_angle_margin.hpp"
#include "redres/constraints/joint_velocity_limits.hpp"
#include "redres/constraints/task_tracking.hpp"
#include "redres/control/controller.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/objectives/manipulability.hpp"
#include "redres/objectives/min_velocity_norm.hpp"

namespace redres {
namespace {

RobotModel chain(bool planar, int n) {
  RobotSpec spec;
  spec.name = (planar ? "planar_" : "spatial_") + std::to_string(n);
  spec.kind = planar ? ChainKind::kPlanar : ChainKind::kSpatial;
  spec.convention = DhConvention::kStandard;
  const double d[4] = {0.36, 0.0, 0.42, 0.0};
  for (int j = 0; j < n; ++j) {
    JointSpec jt;
    jt.name = "j" + std::to_string(j + 1);
    jt.length = 1.0 / n;
    jt.d = d[j % 4] * 7.0 / n;
    jt.alpha = (j % 2 == 0 ? 1.0 : -1.0) * std::numbers::pi / 2;
    jt.lower = -2.5;
    jt.upper = 2.5;
    jt.velocity_limit = testing::constant_law(2.0);
    spec.joints.push_back(jt);
  }
  spec.home = Eigen::VectorXd::Constant(n, planar ? 2.0 / n : 0.3);
  return RobotModel(std::move(spec));
}

void BM_Scaling(benchmark::State& state, const char* engine_name, bool planar, double p = 1.0) {
  const int n = static_cast<int>(state.range(0));
  const RobotModel robot = chain(planar, n);
  std::vector<std::unique_ptr<Objective>> objectives;
  objectives.push_back(std::make_unique<MinVelocityNorm>(MinVelocityNorm::Config{}, robot));
  objectives.push_back(std::make_unique<Manipulability>(
      Manipulability::Config{.p = p, .schedule = Manipulability::Schedule::kConstant}, robot));
  std::vector<std::unique_ptr<Constraint>> constraints;
  constraints.push_back(std::make_unique<TaskTracking>(TaskTracking::Config{}, robot));
  constraints.push_back(std::make_unique<JointAngleMargin>(JointAngleMargin::Config{}, robot));
  constraints.push_back(std::make_unique<JointVelocityLimits>(JointVelocityLimits::Config{}, robot));
  const Scheme scheme(robot, std::move(objectives), std::move(constraints));
  const std::unique_ptr<LviEngine> engine = make_engine(engine_name);
  const int steps = 100;
  const double tau = 0.01, T = steps * tau;
  Controller ctrl(robot, scheme, *engine, nullptr, T, tau);
  StepOutput out = ctrl.make_output();
  KinematicsData k(robot);
  compute_kinematics(robot, robot.home(), k, KinematicsLevel::kPosition);
  const Eigen::VectorXd start = k.f;
  Eigen::VectorXd theta(n), r_d = start, r_d_dot = Eigen::VectorXd::Zero(start.size());
  int failures = 0;
  long iterations = 0, at_bound = 0, flips = 0;
  std::vector<int> side(static_cast<std::size_t>(n), 0), last(static_cast<std::size_t>(n), 0);
  for (auto _ : state) {
    theta = robot.home();
    ctrl.reset();
    std::fill(last.begin(), last.end(), 0);
    for (int s = 0; s < steps; ++s) {
      const double a = 2.0 * std::numbers::pi * s / steps;
      r_d(0) = start(0) + 0.02 * (std::cos(a) - 1.0);
      r_d(1) = start(1) + 0.02 * std::sin(a);
      r_d_dot(0) = -0.02 * 2.0 * std::numbers::pi / T * std::sin(a);
      r_d_dot(1) = 0.02 * 2.0 * std::numbers::pi / T * std::cos(a);
      ctrl.step(theta, s * tau, r_d, r_d_dot, out);
      failures += out.info.status == SolverStatus::kSolved ? 0 : 1;
      iterations += out.info.iterations;
      // Which joints run at their velocity limit (2 rad/s), and how many changed that from the step before.
      for (int j = 0; j < n; ++j) {
        const double v = out.theta_dot(j);
        side[static_cast<std::size_t>(j)] = v >= 2.0 - 1e-9 ? 1 : (v <= -2.0 + 1e-9 ? -1 : 0);
        at_bound += side[static_cast<std::size_t>(j)] != 0;
        flips += s > 0 && side[static_cast<std::size_t>(j)] != last[static_cast<std::size_t>(j)];
      }
      last.swap(side);
      theta += tau * out.theta_dot;
    }
    benchmark::DoNotOptimize(theta.data());
  }
  set_per_step(state, steps);
  state.counters["failed_steps"] = failures;
  state.counters["iterations_per_step"] =
      benchmark::Counter(static_cast<double>(iterations) / steps, benchmark::Counter::kAvgIterations);
  state.counters["at_velocity_bound"] =
      benchmark::Counter(static_cast<double>(at_bound) / steps, benchmark::Counter::kAvgIterations);
  state.counters["bound_changes"] =
      benchmark::Counter(static_cast<double>(flips) / steps, benchmark::Counter::kAvgIterations);
}

void planar_sizes(benchmark::internal::Benchmark* b) {
  for (int n : {3, 6, 12, 24, 48, 96, 192}) b->Arg(n);
}
void spatial_sizes(benchmark::internal::Benchmark* b) {
  for (int n : {7, 14, 28}) b->Arg(n);
}

BENCHMARK_CAPTURE(BM_Scaling, projection_planar, "projection", true)
    ->Apply(planar_sizes)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Scaling, newton_planar, "newton", true)->Apply(planar_sizes)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Scaling, nlopt_planar, "nlopt", true)->Apply(planar_sizes)->Unit(benchmark::kMicrosecond);
// The same chains with p = 0.1: below the p at which the long chains' manipulability ascent overshoots within a step
// (with p = 1, past 48 joints a third of the joints swap velocity bounds every step; see docs/performance.md).
BENCHMARK_CAPTURE(BM_Scaling, newton_planar_p0_1, "newton", true, 0.1)
    ->Apply(planar_sizes)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Scaling, projection_spatial, "projection", false)
    ->Apply(spatial_sizes)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Scaling, newton_spatial, "newton", false)->Apply(spatial_sizes)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Scaling, nlopt_spatial, "nlopt", false)->Apply(spatial_sizes)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace redres

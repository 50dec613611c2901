// Collision avoidance: the cost of one distance query (FCL, per pair), of one collision step (every pair of a
// 7-joint arm against two obstacles plus its self-collision pairs, rows written), and of solving QPs with 0, 4 and
// 16 live inequality rows with each engine (cold solves of random feasible QPs, 7 joints, 3 equality rows).
// Compare within one run, as ratios: the machine is noisy.

#include <random>

#include <benchmark/benchmark.h>

#include "qp_util.hpp"
#include "redres/constraints/obstacle_avoidance.hpp"
#include "redres/constraints/self_collision.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/control/scheme.hpp"
#include "redres/model/collision.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/qp/lvi.hpp"
#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace {

redres::ShapeSpec shape(redres::ShapeSpec::Kind kind) {
  redres::ShapeSpec s;
  s.shape = kind;
  if (kind == redres::ShapeSpec::Kind::kBox) {
    s.size = std::array<double, 3>{0.2, 0.3, 0.4};
  } else {
    s.radius = 0.05;
  }
  if (kind == redres::ShapeSpec::Kind::kCapsule) s.length = 0.3;
  return s;
}

// One query between a capsule and a sphere (analytic in FCL) or a box (GJK), apart.
void BM_DistancePair(benchmark::State& state) {
  const auto other = static_cast<redres::ShapeSpec::Kind>(state.range(0));
  const redres::DistanceQuery q({shape(redres::ShapeSpec::Kind::kCapsule), shape(other)});
  Eigen::Isometry3d Ta = Eigen::Isometry3d::Identity(), Tb = Eigen::Isometry3d::Identity();
  Tb.translation() << 0.4, 0.1, 0.05;
  double x = 0.0;
  for (auto _ : state) {
    Ta.translation().x() = 1e-9 * (x += 1.0);  // a new pose every query
    benchmark::DoNotOptimize(q.distance(0, Ta, 1, Tb).distance);
  }
  state.SetLabel(other == redres::ShapeSpec::Kind::kSphere ? "capsule-sphere" : "capsule-box");
}
BENCHMARK(BM_DistancePair)
    ->Arg(static_cast<int>(redres::ShapeSpec::Kind::kSphere))
    ->Arg(static_cast<int>(redres::ShapeSpec::Kind::kBox));

// One collision step of the Panda: 7 link capsules against 2 obstacles (14 rows) and its 10 self-collision pairs,
// distances, normals, Jacobians and rows (every pair within the influence distance, so every row is written).
void BM_CollisionStep(benchmark::State& state) {
  const redres::RobotModel robot = redres::load_robot(redres::source_path("robots/franka_panda.toml"));
  redres::ShapeSpec sphere = shape(redres::ShapeSpec::Kind::kSphere), box = shape(redres::ShapeSpec::Kind::kBox);
  sphere.xyz = {0.6, 0.2, 0.5};
  box.xyz = {-0.5, 0.4, 0.3};
  std::vector<std::unique_ptr<redres::Constraint>> constraints;
  constraints.push_back(std::make_unique<redres::ObstacleAvoidance>(
      redres::ObstacleAvoidance::Config{.obstacles = {sphere, box}, .influence_distance = 2.0}, robot));
  constraints.push_back(
      std::make_unique<redres::SelfCollision>(redres::SelfCollision::Config{.influence_distance = 2.0}, robot));
  const redres::Scheme scheme(robot, {}, std::move(constraints));
  redres::QpProblem qp;
  redres::SchemeData scheme_data = scheme.make_data();
  scheme.setup(qp, scheme_data);
  redres::KinematicsData kin(robot);
  Eigen::VectorXd theta = robot.home();
  redres::compute_kinematics(robot, theta, kin, redres::KinematicsLevel::kJacobian);
  redres::Context ctx{0.0, 10.0, 0.01, &robot, &kin, nullptr, nullptr};
  for (auto _ : state) {
    scheme.build(ctx, qp, scheme_data);
    benchmark::DoNotOptimize(qp.b.data());
  }
  state.counters["pairs"] = qp.m_in();
  state.counters["per_pair_ns"] = benchmark::Counter(
      static_cast<double>(qp.m_in()), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CollisionStep);

// One obstacle_avoidance step of the Panda (9 link shapes) among `obstacles` static obstacles (spheres, capsules and
// boxes scattered around it, d_i = 0.15 m), brute force (arg 1 = 0) or with FCL's AABB tree (arg 1 = 1).
void BM_ClutterStep(benchmark::State& state) {
  const int count = static_cast<int>(state.range(0));
  const bool tree = state.range(1) != 0;
  const redres::RobotModel robot = redres::load_robot(redres::source_path("robots/franka_panda.toml"));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> pos(-0.9, 0.9), up(0.0, 1.2);
  const redres::ShapeSpec::Kind kinds[] = {redres::ShapeSpec::Kind::kSphere, redres::ShapeSpec::Kind::kCapsule,
                                           redres::ShapeSpec::Kind::kBox};
  std::vector<redres::ShapeSpec> obstacles;
  for (int k = 0; k < count; ++k) {
    redres::ShapeSpec s = shape(kinds[k % 3]);
    s.xyz = {pos(rng), pos(rng), up(rng)};
    obstacles.push_back(s);
  }
  using B = redres::ObstacleAvoidance::Config::Broadphase;
  std::vector<std::unique_ptr<redres::Constraint>> constraints;
  constraints.push_back(std::make_unique<redres::ObstacleAvoidance>(
      redres::ObstacleAvoidance::Config{
          .obstacles = obstacles, .influence_distance = 0.15, .broadphase = tree ? B::kAlways : B::kNever},
      robot));
  const redres::Scheme scheme(robot, {}, std::move(constraints));
  redres::QpProblem qp;
  redres::SchemeData scheme_data = scheme.make_data();
  scheme.setup(qp, scheme_data);
  redres::KinematicsData kin(robot);
  Eigen::VectorXd theta = robot.home();
  redres::Context ctx{0.0, 10.0, 0.01, &robot, &kin, nullptr, nullptr};
  for (auto _ : state) {
    theta(0) += 1e-4;
    redres::compute_kinematics(robot, theta, kin, redres::KinematicsLevel::kJacobian);
    scheme.build(ctx, qp, scheme_data);
    benchmark::DoNotOptimize(qp.b.data());
  }
  state.counters["pairs"] = qp.m_in();
  state.SetLabel(tree ? "aabb-tree" : "brute-force");
}
BENCHMARK(BM_ClutterStep)->ArgsProduct({{10, 40, 160}, {0, 1}});

// 64 random feasible QPs (7 joints, 3 equality rows, `rows` inequality rows) whose rows are live: each one cuts off
// the minimiser without rows (random direction, turned against it), while the known feasible point keeps them
// feasible; several bind at the answer, as when an arm presses against obstacles.
std::vector<redres::QpProblem> live_row_family(int rows) {
  std::mt19937 rng(777);
  std::uniform_real_distribution<double> u(-1.0, 1.0), frac(0.1, 0.9);
  std::vector<redres::QpProblem> family;
  auto exact = redres::make_engine("newton");
  for (int k = 0; k < 64; ++k) {
    const redres::testing::RandomQp base = redres::testing::random_qp(rng, 7, 3, 0);
    redres::SolverResult free;
    exact->setup(7, 3, 0, free);
    exact->reset();
    exact->solve(base.qp, free);
    redres::QpProblem qp = base.qp;
    qp.resize(7, 3, rows);
    qp.W = base.qp.W;
    qp.zeta = base.qp.zeta;
    qp.J = base.qp.J;
    qp.d = base.qp.d;
    qp.lo = base.qp.lo;
    qp.hi = base.qp.hi;
    qp.lo_source = base.qp.lo_source;
    qp.hi_source = base.qp.hi_source;
    qp.source_names = base.qp.source_names;
    qp.eq_source = base.qp.eq_source;
    qp.in_source.assign(static_cast<std::size_t>(rows), 0);
    const Eigen::VectorXd away = free.x - base.feasible;
    for (int r = 0; r < rows; ++r) {
      Eigen::VectorXd a(7);
      for (int i = 0; i < 7; ++i) a(i) = u(rng);
      if (a.dot(away) < 0.0) a = -a;
      qp.A.row(r) = a.normalized().transpose();
      // Between the feasible point (a'f) and the minimiser without rows (a'x0 > a'f): x0 violates the row.
      qp.b(r) = qp.A.row(r).dot(base.feasible) + frac(rng) * qp.A.row(r).dot(away);
    }
    family.push_back(std::move(qp));
  }
  return family;
}

// Cold solves of live_row_family(rows) with one engine; counters: the share solved by the engine itself (not a
// fallback) and the rows active at the answer (z > 0) per solve.
void BM_SolveWithRows(benchmark::State& state, const char* engine_name) {
  const int rows = static_cast<int>(state.range(0));
  const std::vector<redres::QpProblem> family = live_row_family(rows);
  redres::SolverSettings settings;
  settings.tolerance = 1e-8;
  settings.max_iterations = 200000;
  auto engine = redres::make_engine(engine_name, settings);
  redres::SolverResult r;
  engine->setup(7, 3, rows, r);
  std::size_t k = 0;
  int exact = 0, solves = 0;
  long active = 0, iterations = 0;
  for (auto _ : state) {
    engine->reset();
    engine->solve(family[k], r);
    k = (k + 1) % family.size();
    exact += r.info.engine == engine_name ? 1 : 0;
    for (int i = 0; i < rows; ++i) active += r.z(i) > 1e-9 ? 1 : 0;
    iterations += r.info.iterations;
    ++solves;
  }
  state.counters["iterations"] = static_cast<double>(iterations) / std::max(solves, 1);
  state.counters["own_engine_share"] = static_cast<double>(exact) / std::max(solves, 1);
  state.counters["active_rows"] = static_cast<double>(active) / std::max(solves, 1);
}
BENCHMARK_CAPTURE(BM_SolveWithRows, newton, "newton")->Arg(0)->Arg(4)->Arg(16);
BENCHMARK_CAPTURE(BM_SolveWithRows, projection, "projection")->Arg(0)->Arg(4)->Arg(16);
BENCHMARK_CAPTURE(BM_SolveWithRows, nlopt, "nlopt")->Arg(0)->Arg(4)->Arg(16);

// The whole 40 s run of configs/paper_r_obstacle.toml (4001 warm-started steps, one obstacle row live in about half
// of them) with one engine: the control-loop case, where newton's general path settles in about one iteration.
void BM_ObstacleScenario(benchmark::State& state, const char* engine_name) {
  std::string engine_of_run;
  for (auto _ : state) {
    state.PauseTiming();
    redres::Scenario s = redres::load_scenario(redres::source_path("configs/paper_r_obstacle.toml"),
                                               {std::string("solver.engine=") + engine_name});
    state.ResumeTiming();
    const redres::RunResult run = redres::simulate(s);
    engine_of_run = run.engine();
    benchmark::DoNotOptimize(run.trajectory.values().data());
  }
  state.SetLabel(engine_of_run);
}
BENCHMARK_CAPTURE(BM_ObstacleScenario, newton, "newton")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ObstacleScenario, projection, "projection")->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_ObstacleScenario, nlopt, "nlopt")->Unit(benchmark::kMillisecond);

}  // namespace

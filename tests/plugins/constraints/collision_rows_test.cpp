// The collision rows against central differences of the distance itself: for random configurations and random
// joint velocities x, the rate a row constrains, n' (J_a - J_b) x - n' v_obstacle, equals
// (d(theta + h x, t + h) - d(theta - h x, t - h)) / 2h, with d computed independently (a DistanceQuery of its own
// on the kinematics' link frames). Sign, frame and column errors in these rows are the classic bugs; this test
// catches each of them. Also: the damper's bound, slack rows beyond the influence distance, and 0 allocations.

#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "alloc_counter.hpp"
#include "redres/constraints/obstacle_avoidance.hpp"
#include "redres/constraints/self_collision.hpp"
#include "redres/control/controller.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/control/scheme.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/qp/lvi.hpp"
#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

ShapeSpec obstacle(ShapeSpec::Kind kind, std::array<double, 3> xyz, std::optional<std::array<double, 3>> v = {}) {
  ShapeSpec s;
  s.shape = kind;
  if (kind == ShapeSpec::Kind::kBox) {
    s.size = std::array<double, 3>{0.1, 0.15, 0.2};
  } else {
    s.radius = 0.05;
  }
  if (kind == ShapeSpec::Kind::kCapsule || kind == ShapeSpec::Kind::kCylinder) s.length = 0.2;
  s.xyz = xyz;
  s.rpy = {0.0, 0.0, 0.3};
  s.velocity = v;
  return s;
}

// Signed distance between two shapes of `query` on the robot at theta (b < 0: b is obstacle -b-1 at time t).
struct Independent {
  const RobotModel& robot;
  const std::vector<ShapeSpec>& obstacles;
  DistanceQuery query;
  Independent(const RobotModel& r, const std::vector<ShapeSpec>& obs)
      : robot(r), obstacles(obs), query([&] {
          std::vector<ShapeSpec> all;
          for (const auto& l : r.link_shapes()) all.push_back(l.spec);
          for (const auto& o : obs) all.push_back(o);
          return all;
        }()) {}
  double link_obstacle(const Eigen::VectorXd& theta, int l, int o, double t) const {
    KinematicsData k(robot);
    compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
    const auto& s = robot.link_shapes()[static_cast<std::size_t>(l)];
    Eigen::Isometry3d To = obstacles[static_cast<std::size_t>(o)].pose();
    if (const auto& v = obstacles[static_cast<std::size_t>(o)].velocity)
      To.translation() += t * Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]);
    const int L = static_cast<int>(robot.link_shapes().size());
    return query.distance(l, k.link_frames[static_cast<std::size_t>(s.link)] * s.pose, L + o, To).distance;
  }
  double link_link(const Eigen::VectorXd& theta, int a, int b) const {
    KinematicsData k(robot);
    compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
    const auto& sa = robot.link_shapes()[static_cast<std::size_t>(a)];
    const auto& sb = robot.link_shapes()[static_cast<std::size_t>(b)];
    return query
        .distance(a, k.link_frames[static_cast<std::size_t>(sa.link)] * sa.pose, b,
                  k.link_frames[static_cast<std::size_t>(sb.link)] * sb.pose)
        .distance;
  }
};

struct Built {
  std::unique_ptr<Scheme> scheme;
  SchemeData data;
  QpProblem qp;
};

Built build(const RobotModel& robot, std::unique_ptr<Constraint> c) {
  std::vector<std::unique_ptr<Constraint>> constraints;
  constraints.push_back(std::move(c));
  Built b;
  b.scheme = std::make_unique<Scheme>(robot, std::vector<std::unique_ptr<Objective>>{}, std::move(constraints));
  b.data = b.scheme->make_data();
  b.scheme->setup(b.qp, b.data);
  return b;
}

class CollisionRows : public ::testing::TestWithParam<const char*> {};

TEST_P(CollisionRows, ObstacleRowsAreTheRateOfTheDistance) {
  const RobotModel robot = load_robot(source_path(GetParam()));
  const bool planar = robot.kind() == ChainKind::kPlanar;
  const double z = planar ? 0.0 : 0.4;
  const std::vector<ShapeSpec> obstacles = {
      obstacle(ShapeSpec::Kind::kSphere, {0.5, 0.4, z}, std::array<double, 3>{-0.05, 0.02, 0.0}),
      obstacle(ShapeSpec::Kind::kCapsule, {-0.3, 0.6, z}),
      obstacle(ShapeSpec::Kind::kBox, {0.2, 0.8, z}),
  };
  ObstacleAvoidance::Config config{
      .obstacles = obstacles, .influence_distance = 5.0, .safety_distance = 0.01, .xi = 0.3};
  Built b = build(robot, std::make_unique<ObstacleAvoidance>(config, robot));
  const Independent ind(robot, obstacles);
  const Damper damper{5.0, 0.01, 0.3};
  KinematicsData kin(robot);
  std::mt19937 rng(17);
  std::normal_distribution<double> g;
  const int L = static_cast<int>(robot.link_shapes().size());
  int checked = 0;
  for (int rep = 0; rep < 12; ++rep) {
    const Eigen::VectorXd theta = random_inside(robot, rng, 0.1);
    Eigen::VectorXd x(robot.dof());
    for (int j = 0; j < robot.dof(); ++j) x(j) = g(rng);
    const double t = 3.0;
    compute_kinematics(robot, theta, kin, KinematicsLevel::kJacobian);
    Context ctx{t, 10.0, 0.01, &robot, &kin, nullptr, nullptr};
    b.scheme->build(ctx, b.qp, b.data);
    for (int o = 0; o < static_cast<int>(obstacles.size()); ++o) {
      for (int l = 0; l < L; ++l) {
        const int row = o * L + l;
        const double d = ind.link_obstacle(theta, l, o, t);
        if (d <= 0.002) continue;  // near contact the normal is ill-defined
        // Box distances come from GJK (accurate to about 1e-8 m): a wider step keeps its noise out of the quotient;
        // and a capsule nearly parallel to a face has a witness point that is not unique, so the rate is checked
        // to 0.2 % there (a sign, frame or column error is off by far more).
        const bool gjk = obstacles[static_cast<std::size_t>(o)].shape == ShapeSpec::Kind::kBox;
        const double h = gjk ? 1e-4 : 1e-6;
        const double fd =
            (ind.link_obstacle(theta + h * x, l, o, t + h) - ind.link_obstacle(theta - h * x, l, o, t - h)) / (2.0 * h);
        // The row is -n'J x <= -min_rate(d) - n'v: the constrained rate n'J x - n'v is -A x + b + min_rate(d).
        const double rate = -b.qp.A.row(row).dot(x) + b.qp.b(row) + damper.min_rate(d);
        EXPECT_NEAR(rate, fd, (gjk ? 2e-3 : 1e-6) * (1.0 + std::abs(fd)))
            << "row " << row << " (link shape " << l << ", obstacle " << o << ") at d = " << d;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 12 * L);
}

TEST_P(CollisionRows, SelfCollisionRowsAreTheRateOfTheDistance) {
  const RobotModel robot = load_robot(source_path(GetParam()));
  SelfCollision::Config config{.influence_distance = 5.0, .safety_distance = 0.0, .xi = 0.2};
  auto plugin = std::make_unique<SelfCollision>(config, robot);
  const auto pairs = plugin->pairs();
  ASSERT_FALSE(pairs.empty());
  Built b = build(robot, std::move(plugin));
  const Independent ind(robot, {});
  const Damper damper{5.0, 0.0, 0.2};
  KinematicsData kin(robot);
  std::mt19937 rng(23);
  std::normal_distribution<double> g;
  int checked = 0;
  for (int rep = 0; rep < 12; ++rep) {
    const Eigen::VectorXd theta = random_inside(robot, rng, 0.1);
    Eigen::VectorXd x(robot.dof());
    for (int j = 0; j < robot.dof(); ++j) x(j) = g(rng);
    compute_kinematics(robot, theta, kin, KinematicsLevel::kJacobian);
    Context ctx{0.0, 10.0, 0.01, &robot, &kin, nullptr, nullptr};
    b.scheme->build(ctx, b.qp, b.data);
    for (std::size_t row = 0; row < pairs.size(); ++row) {
      const double d = ind.link_link(theta, pairs[row].first, pairs[row].second);
      if (d <= 0.002) continue;
      const double h = 1e-6;
      const double fd = (ind.link_link(theta + h * x, pairs[row].first, pairs[row].second) -
                         ind.link_link(theta - h * x, pairs[row].first, pairs[row].second)) /
                        (2.0 * h);
      const auto r = static_cast<Eigen::Index>(row);
      const double rate = -b.qp.A.row(r).dot(x) + b.qp.b(r) + damper.min_rate(d);
      EXPECT_NEAR(rate, fd, 1e-5 * (1.0 + std::abs(fd))) << "pair " << row << " at d = " << d;
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
}

INSTANTIATE_TEST_SUITE_P(Robots, CollisionRows,
                         ::testing::Values("robots/paper_pushrod_6dof.toml", "robots/planar_4link.toml",
                                           "robots/franka_panda.toml", "robots/kuka_iiwa14.toml",
                                           "robots/kinova_gen3.toml", "robots/ur5e.toml"),
                         [](const ::testing::TestParamInfo<const char*>& p) {
                           std::string n = std::filesystem::path(p.param).stem().string();
                           return n;
                         });

// Every shipped robot starts apart from itself: at its home configuration every checked pair of shapes (links not
// adjacent and not excluded by the robot file) is apart, so self_collision can be switched on from home.
TEST(CollisionRows, EveryShippedRobotIsApartFromItselfAtHome) {
  int robots = 0;
  for (const auto& e : std::filesystem::directory_iterator(source_path("robots"))) {
    if (e.path().extension() != ".toml") continue;
    const RobotModel robot = load_robot(e.path());
    const auto& shapes = robot.link_shapes();
    if (shapes.empty()) continue;
    ++robots;
    const Independent ind(robot, {});
    for (std::size_t a = 0; a < shapes.size(); ++a) {
      for (std::size_t b = a + 1; b < shapes.size(); ++b) {
        if (!robot.self_collision_pair(shapes[a].link, shapes[b].link)) continue;
        EXPECT_GT(ind.link_link(robot.home(), static_cast<int>(a), static_cast<int>(b)), 0.0)
            << e.path().filename() << ": links " << shapes[a].link + 1 << " and " << shapes[b].link + 1;
      }
    }
  }
  EXPECT_GE(robots, 6);
}

TEST(CollisionRows, PairsBeyondTheInfluenceDistanceGetSlackRowsAndTheDamperBoundsTheRest) {
  const RobotModel robot = load_robot(source_path("robots/paper_pushrod_6dof.toml"));
  const std::vector<ShapeSpec> obstacles = {obstacle(ShapeSpec::Kind::kSphere, {5.0, 5.0, 0.0}),
                                            obstacle(ShapeSpec::Kind::kSphere, {0.3, 0.2, 0.0})};
  ObstacleAvoidance::Config config{
      .obstacles = obstacles, .influence_distance = 0.5, .safety_distance = 0.05, .xi = 0.2};
  Built b = build(robot, std::make_unique<ObstacleAvoidance>(config, robot));
  KinematicsData kin(robot);
  compute_kinematics(robot, paper_theta0(), kin, KinematicsLevel::kJacobian);
  Context ctx{0.0, 10.0, 0.01, &robot, &kin, nullptr, nullptr};
  b.scheme->build(ctx, b.qp, b.data);
  const int L = static_cast<int>(robot.link_shapes().size());
  const Independent ind(robot, obstacles);
  for (int l = 0; l < L; ++l) {
    EXPECT_EQ(b.qp.A.row(l).norm(), 0.0);  // the far obstacle: slack
    EXPECT_EQ(b.qp.b(l), 1.0);
    const double d = ind.link_obstacle(paper_theta0(), l, 1, 0.0);
    if (d > 0.5) {
      EXPECT_EQ(b.qp.A.row(L + l).norm(), 0.0);
    } else {
      EXPECT_NEAR(b.qp.b(L + l), 0.2 * (d - 0.05) / (0.5 - 0.05), 1e-12);
    }
  }
}

TEST(CollisionRows, ContributionsAllocateNothingWhileNothingPenetrates) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  const std::vector<ShapeSpec> obstacles = {obstacle(ShapeSpec::Kind::kSphere, {0.6, 0.2, 0.5}),
                                            obstacle(ShapeSpec::Kind::kCapsule, {-0.5, 0.4, 0.3})};
  std::vector<std::unique_ptr<Constraint>> constraints;
  constraints.push_back(std::make_unique<ObstacleAvoidance>(
      ObstacleAvoidance::Config{.obstacles = obstacles, .influence_distance = 2.0}, robot));
  constraints.push_back(std::make_unique<SelfCollision>(SelfCollision::Config{.influence_distance = 2.0}, robot));
  std::vector<std::unique_ptr<Objective>> objectives;
  objectives.push_back(objective_registry().create_default("min_velocity_norm", robot));
  Scheme scheme(robot, std::move(objectives), std::move(constraints));
  QpProblem qp;
  SchemeData scheme_data = scheme.make_data();
  scheme.setup(qp, scheme_data);
  // newton's general path solves the live rows; its solves allocate nothing either.
  auto engine = make_engine("newton");
  SolverResult result;
  engine->setup(qp.n(), qp.m_eq(), qp.m_in(), result);
  KinematicsData kin(robot);
  Eigen::VectorXd theta = robot.home();
  Context ctx{0.0, 10.0, 0.01, &robot, &kin, nullptr, nullptr};
  compute_kinematics(robot, theta, kin, KinematicsLevel::kJacobian);
  scheme.build(ctx, qp, scheme_data);
  engine->solve(qp, result);
  long count = 0;
  int exact = 0;
  {
    const testing::AllocationCounter counter;
    for (int k = 0; k < 200; ++k) {
      theta(0) += 0.001;
      compute_kinematics(robot, theta, kin, KinematicsLevel::kJacobian);
      scheme.build(ctx, qp, scheme_data);
      engine->solve(qp, result);
      exact += result.info.engine == "newton" && result.info.status == SolverStatus::kSolved ? 1 : 0;
    }
    count = counter.count();
  }
  EXPECT_EQ(count, 0);
  EXPECT_EQ(exact, 200);
  EXPECT_GT((qp.A.array() != 0.0).count(), 0);
}

// A cluttered scene (120 obstacles around the Panda: spheres, capsules and boxes, a third of them moving; 960 pairs):
// the broadphase path (FCL's AABB tree) writes exactly the rows of the brute-force path, at random configurations
// and times (its speed is measured by BM_ClutterStep); and, with static obstacles, it allocates nothing per step.
std::vector<ShapeSpec> clutter(std::mt19937& rng, bool moving) {
  std::uniform_real_distribution<double> pos(-0.9, 0.9), up(0.0, 1.2), speed(-0.05, 0.05);
  const ShapeSpec::Kind kinds[] = {ShapeSpec::Kind::kSphere, ShapeSpec::Kind::kCapsule, ShapeSpec::Kind::kBox};
  std::vector<ShapeSpec> out;
  for (int k = 0; k < 120; ++k) {
    std::optional<std::array<double, 3>> v;
    if (moving && k % 3 == 0) v = std::array<double, 3>{speed(rng), speed(rng), speed(rng)};
    out.push_back(obstacle(kinds[k % 3], {pos(rng), pos(rng), up(rng)}, v));
  }
  return out;
}

TEST(CollisionRows, TheBroadphaseWritesTheRowsOfBruteForce) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  std::mt19937 rng(11);
  const std::vector<ShapeSpec> obstacles = clutter(rng, true);
  using B = ObstacleAvoidance::Config::Broadphase;
  const ObstacleAvoidance::Config base{.obstacles = obstacles, .influence_distance = 0.15, .max_rows = 960};
  ObstacleAvoidance::Config tree_config = base, brute_config = base;
  tree_config.broadphase = B::kAuto;  // 8 link shapes x 120 obstacles > kBroadphasePairs
  brute_config.broadphase = B::kNever;
  Built tree = build(robot, std::make_unique<ObstacleAvoidance>(tree_config, robot));
  Built brute = build(robot, std::make_unique<ObstacleAvoidance>(brute_config, robot));
  ASSERT_GT(tree.qp.m_in(), kBroadphasePairs);
  KinematicsData kin(robot);
  int live = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::VectorXd theta = random_inside(robot, rng, 0.1);
    compute_kinematics(robot, theta, kin, KinematicsLevel::kJacobian);
    const double t = 0.5 * trial;  // the moving obstacles wander
    Context ctx{t, 20.0, 0.01, &robot, &kin, nullptr, nullptr};
    tree.scheme->build(ctx, tree.qp, tree.data);
    brute.scheme->build(ctx, brute.qp, brute.data);
    for (int r = 0; r < tree.qp.m_in(); ++r) {
      ASSERT_EQ(tree.qp.b(r), brute.qp.b(r)) << "trial " << trial << " row " << r;
      ASSERT_EQ((tree.qp.A.row(r) - brute.qp.A.row(r)).norm(), 0.0) << "trial " << trial << " row " << r;
      live += brute.qp.A.row(r).norm() > 0.0 ? 1 : 0;
    }
  }
  EXPECT_GT(live, 40);  // pairs within d_i occur, so the comparison covers real rows
}

// More pairs than max_rows: the pairs within d_i share the rows, the nearest first. Each shared row is the row the
// pair has when every pair has one, and no pair left without a row is nearer than one that has a row.
TEST(CollisionRows, SharedRowsHoldTheNearestPairs) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  std::mt19937 rng(13);
  const std::vector<ShapeSpec> obstacles = clutter(rng, false);
  const ObstacleAvoidance::Config full_config{.obstacles = obstacles, .influence_distance = 0.3, .max_rows = 960};
  ObstacleAvoidance::Config shared_config = full_config;
  shared_config.max_rows = 8;
  Built full = build(robot, std::make_unique<ObstacleAvoidance>(full_config, robot));
  Built shared = build(robot, std::make_unique<ObstacleAvoidance>(shared_config, robot));
  ASSERT_EQ(full.qp.m_in(), 960);
  ASSERT_EQ(shared.qp.m_in(), 8);
  KinematicsData kin(robot);
  int crowded = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::VectorXd theta = random_inside(robot, rng, 0.1);
    compute_kinematics(robot, theta, kin, KinematicsLevel::kJacobian);
    Context ctx{0.0, 20.0, 0.01, &robot, &kin, nullptr, nullptr};
    full.scheme->build(ctx, full.qp, full.data);
    shared.scheme->build(ctx, shared.qp, shared.data);
    // The live rows of the full QP, with their pairs' rates (b).
    std::vector<std::pair<double, int>> live;  // (b, row): b grows with the distance (the damper's bound, static)
    for (int r = 0; r < 960; ++r) {
      if (full.qp.A.row(r).norm() > 0.0 || full.qp.b(r) != 1.0) live.emplace_back(full.qp.b(r), r);  // not slack
    }
    std::sort(live.begin(), live.end());
    crowded += live.size() > 8 ? 1 : 0;
    int held = 0;
    for (int r = 0; r < 8; ++r) {
      if (shared.qp.A.row(r).norm() == 0.0 && shared.qp.b(r) == 1.0) continue;  // slack
      ++held;
      // The same row as one of the full QP's, and among the 8 nearest.
      const auto same = std::find_if(live.begin(), live.end(), [&](const auto& e) {
        return e.first == shared.qp.b(r) && (full.qp.A.row(e.second) - shared.qp.A.row(r)).norm() == 0.0;
      });
      ASSERT_NE(same, live.end()) << "trial " << trial << " shared row " << r;
      EXPECT_LT(same - live.begin(), 8) << "trial " << trial << ": a farther pair holds a row";
    }
    EXPECT_EQ(held, static_cast<int>(std::min<std::size_t>(live.size(), 8))) << "trial " << trial;
  }
  EXPECT_GT(crowded, 5) << "more pairs within d_i than rows occur, so the sharing is tested";
}

// A box link gets a row for each corner besides its witness point's: each corner row is the rate of that corner's
// distance to the obstacle (central differences), and a flat face turning over a box obstacle stays at d_s
// (tests/data/scenarios/box_hand_over_box.toml: with one row per pair, the next corner sank 0.12 mm through d_s
// there; what remains is the step's second-order motion, some 1e-5 m).
TEST(CollisionRows, ABoxLinkHoldsEachCornerAtTheSafetyDistance) {
  Scenario s = load_scenario(data_path("scenarios/box_hand_over_box.toml"));
  const RobotModel& robot = *s.robot;
  const auto controller = Controller::from_scenario(s);
  EXPECT_EQ(controller->qp().m_in(), 3 + 9) << "three capsule links, and the box link's witness and 8 corners";
  const RunResult run = simulate(s);
  const std::size_t col = run.trajectory.column("min_obstacle_distance");
  double lowest = std::numeric_limits<double>::infinity();
  for (std::size_t r = 0; r < run.trajectory.size(); ++r) lowest = std::min(lowest, run.trajectory(r, col));
  RecordProperty("lowest_distance", std::to_string(lowest));
  EXPECT_GE(lowest, 0.02 - 5e-5);
  // Corner rows at a state of the run where the box is within d_i: rate of the corner's distance.
  const std::size_t row = run.trajectory.size() / 2;
  const Eigen::VectorXd theta = recorded_theta(robot, run.trajectory, row);
  const double t = run.trajectory.at(row, "t");
  StepOutput out = controller->make_output();
  controller->step(theta, t, out);
  const QpProblem& qp = controller->qp();
  const auto& box = robot.link_shapes()[3];
  ASSERT_EQ(box.spec.shape, ShapeSpec::Kind::kBox);
  const auto* avoid = dynamic_cast<const ObstacleAvoidance*>(s.scheme->constraints()[2].get());
  ASSERT_NE(avoid, nullptr);
  std::vector<ShapeSpec> obstacles;
  avoid->scene_obstacles(obstacles);
  ASSERT_EQ(obstacles.size(), 1u);
  ShapeSpec ob = obstacles[0];
  ob.xyz = {0.0, 0.0, 0.0};  // its pose is obstacle_pose()
  const DistanceQuery query({box.spec, ob});
  const Eigen::Isometry3d To = avoid->obstacle_pose(0, t);
  const auto corner_distance = [&](const Eigen::VectorXd& th, int c) {
    KinematicsData k(robot);
    compute_kinematics(robot, th, k, KinematicsLevel::kPosition);
    const Eigen::Isometry3d Tl = k.link_frames[static_cast<std::size_t>(box.link)] * box.pose;
    const auto& size = *box.spec.size;
    const Eigen::Vector3d p = Tl * Eigen::Vector3d(((c & 1) ? 0.5 : -0.5) * size[0], ((c & 2) ? 0.5 : -0.5) * size[1],
                                                   ((c & 4) ? 0.5 : -0.5) * size[2]);
    return (p - query.nearest_point(1, To, p)).norm();
  };
  std::mt19937 rng(17);
  std::normal_distribution<double> normal;
  int live = 0;
  const int first = qp.m_in() - 12 + 3 + 1;  // the box's corner rows follow its witness row (the 4th pair)
  for (int c = 0; c < 8; ++c) {
    const int r = first + c;
    if (qp.A.row(r).norm() == 0.0) continue;  // a corner beyond d_i
    ++live;
    Eigen::VectorXd x(robot.dof());
    for (int j = 0; j < x.size(); ++j) x(j) = normal(rng);
    const double h = 1e-6;
    const double rate = (corner_distance(theta + h * x, c) - corner_distance(theta - h * x, c)) / (2 * h);
    EXPECT_NEAR(-qp.A.row(r).dot(x), rate, 1e-6 * (1.0 + std::abs(rate))) << "corner " << c;
  }
  EXPECT_GE(live, 2) << "the face's corners near the obstacle have rows";
}

TEST(CollisionRows, TheBroadphaseAllocatesNothingPerStepWithStaticObstacles) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  std::mt19937 rng(12);
  Built b =
      build(robot, std::make_unique<ObstacleAvoidance>(
                       ObstacleAvoidance::Config{.obstacles = clutter(rng, false), .influence_distance = 0.15}, robot));
  KinematicsData kin(robot);
  Eigen::VectorXd theta = robot.home();
  Context ctx{0.0, 10.0, 0.01, &robot, &kin, nullptr, nullptr};
  compute_kinematics(robot, theta, kin, KinematicsLevel::kJacobian);
  b.scheme->build(ctx, b.qp, b.data);  // places the obstacles in the tree
  long count = 0;
  {
    const testing::AllocationCounter counter;
    for (int k = 0; k < 100; ++k) {
      theta(0) += 0.002;
      compute_kinematics(robot, theta, kin, KinematicsLevel::kJacobian);
      b.scheme->build(ctx, b.qp, b.data);
    }
    count = counter.count();
  }
  EXPECT_EQ(count, 0);
}

}  // namespace
}  // namespace redres

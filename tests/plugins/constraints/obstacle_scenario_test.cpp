// The shipped obstacle scenarios (configs/paper_r_obstacle.toml, a static sphere, and
// configs/paper_r_moving_obstacle.toml, a sphere crossing the workspace) on real runs: with the constraint every
// link stays at least the safety distance from the obstacle and the R is written to the paper's accuracy; the same
// run without the constraint goes closer than the safety distance (so this test can fail); a start in collision is
// a failed step that names the pair and its distance. Distances are recomputed here, independently, from the
// recorded angles and time (a moving obstacle is at p0 + v t).

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "redres/constraints/obstacle_avoidance.hpp"
#include "redres/parsers/cloud_file.hpp"
#include "redres/run/run_summary.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

// The smallest distance between the robot's link shapes and the scenario's obstacles over a recorded run.
double min_distance(const Scenario& s, const Trajectory& tr, const std::vector<ShapeSpec>& obstacles) {
  const RobotModel& robot = *s.robot;
  std::vector<ShapeSpec> shapes;
  for (const auto& l : robot.link_shapes()) shapes.push_back(l.spec);
  for (const auto& o : obstacles) shapes.push_back(o);
  const DistanceQuery q(shapes);
  KinematicsData k(robot);
  Eigen::VectorXd theta(robot.dof());
  double low = 1e9;
  const int L = static_cast<int>(robot.link_shapes().size());
  for (std::size_t r = 0; r < tr.size(); ++r) {
    theta = recorded_theta(robot, tr, r);
    compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
    const double t = tr(r, tr.column("t"));
    for (int l = 0; l < L; ++l) {
      const auto& shape = robot.link_shapes()[static_cast<std::size_t>(l)];
      for (std::size_t o = 0; o < obstacles.size(); ++o) {
        Eigen::Isometry3d at = obstacles[o].pose();
        if (obstacles[o].velocity) at.pretranslate(t * Eigen::Vector3d(obstacles[o].velocity->data()));
        low = std::min(low, q.distance(l, k.link_frames[static_cast<std::size_t>(shape.link)] * shape.pose,
                                       L + static_cast<int>(o), at)
                                .distance);
      }
    }
  }
  return low;
}

const ObstacleAvoidance& plugin_of(const Scenario& s) {
  for (const auto& c : s.scheme->constraints()) {
    if (const auto* p = dynamic_cast<const ObstacleAvoidance*>(c.get())) return *p;
  }
  throw std::logic_error("the scenario has no obstacle_avoidance");
}

// The smallest distance between shapes of two links that self_collision checks, over a recorded run.
double min_self_distance(const Scenario& s, const Trajectory& tr) {
  const RobotModel& robot = *s.robot;
  std::vector<ShapeSpec> shapes;
  for (const auto& l : robot.link_shapes()) shapes.push_back(l.spec);
  const DistanceQuery q(shapes);
  KinematicsData k(robot);
  Eigen::VectorXd theta(robot.dof());
  double low = 1e9;
  const auto& ls = robot.link_shapes();
  for (std::size_t r = 0; r < tr.size(); ++r) {
    theta = recorded_theta(robot, tr, r);
    compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
    for (std::size_t a = 0; a < ls.size(); ++a) {
      for (std::size_t b = a + 1; b < ls.size(); ++b) {
        if (!robot.self_collision_pair(ls[a].link, ls[b].link)) continue;
        low = std::min(low,
                       q.distance(static_cast<int>(a), k.link_frames[static_cast<std::size_t>(ls[a].link)] * ls[a].pose,
                                  static_cast<int>(b), k.link_frames[static_cast<std::size_t>(ls[b].link)] * ls[b].pose)
                           .distance);
      }
    }
  }
  return low;
}

struct ObstacleCase {
  const char* config;
  double max_position_error;  // the scheme's own accuracy on the same path without obstacles, with a margin
};

void PrintTo(const ObstacleCase& c, std::ostream* os) { *os << c.config; }

class ObstacleScenarios : public ::testing::TestWithParam<ObstacleCase> {};

TEST_P(ObstacleScenarios, LinksKeepTheSafetyDistanceAndTheTaskIsMet) {
  const std::string file = std::string("configs/") + GetParam().config + ".toml";
  Scenario s = load_scenario(source_path(file));
  const auto& config = plugin_of(s).settings();
  const RunResult run = simulate(s);
  const RunSummary sum = summarise(s, run);
  EXPECT_EQ(sum.solver.failures, 0) << sum.solver.first_failure;
  EXPECT_EQ(run.engine(), s.engine.type) << "a step fell back to another engine";
  EXPECT_LT(sum.max_position_error, GetParam().max_position_error);
  const double d = min_distance(s, run.trajectory, config.obstacles);
  EXPECT_GE(d, config.safety_distance - 1e-4);
  const Metric* m = sum.metric("obstacle_avoidance", "min_obstacle_distance");
  ASSERT_NE(m, nullptr);
  EXPECT_NEAR(m->values.at(0), d, 1e-9);
  const Metric* active = sum.metric("obstacle_avoidance", "steps_with_active_rows");
  ASSERT_NE(active, nullptr);
  EXPECT_GT(active->values.at(0), 0.0);
  RecordProperty("min_distance_with_constraint", std::to_string(d));
  if (const Metric* self = sum.metric("self_collision", "min_self_distance")) {
    // The smallest distance measured, or, when no pair ever came within d_i (pairs beyond it are culled, not
    // measured), d_i as the stated value.
    const double ds = min_self_distance(s, run.trajectory);
    const double di = sum.metric("self_collision", "influence_distance")->values.at(0);
    EXPECT_NEAR(self->values.at(0), std::min(ds, di), 1e-9);
    EXPECT_GE(ds, sum.metric("self_collision", "safety_distance")->values.at(0) - 1e-4);
  }

  // Without the constraint a link runs into the obstacle.
  Scenario off = load_scenario(source_path(file), {"constraints.3.active=false"});
  const RunResult free_run = simulate(off);
  const double d_free = min_distance(off, free_run.trajectory, config.obstacles);
  EXPECT_LT(d_free, 0.0);
  RecordProperty("min_distance_without_constraint", std::to_string(d_free));
}

INSTANTIATE_TEST_SUITE_P(Configs, ObstacleScenarios,
                         ::testing::Values(ObstacleCase{"paper_r_obstacle", 1e-5},
                                           ObstacleCase{"paper_r_moving_obstacle", 1e-5},
                                           ObstacleCase{"panda_table_pole", 1e-4},
                                           ObstacleCase{"panda_point_cloud", 1e-4}),
                         [](const ::testing::TestParamInfo<ObstacleCase>& c) { return std::string(c.param.config); });

// The point-cloud scenario against the points themselves, by brute force (every 10th recorded row, every capsule or
// sphere link, all 100,000 points): the grown cells hold each point's ball of the obstacle's radius, so every link
// keeps the safety distance from those balls too, and the closest approach to them is within a cell's diagonal of the
// one the run reports.
TEST(ObstacleScenario, ThePointCloudRunKeepsItsLinksOffThePointsThemselves) {
  Scenario s = load_scenario(source_path("configs/panda_point_cloud.toml"));
  const auto& config = plugin_of(s).settings();
  ASSERT_EQ(config.obstacles.size(), 1U);
  const ShapeSpec& cloud = config.obstacles[0];
  const std::vector<Eigen::Vector3d> points = read_points(source_path("configs/clouds/panda_workcell.ply"));
  ASSERT_EQ(points.size(), 100000U);
  const RunResult run = simulate(s);
  const RobotModel& robot = *s.robot;
  KinematicsData k(robot);
  double low = 1e9;
  int links = 0;
  for (std::size_t r = 0; r < run.trajectory.size(); r += 10) {
    compute_kinematics(robot, recorded_theta(robot, run.trajectory, r), k, KinematicsLevel::kPosition);
    links = 0;
    for (const auto& shape : robot.link_shapes()) {
      if (shape.spec.shape != ShapeSpec::Kind::kCapsule && shape.spec.shape != ShapeSpec::Kind::kSphere) continue;
      ++links;
      const Eigen::Isometry3d T =
          cloud.pose().inverse() * k.link_frames[static_cast<std::size_t>(shape.link)] * shape.pose;
      const double h = shape.spec.shape == ShapeSpec::Kind::kCapsule ? 0.5 * shape.spec.axis_length() : 0.0;
      const Eigen::Vector3d a = T * Eigen::Vector3d(0, 0, -h), b = T * Eigen::Vector3d(0, 0, h);
      const Eigen::Vector3d ab = b - a;
      for (const Eigen::Vector3d& p : points) {
        const double u = h > 0.0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
        low = std::min(low, (a + u * ab - p).norm() - *shape.spec.radius - *cloud.radius);
      }
    }
  }
  EXPECT_GE(links, 6) << "most of the Panda's links are capsules";
  EXPECT_GE(low, config.safety_distance - 1e-4);
  const double reported = summarise(s, run).metric("obstacle_avoidance", "min_obstacle_distance")->values.at(0);
  EXPECT_LE(reported, low + 1e-9);
  EXPECT_GE(reported, low - std::sqrt(3.0) * *cloud.resolution - 0.01) << "sampled every 10th row";
  RecordProperty("min_distance_to_points", std::to_string(low));
}

// The moving-sphere run is solved by newton itself on every step (its rows live on about half of them), and the
// closest approach happens while the sphere passes the elbow, not at the start or the end of the run.
TEST(ObstacleScenario, TheMovingSphereIsPassedByNewtonOnEveryStep) {
  Scenario s = load_scenario(source_path("configs/paper_r_moving_obstacle.toml"));
  const RunResult run = simulate(s);
  EXPECT_EQ(run.engine(), "newton") << "a step fell back to projection";
  EXPECT_EQ(run.failures, 0) << run.first_failure;
  const Trajectory& tr = run.trajectory;
  const auto col = tr.column("min_obstacle_distance");
  std::size_t closest = 0;
  for (std::size_t r = 0; r < tr.size(); ++r) {
    if (tr(r, col) < tr(closest, col)) closest = r;
  }
  const double t_closest = tr(closest, tr.column("t"));
  EXPECT_GT(t_closest, 5.0);
  EXPECT_LT(t_closest, 35.0);
}

// The exact engine solves the live collision rows itself (its general path), on every step, and ends where the
// paper's projection algorithm ends.
TEST(ObstacleScenario, NewtonSolvesTheCollisionRowsItself) {
  Scenario proj = load_scenario(source_path("configs/paper_r_obstacle.toml"));
  Scenario newton = load_scenario(source_path("configs/paper_r_obstacle.toml"), {"solver.engine=newton"});
  const RunResult a = simulate(proj), b = simulate(newton);
  EXPECT_EQ(b.engine(), "newton") << "a step fell back to projection";
  EXPECT_EQ(b.failures, 0) << b.first_failure;
  const RunSummary sa = summarise(proj, a), sb = summarise(newton, b);
  for (std::size_t j = 0; j < sa.final_theta.size(); ++j) EXPECT_NEAR(sb.final_theta[j], sa.final_theta[j], 1e-5);
  const double d = min_distance(newton, b.trajectory, plugin_of(newton).settings().obstacles);
  EXPECT_GE(d, plugin_of(newton).settings().safety_distance - 1e-6);
  EXPECT_LT(sb.solver.mean_iterations, 3.0);
}

TEST(ObstacleScenario, AStartInCollisionIsAFailedStepNamingThePair) {
  // A sphere overlapping the second link by 5 mm at t = 0: the damper can push the link out, so the solve succeeds,
  // and the step fails on the violation; then a sphere deep on the link, where the step cannot be solved: the
  // infeasible solve's diagnosis names the same pair. Either way: the time, the pair and its negative distance.
  for (const char* at : {"[0.2550, 0.3559, 0.0]", "[0.285, 0.338, 0.0]"}) {
    SCOPED_TRACE(at);
    Scenario s = load_scenario(source_path("configs/paper_r_obstacle.toml"),
                               {"duration=0.1", std::string("constraints.3.obstacles=[{ shape = \"sphere\", radius = "
                                                            "0.02, xyz = ") +
                                                    at + " }]"});
    const RunResult run = simulate(s);
    ASSERT_GT(run.failures, 0);
    EXPECT_EQ(run.first_failure.rfind("t = 0 s: ", 0), 0u) << run.first_failure;
    EXPECT_NE(run.first_failure.find("link 'joint2' capsule(r = 0.02 m, l = 0.29 m) vs obstacle 1 sphere(r = 0.02 m) "
                                     "at distance -"),
              std::string::npos)
        << run.first_failure;
  }
}

// A sphere on the hand's own path (inside the R's bowl): the task and the damper cannot both hold, so the run has
// failed steps, the first one infeasible at t > 0 with a diagnosis that names the task rows and the link-obstacle
// pair with its distance; the recorded trajectory stays finite (no silent NaN).
TEST(ObstacleScenario, AnObstacleOnThePathIsAnInfeasibleStepNamingThePair) {
  Scenario s =
      load_scenario(source_path("configs/paper_r_obstacle.toml"),
                    {R"(constraints.3.obstacles=[{ shape = "sphere", radius = 0.015, xyz = [0.32, 1.11, 0.0] }])"});
  const RunResult run = simulate(s);
  ASSERT_GT(run.failures, 0);
  EXPECT_EQ(run.first_failure.rfind("t = 0 s", 0), std::string::npos) << run.first_failure;
  EXPECT_NE(run.first_failure.find("infeasible"), std::string::npos) << run.first_failure;
  EXPECT_NE(run.first_failure.find("from 'task_tracking'"), std::string::npos) << run.first_failure;
  EXPECT_NE(run.first_failure.find("from 'obstacle_avoidance': link 'joint6' capsule(r = 0.02 m, l = 0.103 m) vs "
                                   "obstacle 1 sphere(r = 0.015 m) at distance "),
            std::string::npos)
      << run.first_failure;
  const Trajectory& tr = run.trajectory;
  for (std::size_t r = 0; r < tr.size(); ++r) {
    for (std::size_t c = 0; c < tr.width(); ++c) {
      ASSERT_TRUE(std::isfinite(tr(r, c))) << "row " << r << ", column " << tr.columns()[c];
    }
  }
}

}  // namespace
}  // namespace redres

// The paper's claims, checked on real runs of configs/paper_r_*.toml (tau = 0.01 s, the paper's algorithm eq. 15),
// and the same runs with the exact engine.

#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

struct PaperRun {
  Scenario scenario;
  RunResult result;
};

PaperRun run(const std::string& config, const std::vector<std::string>& overrides = {}) {
  PaperRun r{load_scenario(source_path("configs/" + config + ".toml"), overrides), {}};
  r.result = simulate(r.scenario);
  return r;
}

const PaperRun& cached(const std::string& config) {
  static std::map<std::string, PaperRun> runs;
  auto it = runs.find(config);
  if (it == runs.end()) it = runs.emplace(config, run(config)).first;
  return it->second;
}

double joint_velocity_norm(const PaperRun& r, std::size_t row) {
  double sq = 0.0;
  for (int j = 1; j <= r.scenario.robot->dof(); ++j)
    sq += std::pow(r.result.trajectory.at(row, "theta_dot_" + std::to_string(j)), 2);
  return std::sqrt(sq);
}

TEST(PaperClaims, RunsUseTheSettingsOfThePaper) {
  const PaperRun& tv = cached("paper_r_tvcmm");
  EXPECT_EQ(tv.scenario.steps(), 4000);
  EXPECT_DOUBLE_EQ(tv.scenario.tau, 0.01);
  EXPECT_EQ(tv.scenario.engine.type, "projection");
  EXPECT_EQ(tv.result.trajectory.size(), 4001u);
  EXPECT_EQ(tv.result.failures, 0) << tv.result.first_failure;
  EXPECT_LT((tv.scenario.theta0 - paper_theta0()).norm(), 1e-15);
}

TEST(PaperClaims, TvcmmStartsAndEndsAtRestWhileConstantPDoesNot) {
  const PaperRun& tv = cached("paper_r_tvcmm");
  const PaperRun& p1 = cached("paper_r_constant_p");
  EXPECT_LE(joint_velocity_norm(tv, 0), 1e-4);
  EXPECT_LE(joint_velocity_norm(tv, tv.result.trajectory.size() - 1), 1e-4);
  EXPECT_GE(joint_velocity_norm(p1, 0), 0.05);
}

TEST(PaperClaims, TvcmmManipulabilityIsNeverBelowMvn) {
  const PaperRun& tv = cached("paper_r_tvcmm");
  const PaperRun& mvn = cached("paper_r_mvn");
  ASSERT_EQ(tv.result.trajectory.size(), mvn.result.trajectory.size());
  double worst = 1e300;
  for (std::size_t k = 1; k < tv.result.trajectory.size(); ++k) {
    const double d = tv.result.trajectory.at(k, "manipulability") - mvn.result.trajectory.at(k, "manipulability");
    worst = std::min(worst, d);
    ASSERT_GE(d, -1e-9) << "t = " << tv.result.trajectory.at(k, "t");
  }
  // And it is clearly larger over the task.
  EXPECT_GT(tv.result.trajectory.at(2000, "manipulability"), mvn.result.trajectory.at(2000, "manipulability") + 0.005);
}

TEST(PaperClaims, ConstantPLeadsEarlyThenTvcmmCatchesUpAfterEightSeconds) {
  const PaperRun& tv = cached("paper_r_tvcmm");
  const PaperRun& p1 = cached("paper_r_constant_p");
  int early_lead = 0, early = 0;
  for (std::size_t k = 1; k < tv.result.trajectory.size(); ++k) {
    const double t = tv.result.trajectory.at(k, "t");
    const double w_tv = tv.result.trajectory.at(k, "manipulability"),
                 w_p1 = p1.result.trajectory.at(k, "manipulability");
    if (t <= 4.0) {
      ++early;
      early_lead += w_p1 > w_tv ? 1 : 0;
    }
    if (t >= 8.0) {
      EXPECT_LE(std::abs(w_p1 - w_tv), 0.01 * w_tv) << "t = " << t;
    }
  }
  EXPECT_EQ(early_lead, early);  // larger at every step of the first 4 s
}

class PaperSafety : public ::testing::TestWithParam<const char*> {};

TEST_P(PaperSafety, LimitsHoldAndTheTaskIsTracked) {
  const PaperRun& r = cached(GetParam());
  const RobotModel& robot = *r.scenario.robot;
  double angle_viol = 0.0, safety_entry = 0.0, vel_viol = 0.0, max_err = 0.0;
  for (std::size_t k = 0; k < r.result.trajectory.size(); ++k) {
    for (int j = 0; j < robot.dof(); ++j) {
      const std::string J = std::to_string(j + 1);
      const double th = r.result.trajectory.at(k, "theta_" + J), thd = r.result.trajectory.at(k, "theta_dot_" + J);
      const double lo = robot.lower_limits()(j), hi = robot.upper_limits()(j);
      angle_viol = std::max({angle_viol, th - hi, lo - th});
      safety_entry = std::max({safety_entry, th - (hi - 0.0349), (lo + 0.0349) - th});
      // The velocity law evaluated here, independently of the recorded columns.
      const VelocityBounds b = robot.joint(j).velocity_limit->bounds(th);
      vel_viol = std::max({vel_viol, thd - b.upper, b.lower - thd});
    }
    max_err = std::max(max_err, r.result.trajectory.at(k, "position_error"));
  }
  EXPECT_LE(angle_viol, 0.0);
  EXPECT_LE(safety_entry, 1e-6);
  EXPECT_LE(vel_viol, 0.0);
  EXPECT_LE(max_err, 1e-5);
}

INSTANTIATE_TEST_SUITE_P(Schemes, PaperSafety, ::testing::Values("paper_r_tvcmm", "paper_r_constant_p", "paper_r_mvn"));

class PaperEngines : public ::testing::TestWithParam<const char*> {};

// The exact engine reaches the same final configuration as the paper's algorithm.
TEST_P(PaperEngines, NewtonEndsWhereProjectionEnds) {
  const PaperRun& proj = cached(GetParam());
  const PaperRun newton = run(GetParam(), {"solver.engine=newton"});
  EXPECT_EQ(newton.result.engine(), "newton");
  EXPECT_EQ(newton.result.failures, 0);
  const std::size_t last = proj.result.trajectory.size() - 1;
  for (int j = 1; j <= proj.scenario.robot->dof(); ++j) {
    const std::string c = "theta_" + std::to_string(j);
    EXPECT_NEAR(newton.result.trajectory.at(last, c), proj.result.trajectory.at(last, c), 1e-6) << c;
  }
}

INSTANTIATE_TEST_SUITE_P(Schemes, PaperEngines,
                         ::testing::Values("paper_r_tvcmm", "paper_r_constant_p", "paper_r_mvn"));

// Sixteen times faster: the push-rod velocity limits bind in part of the steps and are never exceeded.
TEST(PaperFast, VelocityBoundsAreActiveAndNeverViolated) {
  const PaperRun r = run("paper_r_fast");
  EXPECT_EQ(r.result.failures, 0) << r.result.first_failure;
  const RobotModel& robot = *r.scenario.robot;
  int law_active = 0;
  double viol = 0.0;
  for (std::size_t k = 0; k < r.result.trajectory.size(); ++k) {
    bool active = false;
    for (int j = 0; j < robot.dof(); ++j) {
      const std::string J = std::to_string(j + 1);
      const double th = r.result.trajectory.at(k, "theta_" + J), thd = r.result.trajectory.at(k, "theta_dot_" + J);
      const VelocityBounds b = robot.joint(j).velocity_limit->bounds(th);
      viol = std::max({viol, thd - b.upper, b.lower - thd});
      active = active || std::abs(thd - b.upper) <= 1e-9 || std::abs(thd - b.lower) <= 1e-9;
    }
    law_active += active ? 1 : 0;
  }
  const double fraction = static_cast<double>(law_active) / static_cast<double>(r.result.trajectory.size());
  RecordProperty("velocity_law_active_fraction", std::to_string(fraction));
  EXPECT_GT(law_active, 0) << "the push-rod limits never bind, so the run does not test them";
  EXPECT_LT(fraction, 1.0);
  EXPECT_LE(viol, 0.0);
}

}  // namespace
}  // namespace redres

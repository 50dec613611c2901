// A loaded scenario is a value that runs only read (run/scenario.hpp): every run makes its own controller, engine
// (with its warm start) and plugin data, so two runs of one scenario at once, in two threads, each give what a run
// alone gives, bit for bit; and a run leaves the scenario as it found it.

#include <algorithm>
#include <cstring>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

void expect_same_run(const RunResult& a, const RunResult& b, const char* what) {
  ASSERT_EQ(a.trajectory.columns(), b.trajectory.columns()) << what;
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size()) << what;
  const auto x = a.trajectory.values(), y = b.trajectory.values();
  std::size_t differing = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    // Bit for bit, NaN entries included.
    if (std::memcmp(&x[i], &y[i], sizeof(double)) != 0) ++differing;
  }
  EXPECT_EQ(differing, 0U) << what;
  EXPECT_EQ(a.failures, b.failures) << what;
}

TEST(ScenarioValue, TwoRunsOfOneScenarioAtOnceEachGiveTheRunAlone) {
  // The Panda past a table and a pole: collision constraints with per-run distance data, a warm-started engine.
  for (const char* config : {"configs/panda_table_pole.toml", "configs/panda_tool_elbow_posture.toml"}) {
    SCOPED_TRACE(config);
    const Scenario s = load_scenario(source_path(config), {"duration=1.0"});
    const RunResult alone = simulate(s);
    ASSERT_GT(alone.trajectory.size(), 50U);
    RunResult first, second;
    std::thread a([&] { simulate(s, first); });
    std::thread b([&] { simulate(s, second); });
    a.join();
    b.join();
    expect_same_run(alone, first, "first thread");
    expect_same_run(alone, second, "second thread");
    // And a run after them: nothing of the earlier runs (a warm start, a plugin's state) stayed with the scenario.
    expect_same_run(alone, simulate(s), "a run after both");
  }
}

TEST(ScenarioValue, ControllersOfOneScenarioHaveEnginesOfTheirOwn) {
  const Scenario s = load_scenario(source_path("configs/paper_r_fast.toml"));
  const auto c1 = Controller::from_scenario(s), c2 = Controller::from_scenario(s);
  StepOutput o1 = c1->make_output(), o2 = c2->make_output();
  // c1 steps along; c2 starts cold at the same state each time its turn comes: c1's warm start is not c2's.
  Eigen::VectorXd theta = s.theta0;
  for (int k = 0; k < 20; ++k) {
    c1->step(theta, k * s.tau, o1);
    theta += s.tau * o1.theta_dot;
  }
  c2->step(theta, 20 * s.tau, o2);
  c1->step(theta, 20 * s.tau, o1);
  EXPECT_EQ(o2.info.engine, o1.info.engine);
  EXPECT_GT(o2.info.iterations, o1.info.iterations) << "a cold start takes more iterations than a warm one";
  EXPECT_NEAR((o1.theta_dot - o2.theta_dot).cwiseAbs().maxCoeff(), 0.0, 1e-3);
}

}  // namespace
}  // namespace redres

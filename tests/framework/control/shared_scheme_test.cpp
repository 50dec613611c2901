// A scheme is immutable: everything a step writes lives in each controller's plugin data (Scheme::make_data()).
// Two controllers on one scheme, stepping at the same time in two threads, give bit for bit what one controller
// gives alone, on scenarios whose constraints keep per-step state (FCL distance queries with a broadphase tree,
// pair distances, scratch Jacobians).

#include <cstring>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "redres/control/collision_rows.hpp"
#include "redres/control/controller.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/run/scenario.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

// What a closed loop saw: theta and theta_dot after every step, the status, and every collision constraint's pair
// distances (from its data in this controller).
struct Loop {
  std::vector<double> values;
  int failures = 0;
};

Loop run_loop(Controller& ctrl, const Eigen::VectorXd& theta0, double tau, int steps) {
  Loop loop;
  StepOutput out = ctrl.make_output();
  Eigen::VectorXd theta = theta0;
  for (int k = 0; k < steps; ++k) {
    ctrl.step(theta, k * tau, out);
    if (out.info.status != SolverStatus::kSolved) ++loop.failures;
    theta += tau * out.theta_dot;
    loop.values.insert(loop.values.end(), theta.data(), theta.data() + theta.size());
    loop.values.insert(loop.values.end(), out.theta_dot.data(), out.theta_dot.data() + out.theta_dot.size());
    const auto& constraints = ctrl.scheme().constraints();
    for (std::size_t c = 0; c < constraints.size(); ++c) {
      const auto* pair = dynamic_cast<const PairData*>(ctrl.plugin_data().constraints[c].get());
      if (pair == nullptr) continue;
      for (int r = 0; r < constraints[c]->inequality_rows(ctrl.robot()); ++r) loop.values.push_back(pair->distances[r]);
    }
  }
  return loop;
}

void expect_bit_identical(const Loop& a, const Loop& b, const char* what) {
  ASSERT_EQ(a.values.size(), b.values.size()) << what;
  EXPECT_EQ(a.failures, b.failures) << what;
  std::size_t differ = 0, first = a.values.size();
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    if (std::memcmp(&a.values[i], &b.values[i], sizeof(double)) != 0) {
      if (differ++ == 0) first = i;
    }
  }
  EXPECT_EQ(differ, 0U) << what << ": " << differ << " values differ, the first at " << first;
}

class SharedScheme : public ::testing::TestWithParam<const char*> {};

TEST_P(SharedScheme, TwoControllersInTwoThreadsGiveWhatOneGivesAlone) {
  // The table-and-pole Panda with the broadphase tree forced on (its state is per controller), and the planar
  // R with a moving obstacle, every pair measured at every step (no cull: its first 150 steps stay beyond d_i).
  std::vector<std::string> overrides;
  if (std::string(GetParam()) == "panda_table_pole") overrides.push_back("constraints.3.broadphase=\"always\"");
  if (std::string(GetParam()) == "paper_r_moving_obstacle") overrides.push_back("constraints.3.broadphase=\"never\"");
  Scenario s = load_scenario(source_path(std::string("configs/") + GetParam() + ".toml"), overrides);
  const int steps = 150;
  const auto e0 = s.engine.make(), e1 = s.engine.make(), e2 = s.engine.make();

  Controller alone(*s.robot, *s.scheme, *e0, s.path.get(), s.duration, s.tau);
  const Loop reference = run_loop(alone, s.theta0, s.tau, steps);
  ASSERT_GT(reference.values.size(), 0U);

  Controller a(*s.robot, *s.scheme, *e1, s.path.get(), s.duration, s.tau);
  Controller b(*s.robot, *s.scheme, *e2, s.path.get(), s.duration, s.tau);
  Loop la, lb;
  std::thread ta([&] { la = run_loop(a, s.theta0, s.tau, steps); });
  std::thread tb([&] { lb = run_loop(b, s.theta0, s.tau, steps); });
  ta.join();
  tb.join();
  expect_bit_identical(reference, la, "thread 1");
  expect_bit_identical(reference, lb, "thread 2");
  // The distances are really there: some pair of some collision constraint was measured (a finite distance).
  bool measured = false;
  for (const auto& c : alone.plugin_data().constraints) {
    const auto* pair = dynamic_cast<const PairData*>(c.get());
    if (pair != nullptr && std::isfinite(pair->distances[pair->distances.worst()])) measured = true;
  }
  EXPECT_TRUE(measured) << "no collision constraint measured a pair: the test would not see shared state";
}

INSTANTIATE_TEST_SUITE_P(Configs, SharedScheme, ::testing::Values("panda_table_pole", "paper_r_moving_obstacle"));

}  // namespace
}  // namespace redres

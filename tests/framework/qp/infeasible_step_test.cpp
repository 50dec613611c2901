// The step that no engine solved (tests/data/reproducers/iiwa_pose_step: pybullet's KUKA iiwa on a helix holding a
// 6-D pose past a pole; at t = 5.44 s the rows miss by 3.2e-6 at best, and an independent LP, HiGHS, finds them
// infeasible): every engine reports it `infeasible`, naming the task row and the obstacle row that conflict; newton
// decides it without running projection's 20,000 iterations, and the step is newton's (the engine that decided).

#include <string>

#include <gtest/gtest.h>

#include "redres/control/controller.hpp"
#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

const char* const kScenario = "tests/data/reproducers/iiwa_pose_step/scenarios/iiwa_b3_helix_pose.toml";

// The failed step of the run with `engine`, taken again by a controller from the state the run failed at.
SolverInfo failed_step(const std::string& engine, RunResult& run) {
  Scenario s = load_scenario(source_path(kScenario), {"solver.engine=\"" + engine + "\""});
  run = simulate(s);
  const std::size_t last = run.trajectory.size() - 1;
  Eigen::VectorXd theta(s.robot->dof());
  for (int j = 0; j < theta.size(); ++j) theta(j) = run.trajectory.at(last, "theta_" + std::to_string(j + 1));
  const auto controller = Controller::from_scenario(s);
  StepOutput out = controller->make_output();
  controller->step(theta, run.trajectory.at(last, "t"), out);
  return out.info;
}

TEST(InfeasibleStep, TheIiwaPoseStepIsInfeasibleForEveryEngineNamingItsRows) {
  for (const char* engine : {"newton", "projection", "nlopt"}) {
    SCOPED_TRACE(engine);
    RunResult run;
    const SolverInfo info = failed_step(engine, run);
    EXPECT_TRUE(run.stopped);
    EXPECT_EQ(run.first_failure.rfind("t = 5.44 s: infeasible: the constraint rows cannot be met", 0), 0u)
        << run.first_failure;
    EXPECT_EQ(run.engine(), engine) << "the engine that decided, alone";
    EXPECT_EQ(info.status, SolverStatus::kInfeasible) << info.diagnosis;
    EXPECT_EQ(info.engine, engine);
    const std::string& d = info.diagnosis;
    EXPECT_EQ(d.rfind("the constraint rows cannot be met inside the bounds: equality row ", 0), 0u) << d;
    EXPECT_NE(d.find("(from 'task_tracking') misses by 3."), std::string::npos) << d;
    EXPECT_NE(d.find("(from 'obstacle_avoidance': link 'lbr_iiwa_link_6'"), std::string::npos) << d;
    EXPECT_EQ(d.find("cannot be met", d.find("cannot be met") + 1), std::string::npos) << "said once: " << d;
  }
}

TEST(InfeasibleStep, NewtonDecidesWithoutProjectionsIterations) {
  RunResult run;
  const SolverInfo info = failed_step("newton", run);
  // Newton's own iterations only: the fallback found the rows unmeetable before running projection.
  EXPECT_LT(info.iterations, 200) << info.diagnosis;
  EXPECT_EQ(info.diagnosis.find("projection"), std::string::npos) << info.diagnosis;
}

}  // namespace
}  // namespace redres

// The step-loop benchmarks' baseline (benchmarks/paper_baseline.cpp, a hand-written loop of the paper's arm that
// uses nothing of the framework) computes the same run as the framework: the same w at every step and the same
// theta(T), for the paper's TVCMM scheme with newton, so that timing one against the other compares equal work.

#include <cmath>

#include <gtest/gtest.h>

#include "paper_baseline_setup.hpp"
#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

TEST(Baseline, ComputesTheFrameworksRunOfThePaperArm) {
  for (const char* engine : {"newton", "projection"}) {
    Scenario s = load_scenario(source_path("configs/paper_r_tvcmm.toml"),
                               {std::string("solver.engine=") + engine, "solver.tolerance=1e-10"});
    const baseline::Case c = baseline::paper_case(s);
    const std::size_t cells = static_cast<std::size_t>(c.steps + 1) * 13;
    baseline::Record record;
    record.rows.assign(cells, 0.0);
    const baseline::Joints theta =
        baseline::run(c.arm, c.theta0, c.r_d.data(), c.r_d_dot.data(), c.steps, c.tau, record);
    EXPECT_EQ(record.failures, 0);
    // The run that evaluates the letter in its loop is the same run.
    baseline::Record in_loop;
    in_loop.rows.assign(cells, 0.0);
    const baseline::Joints theta_in_loop = baseline::run_letter_r(c.arm, c.letter, c.theta0, c.steps, c.tau, in_loop);
    EXPECT_EQ(in_loop.failures, 0);
    for (std::size_t j = 0; j < 6; ++j) EXPECT_NEAR(theta_in_loop[j], theta[j], 1e-9) << "joint " << j + 1;
    const RunResult run = simulate(s);
    ASSERT_EQ(run.failures, 0) << run.first_failure;
    const std::size_t last = run.trajectory.size() - 1;
    double worst_theta = 0.0, worst_w = 0.0;
    for (int j = 0; j < 6; ++j) {
      worst_theta = std::max(worst_theta, std::abs(theta[static_cast<std::size_t>(j)] -
                                                   run.trajectory.at(last, "theta_" + std::to_string(j + 1))));
    }
    for (std::size_t r = 0; r <= last; ++r) {
      worst_w = std::max(worst_w, std::abs(record.rows[r * 13 + 12] - run.trajectory.at(r, "manipulability")));
    }
    RecordProperty(std::string(engine) + "_max_theta_difference", std::to_string(worst_theta));
    // newton solves each QP exactly; projection to its tolerance (1e-10 here).
    const double tol = std::string(engine) == "newton" ? 1e-9 : 1e-6;
    EXPECT_LT(worst_theta, tol) << engine;
    EXPECT_LT(worst_w, tol) << engine;
  }
}

}  // namespace
}  // namespace redres

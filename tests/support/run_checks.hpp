#pragma once
// GoogleTest checks on a finished run, shared by the scenario tests.

#include <gtest/gtest.h>

#include "redres/run/run_summary.hpp"

namespace redres {

/// A run that solved every step, tracked its position within `max_position_error` (m) and never left a joint's
/// position limits or its velocity law.
inline void expect_clean_run(const RunSummary& sum, double max_position_error) {
  EXPECT_EQ(sum.solver.failures, 0) << sum.name << ": " << sum.solver.first_failure;
  EXPECT_LT(sum.max_position_error, max_position_error) << sum.name;
  EXPECT_LE(sum.max_joint_angle_violation, 0.0) << sum.name;
  EXPECT_LE(sum.max_joint_velocity_violation, 0.0) << sum.name;
}

}  // namespace redres

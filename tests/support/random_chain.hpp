#pragma once
// rapidcheck generators for random robot chains and configurations (planar and spatial, 2 to 9 joints).

#include <memory>
#include <string>

#include <rapidcheck.h>

#include "redres/model/robot.hpp"

namespace redres::testing {

/// A uniform double in [lo, hi], drawn through rapidcheck (so it shrinks and is reproducible with the seed).
inline double draw(double lo, double hi) {
  const int k = *rc::gen::inRange(0, 1'000'001);
  return lo + (hi - lo) * static_cast<double>(k) / 1e6;
}

/// A constant velocity law +-limit.
std::shared_ptr<const VelocityLimitLaw> constant_law(double limit);

/// A random planar chain with `n` joints: lengths in [0.05, 1] m, limits around zero.
RobotSpec random_planar(int n, TaskRows task);

/// A random spatial chain with `n` joints: random DH convention, a, alpha, d, offsets; about one joint in four
/// prismatic.
RobotSpec random_spatial(int n, TaskRows task);

/// A random configuration strictly inside the model's limits.
Eigen::VectorXd random_theta(const RobotModel& model);

}  // namespace redres::testing

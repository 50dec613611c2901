// The paper's arm at theta(0): the reference values of docs/paper.md, computed independently, to 1e-9.

#include <cmath>

#include <gtest/gtest.h>

#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

TEST(PaperArm, DesignSection4ValuesAtTheta0) {
  const RobotModel model = load_robot(source_path("robots/paper_pushrod_6dof.toml"));
  ASSERT_EQ(model.dof(), 6);
  ASSERT_EQ(model.task_dim(), 2);
  const Eigen::VectorXd theta = paper_theta0();
  EXPECT_LT((model.home() - theta).norm(), 1e-15);

  KinematicsData k(model);
  compute_kinematics(model, theta, k, KinematicsLevel::kAll);
  EXPECT_NEAR(k.f(0), 0.380830430, 1e-9);
  EXPECT_NEAR(k.f(1), 1.225770312, 1e-9);
  EXPECT_NEAR(k.w, 0.234131505, 1e-9);
  const double q[] = {0.0, 0.253141171, 0.505876530, 0.548125133, 0.403410318, 0.142114701};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(k.grad_w(i), q[i], 1e-9) << "q_" << i + 1;
  EXPECT_NEAR(k.mu, std::sqrt(k.w), 1e-12);

  Eigen::VectorXd lo(6), hi(6);
  model.velocity_limits(theta, lo, hi);
  const double pushrod[] = {0.364311967, 0.364311967, 0.382146972, 0.352452112, 0.356499022};
  EXPECT_NEAR(hi(0), 25.0 * M_PI / 24.0, 1e-12);
  EXPECT_NEAR(lo(0), -25.0 * M_PI / 24.0, 1e-12);
  for (int i = 1; i < 6; ++i) {
    EXPECT_NEAR(hi(i), pushrod[i - 1], 1e-9) << "joint " << i + 1;
    EXPECT_NEAR(lo(i), -pushrod[i - 1], 1e-9) << "joint " << i + 1;
  }
}

}  // namespace
}  // namespace redres

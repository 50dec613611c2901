// A peer on the Panda helix (configs/panda_helix.toml): the same position task (3 rows, gain 8, tau = 10 ms, the
// same path and Euler steps) with Orocos KDL (Debian's liborocos-kdl-dev, used by this benchmark only), against the
// full redres run of that scenario.
//   BM_PandaHelix/redres_newton      simulate(): bounded QP with the manipulability gradient, every bound kept
//   BM_PandaHelix/kdl_jac_pinv       KDL's ChainFkSolverPos_recursive and ChainJntToJacSolver, then the 3x7
//                                    pseudo-inverse x = J'(JJ')^-1 (r_d_dot + K (r_d - f)) by Eigen; no bounds
//   BM_PandaHelix/kdl_ik_vel_pinv    KDL's stock ChainIkSolverVel_pinv on the 6-D twist (orientation held by zero
//                                    angular velocity), for reference
// The KDL chain is built from redres's own joint frames (base, A_j, the joint about z, B_j, tool), and its
// position and Jacobian are checked against redres's at the start (the benchmark stops if they differ).

#include <stdexcept>

#include <benchmark/benchmark.h>
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolvervel_pinv.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include <Eigen/Cholesky>

#include "bench_counters.hpp"
#include "redres/run/simulation.hpp"

namespace redres {
namespace {

KDL::Frame to_kdl(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d& R = T.linear();
  return KDL::Frame(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
                    KDL::Vector(T.translation().x(), T.translation().y(), T.translation().z()));
}

KDL::Chain kdl_chain(const RobotModel& robot) {
  KDL::Chain chain;
  chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::None), to_kdl(robot.base() * robot.before(0))));
  for (int j = 0; j < robot.dof(); ++j) {
    if (!robot.frame_shape(j).z_axis) throw std::invalid_argument("kdl_chain: joints about z only");
    const Eigen::Isometry3d tip =
        robot.after(j) * (j + 1 < robot.dof() ? robot.before(j + 1) : robot.spec().end_effector);
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ), to_kdl(tip)));
  }
  return chain;
}

struct Helix {
  Scenario scenario;
  std::vector<Eigen::Vector3d> r_d, r_d_dot;
};

Helix helix() {
  Helix h{load_scenario(std::string(REDRES_SOURCE_DIR) + "/configs/panda_helix.toml"), {}, {}};
  const Scenario& s = h.scenario;
  Eigen::VectorXd r(3), v(3);
  for (int k = 0; k <= s.steps(); ++k) {
    s.path->evaluate(k == s.steps() ? s.duration : k * s.tau, r, v);
    h.r_d.emplace_back(r);
    h.r_d_dot.emplace_back(v);
  }
  return h;
}

// KDL's position and Jacobian equal redres's at theta(0): the two compute the same arm.
void check_same_arm(const RobotModel& robot, KDL::Chain& chain, const Eigen::VectorXd& theta) {
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::ChainJntToJacSolver jac(chain);
  KDL::JntArray q(robot.dof());
  q.data = theta;
  KDL::Frame F;
  KDL::Jacobian J(robot.dof());
  fk.JntToCart(q, F);
  jac.JntToJac(q, J);
  KinematicsData k(robot);
  compute_kinematics(robot, theta, k, KinematicsLevel::kJacobian);
  const Eigen::Vector3d p(F.p.x(), F.p.y(), F.p.z());
  if ((p - k.f.head<3>()).norm() > 1e-12 || (J.data.topRows(3) - k.J.topRows(3)).cwiseAbs().maxCoeff() > 1e-12) {
    throw std::runtime_error("KDL's chain is not redres's arm");
  }
}

void BM_PandaHelix_Redres(benchmark::State& state) {
  Helix h = helix();
  for (auto _ : state) {
    const RunResult run = simulate(h.scenario);
    if (run.failures != 0) state.SkipWithError(run.first_failure.c_str());
    benchmark::DoNotOptimize(run.trajectory.values().data());
  }
  set_per_step(state, h.scenario.steps() + 1);
}

void BM_PandaHelix_KdlJacPinv(benchmark::State& state) {
  Helix h = helix();
  const RobotModel& robot = *h.scenario.robot;
  KDL::Chain chain = kdl_chain(robot);
  check_same_arm(robot, chain, h.scenario.theta0);
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::ChainJntToJacSolver jac(chain);
  const int n = robot.dof(), steps = h.scenario.steps();
  const double tau = h.scenario.tau, gain = 8.0;
  KDL::JntArray q(n);
  KDL::Frame F;
  KDL::Jacobian J(n);
  Eigen::Matrix<double, 3, Eigen::Dynamic> Jp(3, n);
  Eigen::LDLT<Eigen::Matrix3d> ldlt;
  for (auto _ : state) {
    q.data = h.scenario.theta0;
    for (int k = 0; k <= steps; ++k) {
      fk.JntToCart(q, F);
      jac.JntToJac(q, J);
      Jp = J.data.topRows(3);
      const Eigen::Vector3d f(F.p.x(), F.p.y(), F.p.z());
      const Eigen::Vector3d d =
          h.r_d_dot[static_cast<std::size_t>(k)] + gain * (h.r_d[static_cast<std::size_t>(k)] - f);
      ldlt.compute(Jp * Jp.transpose());
      const Eigen::VectorXd x = Jp.transpose() * ldlt.solve(d);
      if (k < steps) q.data += tau * x;
    }
    benchmark::DoNotOptimize(q.data.data());
  }
  set_per_step(state, steps + 1);
}

void BM_PandaHelix_KdlIkVelPinv(benchmark::State& state) {
  Helix h = helix();
  const RobotModel& robot = *h.scenario.robot;
  KDL::Chain chain = kdl_chain(robot);
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::ChainIkSolverVel_pinv ik(chain);
  const int n = robot.dof(), steps = h.scenario.steps();
  const double tau = h.scenario.tau, gain = 8.0;
  KDL::JntArray q(n), qdot(n);
  KDL::Frame F;
  for (auto _ : state) {
    q.data = h.scenario.theta0;
    for (int k = 0; k <= steps; ++k) {
      fk.JntToCart(q, F);
      const Eigen::Vector3d f(F.p.x(), F.p.y(), F.p.z());
      const Eigen::Vector3d d =
          h.r_d_dot[static_cast<std::size_t>(k)] + gain * (h.r_d[static_cast<std::size_t>(k)] - f);
      ik.CartToJnt(q, KDL::Twist(KDL::Vector(d.x(), d.y(), d.z()), KDL::Vector::Zero()), qdot);
      if (k < steps) q.data += tau * qdot.data;
    }
    benchmark::DoNotOptimize(q.data.data());
  }
  set_per_step(state, steps + 1);
}

BENCHMARK(BM_PandaHelix_Redres)->Name("BM_PandaHelix/redres_newton")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PandaHelix_KdlJacPinv)->Name("BM_PandaHelix/kdl_jac_pinv")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PandaHelix_KdlIkVelPinv)->Name("BM_PandaHelix/kdl_ik_vel_pinv")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace redres

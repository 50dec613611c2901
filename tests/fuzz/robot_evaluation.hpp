#pragma once
/// @file
/// Shared by the robot and URDF targets (docs/fuzzing.md): a robot that loaded is evaluated at a few configurations
/// inside its limits: forward kinematics, the Jacobian and every derived quantity (both kinematics paths), the
/// velocity-limit laws, and the distances between the collision shapes of the link pairs checked for
/// self-collision. A non-finite f or J at a finite configuration is a finding (the loaders bound every length and
/// position).

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <vector>

#include "redres/model/collision.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/model/robot.hpp"

namespace redres::fuzz {

using redres::KinematicsData;
using redres::KinematicsLevel;
using redres::RobotModel;

// Self-collision distances per configuration, at most (the pair count grows with n^2).
constexpr int kMaxPairsPerConfiguration = 256;

[[noreturn]] inline void finding(const char* what) {
  std::fprintf(stderr, "redres fuzz finding: %s\n", what);
  std::abort();
}

inline std::vector<Eigen::VectorXd> configurations(const RobotModel& robot) {
  const Eigen::VectorXd& lo = robot.lower_limits();
  const Eigen::VectorXd& hi = robot.upper_limits();
  std::vector<Eigen::VectorXd> out;
  if (robot.home().size() == robot.dof()) out.push_back(robot.home());
  for (const double s : {0.0, 0.5, 1.0, 0.25}) out.push_back(lo + s * (hi - lo));
  // Alternating ends: every joint at a limit, neighbours at opposite ones.
  Eigen::VectorXd alt(robot.dof());
  for (int j = 0; j < robot.dof(); ++j) alt(j) = j % 2 == 0 ? lo(j) : hi(j);
  out.push_back(alt);
  return out;
}

inline void evaluate_robot(const RobotModel& robot) {
  const int n = robot.dof();
  KinematicsData k(robot);
  KinematicsData g(robot);
  Eigen::VectorXd vlo(n), vhi(n);

  std::vector<redres::ShapeSpec> shapes;
  for (const auto& ls : robot.link_shapes()) shapes.push_back(ls.spec);
  std::unique_ptr<redres::DistanceQuery> query;
  if (!shapes.empty()) {
    try {
      query = std::make_unique<redres::DistanceQuery>(shapes);
    } catch (const std::exception&) {
      // A shape the geometry code refuses (the loader checked it already; the plugin reports the same).
    }
  }

  for (const Eigen::VectorXd& theta : configurations(robot)) {
    if (!theta.allFinite()) continue;
    compute_kinematics(robot, theta, k, KinematicsLevel::kAll);
    compute_kinematics_general(robot, theta, g, KinematicsLevel::kAll);
    if (!k.f.allFinite() || !k.J.allFinite() || !g.f.allFinite() || !g.J.allFinite()) {
      finding("robot evaluation: non-finite f or J at a configuration inside the limits");
    }
    (void)k.w, (void)k.mu, (void)g.w;
    robot.velocity_limits(theta, vlo, vhi);

    if (query) {
      const auto& links = robot.link_shapes();
      int pairs = 0;
      for (std::size_t a = 0; a < links.size() && pairs < kMaxPairsPerConfiguration; ++a) {
        for (std::size_t b = a + 1; b < links.size() && pairs < kMaxPairsPerConfiguration; ++b) {
          if (!robot.self_collision_pair(links[a].link, links[b].link)) continue;
          ++pairs;
          const Eigen::Isometry3d Ta = k.link_frames[static_cast<std::size_t>(links[a].link)] * links[a].pose;
          const Eigen::Isometry3d Tb = k.link_frames[static_cast<std::size_t>(links[b].link)] * links[b].pose;
          (void)query->distance(static_cast<int>(a), Ta, static_cast<int>(b), Tb);
        }
      }
    }
  }
}

}  // namespace redres::fuzz

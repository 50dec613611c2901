// libFuzzer target: the robot loader and the kinematics (docs/fuzzing.md).
//
// The input is a robot TOML file. It is written into the scratch directory (fuzz_util.hpp, where the repository's
// URDF files and CSV tables resolve as they do beside robots/) and loaded with load_robot(path), the entry point of
// `redres robot` and of every scenario. A robot that loads is evaluated at a few configurations inside its limits:
// forward kinematics, the Jacobian and every derived quantity (both kinematics paths), the velocity-limit laws, and
// the distances between the collision shapes of the link pairs checked for self-collision.
//
// Exceptions derived from std::exception are the loader's answers to bad input and are expected. Crashes, sanitizer
// reports, leaks, timeouts and out-of-memory are findings; so is a non-finite f or J at a finite configuration of a
// robot that loaded (the loader bounds every length and position).

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <vector>

#include "fuzz_util.hpp"
#include "redres/model/collision.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/model/robot.hpp"
#include "redres/parsers/robot_toml.hpp"

namespace {

using redres::KinematicsData;
using redres::KinematicsLevel;
using redres::RobotModel;

// Self-collision distances per configuration, at most (the pair count grows with n^2).
constexpr int kMaxPairsPerConfiguration = 256;

[[noreturn]] void finding(const char* what) {
  std::fprintf(stderr, "robot_loader_fuzz: %s\n", what);
  std::abort();
}

std::vector<Eigen::VectorXd> configurations(const RobotModel& robot) {
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

void evaluate(const RobotModel& robot) {
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
      finding("non-finite f or J at a configuration inside the limits");
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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = redres::fuzz::scratch().write("input.toml", data, size);
  try {
    const RobotModel robot = redres::load_robot(file);
    evaluate(robot);
  } catch (const std::exception&) {
    // Bad input, reported as a ConfigError, UrdfError, std::invalid_argument, ...
  }
  return 0;
}

#pragma once
// Point clouds for the cloud obstacles' tests (the readers' in tests/framework/parsers/, the distances' in
// tests/framework/model/): a sampled cloud, its .xyz file, and a `points` obstacle naming a file (their directories:
// scratch_dir(), test_util.hpp).

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/model/collision.hpp"
#include "test_util.hpp"

namespace redres::testing {

// A table top, a ball's surface and a scatter: points with structure at several scales.
inline std::vector<Eigen::Vector3d> sample_cloud(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < n; ++i) {
    if (i % 3 == 0) {
      out.emplace_back(0.5 + 0.2 * u(rng), 0.2 * u(rng), 0.002 * u(rng));
    } else if (i % 3 == 1) {
      Eigen::Vector3d d(g(rng), g(rng), g(rng));
      out.emplace_back(Eigen::Vector3d(0.5, 0.3, 0.3) + 0.1 * d.normalized());
    } else {
      out.emplace_back(0.5 + 0.4 * u(rng), 0.4 * u(rng), 0.5 + 0.5 * u(rng));
    }
  }
  return out;
}

inline void write_xyz(const std::filesystem::path& f, const std::vector<Eigen::Vector3d>& pts) {
  std::ofstream o(f);
  o.precision(17);
  o << "# x y z r g b\n";
  for (const auto& p : pts) o << p.x() << " " << p.y() << ", " << p.z() << " 1 2 3\n";
}

inline ShapeSpec cloud_spec(const std::filesystem::path& file, double resolution, double radius) {
  ShapeSpec s;
  s.shape = ShapeSpec::Kind::kPoints;
  s.file = file;
  s.resolution = resolution;
  s.radius = radius;
  return s;
}

}  // namespace redres::testing

#pragma once
// Shapes for the collision, cloud, mesh and hull tests (tests/framework/model/): a capsule's spec and a cube written
// as an OBJ object.

#include <string>

#include <Eigen/Core>

#include "redres/model/collision.hpp"

namespace redres::testing {

/// A capsule of radius `r` and length `l` along its link.
inline ShapeSpec capsule(double r, double l) {
  ShapeSpec s;
  s.shape = ShapeSpec::Kind::kCapsule;
  s.radius = r;
  s.length = l;
  return s;
}

/// A cube of side 2 centred on `c`, as an OBJ object named `name` (its vertices numbered from first + 1).
inline std::string cube_obj(const std::string& name, const Eigen::Vector3d& c, int first) {
  std::string out = "o " + name + "\n";
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d p = c + Eigen::Vector3d(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1);
    out += "v " + std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
  }
  const int f[12][3] = {{1, 3, 2}, {2, 3, 4}, {5, 6, 7}, {6, 8, 7}, {1, 2, 5}, {2, 6, 5},
                        {3, 7, 4}, {4, 7, 8}, {1, 5, 3}, {3, 5, 7}, {2, 4, 6}, {4, 8, 6}};
  for (const auto& t : f) {
    out += "f " + std::to_string(t[0] + first) + " " + std::to_string(t[1] + first) + " " +
           std::to_string(t[2] + first) + "\n";
  }
  return out;
}

}  // namespace redres::testing

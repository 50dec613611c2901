#pragma once
// Helpers shared by the tests.

#include <cmath>
#include <filesystem>
#include <string>

#include <Eigen/Core>

namespace redres {

/// A path inside the source tree.
inline std::filesystem::path source_path(const std::string& relative) {
  return std::filesystem::path(REDRES_SOURCE_DIR) / relative;
}

/// A path inside tests/data.
inline std::filesystem::path data_path(const std::string& relative) {
  return std::filesystem::path(REDRES_TEST_DATA_DIR) / relative;
}

/// theta(0) of the paper, section 4.
inline Eigen::VectorXd paper_theta0() {
  Eigen::VectorXd t(6);
  t << M_PI / 4, M_PI / 12, M_PI / 12, M_PI / 12, M_PI / 36, M_PI / 36;
  return t;
}

}  // namespace redres

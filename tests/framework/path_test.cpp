// Paths: the letter R of docs/letter_r.md, timing laws, and r_d_dot against central differences of r_d for every
// path type.

#include <cmath>

#include <gtest/gtest.h>

#include "redres/control/path.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

std::unique_ptr<Path> make(const std::string& toml, int dim = 2, double T = 40.0,
                           const Eigen::Vector3d& start = Eigen::Vector3d(0.38, 1.22, 0.0)) {
  const auto file = parse_toml_string(toml, "<path>");
  PathContext ctx;
  ctx.dim = dim;
  ctx.start = start;
  ctx.duration = T;
  return make_path(TableReader::root(file), ctx);
}

TEST(Timing, LawsGoFromZeroToOneAtRestAndMatchTheirDerivatives) {
  for (TimingLaw law : {TimingLaw::kCycloidal, TimingLaw::kSin2, TimingLaw::kQuintic}) {
    double s = 0, ds = 0;
    timing(law, 0.0, s, ds);
    EXPECT_NEAR(s, 0.0, 1e-15);
    EXPECT_NEAR(ds, 0.0, 1e-15);
    timing(law, 1.0, s, ds);
    EXPECT_NEAR(s, 1.0, 1e-15);
    EXPECT_NEAR(ds, 0.0, 1e-15);
    for (double u = 0.05; u < 1.0; u += 0.1) {
      double sp = 0, sm = 0, d = 0;
      timing(law, u + 1e-6, sp, d);
      timing(law, u - 1e-6, sm, d);
      timing(law, u, s, ds);
      EXPECT_NEAR(ds, (sp - sm) / 2e-6, 1e-7);
    }
  }
}

TEST(LetterR, GeometryPlacementAndTimingFollowDesignSection5) {
  const double h = 0.15, c = h / 6, rho = h / 4;
  const auto path = make("type = \"letter_r\"\n");
  const double length = h + c + M_PI * rho + c + std::hypot(c + rho, h / 2);
  EXPECT_NEAR(path->length(), length, 1e-12);
  Eigen::VectorXd r(2), v(2);
  path->evaluate(0.0, r, v);
  EXPECT_NEAR((r - Eigen::Vector2d(0.38, 1.22)).norm(), 0.0, 1e-15);  // starts at f(theta(0))
  EXPECT_NEAR(v.norm(), 0.0, 1e-15);
  // The stem goes "up" in letter coordinates, i.e. down in the base frame after the 180 degree rotation.
  const double t_stem = 40.0 * h / length;
  path->evaluate(t_stem, r, v);
  EXPECT_NEAR(r.x(), 0.38, 1e-12);
  EXPECT_NEAR(r.y(), 1.22 - h, 1e-12);
  EXPECT_NEAR(v.norm(), 0.0, 1e-12);  // at rest between strokes
  // The bowl reaches x = c + rho in letter coordinates (x = 0.38 - (c + rho) after the rotation).
  double best = 1e9;
  for (double t = t_stem; t < t_stem + 40.0 * (2 * c + M_PI * rho) / length; t += 0.001) {
    path->evaluate(t, r, v);
    best = std::min(best, r.x());
  }
  EXPECT_NEAR(best, 0.38 - (c + rho), 1e-6);
  path->evaluate(40.0, r, v);
  EXPECT_NEAR(r.x(), 0.38 - (c + rho), 1e-12);  // the leg ends at (c + rho, 0), rotated
  EXPECT_NEAR(r.y(), 1.22, 1e-12);
  EXPECT_NEAR(v.norm(), 0.0, 1e-15);
}

// r_d_dot is the time derivative of r_d everywhere, corners included (continuity: no jumps).
class PathDerivative : public ::testing::TestWithParam<std::pair<std::string, int>> {};

TEST_P(PathDerivative, VelocityMatchesCentralDifferencesAndIsContinuous) {
  const auto [toml, dim] = GetParam();
  const double T = 10.0;
  const auto path = make(toml, dim, T, Eigen::Vector3d(0.3, 0.1, 0.5));
  Eigen::VectorXd r(dim), v(dim), rp(dim), rm(dim), dummy(dim), v_prev(dim);
  path->evaluate(0.0, r, v_prev);
  const double h = 1e-6;
  double worst = 0.0, jump = 0.0;
  for (double t = h; t < T - h; t += 0.0037) {
    path->evaluate(t, r, v);
    path->evaluate(t + h, rp, dummy);
    path->evaluate(t - h, rm, dummy);
    worst = std::max(worst, ((rp - rm) / (2 * h) - v).cwiseAbs().maxCoeff());
    jump = std::max(jump, (v - v_prev).cwiseAbs().maxCoeff());
    v_prev = v;
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(jump, 1e-3);  // 3.7 ms apart: no jumps
}

INSTANTIATE_TEST_SUITE_P(
    Types, PathDerivative,
    ::testing::Values(std::make_pair(std::string("type = \"letter_r\"\n"), 2),
                      std::make_pair(std::string("type = \"circle\"\nradius = 0.05\n"), 2),
                      std::make_pair(std::string("type = \"line\"\ndelta = [0.1, -0.05]\ntiming = \"quintic\"\n"), 2),
                      std::make_pair(std::string("type = \"polyline\"\nsegments = [{to = [0.1, 0.0]}, "
                                                 "{center = [0.1, 0.05], sweep_deg = 90}]\n"),
                                     2),
                      std::make_pair(std::string("type = \"line\"\ndelta = [0.1, 0.0, 0.05]\ntiming = \"sin2\"\n"), 3),
                      std::make_pair(std::string("type = \"circle\"\nnormal = [1.0, 1.0, 0.0]\n"), 3),
                      std::make_pair(std::string("type = \"helix\"\n"), 3)));

TEST(Waypoints, CsvPointsAreVisitedInOrderRelativeToTheScenarioFile) {
  const std::string csv = data_path("paths/zigzag.csv").string();
  const auto path = make("type = \"waypoints\"\nfile = \"" + csv + "\"\nstop_at_points = true\n", 2, 3.0,
                         Eigen::Vector3d(1.0, 2.0, 0.0));
  const double l1 = std::hypot(0.02, 0.01), l2 = std::hypot(0.02, 0.01), l3 = std::hypot(0.02, 0.02);
  EXPECT_NEAR(path->length(), l1 + l2 + l3, 1e-15);
  Eigen::VectorXd r(2), v(2);
  path->evaluate(3.0 * l1 / path->length(), r, v);  // end of the first stroke
  EXPECT_NEAR((r - Eigen::Vector2d(1.02, 2.01)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(v.norm(), 0.0, 1e-12);
  path->evaluate(3.0, r, v);
  EXPECT_NEAR((r - Eigen::Vector2d(1.06, 1.98)).norm(), 0.0, 1e-12);
}

TEST(PathConfig, BadKeysAreReportedWithTheirLocation) {
  try {
    (void)make("type = \"letter_r\"\nheigth = 0.1\n");
    FAIL() << "accepted a misspelt key";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("<path>:2:1: unknown key 'heigth'", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("height"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)make("type = \"helix\"\n", 2), ConfigError);  // helix needs a spatial task
  EXPECT_THROW((void)make("type = \"spiral\"\n"), ConfigError);
  EXPECT_THROW((void)make("type = \"line\"\ndelta = [0.0, 0.0]\n"), ConfigError);
}

}  // namespace
}  // namespace redres

// Paths: the letter R of docs/letter_r.md, timing laws, r_d_dot against central differences of r_d and r_d_ddot
// against central differences of r_d_dot for every path type, timing law and timing scope.

#include <cmath>
#include <iomanip>
#include <sstream>
#include <tuple>
#include <vector>

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

TEST(Timing, SecondDerivativesMatchCentralDifferencesAndLeaveTheFirstTwoUnchanged) {
  for (TimingLaw law : {TimingLaw::kCycloidal, TimingLaw::kSin2, TimingLaw::kQuintic}) {
    SCOPED_TRACE(std::string(config_io::enum_name(law)));
    double s = 0, ds = 0, d2s = 0, s3 = 0, ds3 = 0;
    // Rest to rest with zero acceleration, except sin2, which starts and stops with +-pi^2/2.
    const double ends = law == TimingLaw::kSin2 ? 0.5 * M_PI * M_PI : 0.0;
    timing(law, 0.0, s, ds, d2s);
    EXPECT_NEAR(d2s, ends, 1e-12);
    timing(law, 1.0, s, ds, d2s);
    EXPECT_NEAR(d2s, -ends, 1e-12);
    for (double u = -0.2; u <= 1.2; u += 0.01) {
      timing(law, u, s, ds, d2s);
      timing(law, u, s3, ds3);
      EXPECT_EQ(s, s3);  // bit for bit
      EXPECT_EQ(ds, ds3);
    }
    const double h = 1e-5;
    double worst = 0.0;
    for (double u = 0.005; u < 1.0; u += 0.01) {
      double sp = 0, dp = 0, sm = 0, dm = 0;
      timing(law, u + h, sp, dp);
      timing(law, u - h, sm, dm);
      timing(law, u, s, ds, d2s);
      worst = std::max(worst, std::abs(d2s - (dp - dm) / (2 * h)));
    }
    EXPECT_LT(worst, 1e-7);  // |d2sigma| is O(1..10); the differences' error is O(h^2 |d4sigma|) ~ 1e-8
  }
}

TEST(PathSegment, SecondDerivativeIsTheCurvatureVectorAndMatchesCentralDifferences) {
  PathSegment helix = PathSegment::arc(Eigen::Vector3d(0.1, 0.0, 0.0), 0.04, 0.3, 4.0 * M_PI,
                                       Eigen::Vector3d(0.0, 1.0, 0.0), Eigen::Vector3d(0.0, 0.0, 1.0));
  helix.kind = PathSegment::Kind::kHelix;
  helix.axis = Eigen::Vector3d::UnitX();
  helix.rise = 0.05;
  helix.length = std::hypot(0.04 * 4.0 * M_PI, 0.05);
  const PathSegment segments[] = {PathSegment::line(Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(-0.2, 0.4, 0.1)),
                                  PathSegment::arc(Eigen::Vector3d(0.1, 0.2, 0.0), 0.05, 0.4, -2.5), helix};
  for (const PathSegment& seg : segments) {
    Eigen::Vector3d p, t, d2, p3, t3, pp, tp, pm, tm;
    const double h = 1e-5;
    for (double s = 0.01 * seg.length; s < seg.length; s += 0.05 * seg.length) {
      seg.at(s, p, t, d2);
      seg.at(s, p3, t3);
      EXPECT_EQ(p, p3);
      EXPECT_EQ(t, t3);
      seg.at(s + h, pp, tp);
      seg.at(s - h, pm, tm);
      EXPECT_LT((d2 - (tp - tm) / (2 * h)).norm(), 1e-7 * std::max(1.0, d2.norm()));
      EXPECT_NEAR(d2.dot(t), 0.0, 1e-12);  // unit speed: the curvature vector is normal to the tangent
    }
  }
  Eigen::Vector3d p, t, d2;
  segments[0].at(0.1, p, t, d2);
  EXPECT_EQ(d2, Eigen::Vector3d::Zero());
  segments[1].at(0.1, p, t, d2);
  EXPECT_NEAR(d2.norm(), 1.0 / 0.05, 1e-12);                                                // 1 / radius
  EXPECT_NEAR((p + 0.05 * 0.05 * d2 - Eigen::Vector3d(0.1, 0.2, 0.0)).norm(), 0.0, 1e-14);  // towards the centre
  segments[2].at(0.1, p, t, d2);
  const double turn_rate = 4.0 * M_PI / helix.length;  // d angle / ds
  EXPECT_NEAR(d2.norm(), turn_rate * turn_rate * 0.04, 1e-12);
  EXPECT_NEAR(d2.dot(helix.axis), 0.0, 1e-15);  // the rise is linear in s
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

// r_d_ddot is the time derivative of r_d_dot for every path type, timing law and timing scope: at every 3.7 ms, at
// 0.1 ms and 1 ms from each end and either side of every stroke boundary (per_stroke timing restarts the law there),
// and, under sin2, on the stroke boundaries themselves.
// Where r_d_ddot jumps (a segment joint: the curvature changes; a corner between strokes under whole timing: r_d_dot
// itself turns) the central difference straddles the jump; a sample whose window holds one is checked 3h either side
// instead, and there are at most as many of those as there are joints. The 3- and 4-argument evaluate() give the
// same r_d and r_d_dot, bit for bit.
struct AccelerationCase {
  const char* name;
  std::string toml;             // type and geometry keys (no timing keys)
  int dim;                      // 2 or 3
  std::vector<double> strokes;  // stroke lengths (m), in order (one entry: a single stroke)
  int joints;                   // segment joints (stroke boundaries included)
};

void PrintTo(const AccelerationCase& c, std::ostream* os) { *os << c.name; }

std::vector<AccelerationCase> acceleration_cases() {
  const double h = 0.15, c = h / 6, rho = h / 4;
  const std::string csv = data_path("paths/zigzag.csv").string();
  const double z1 = std::hypot(0.02, 0.01), z3 = std::hypot(0.02, 0.02);
  return {
      {"letter_r", "type = \"letter_r\"\n", 2, {h, 2 * c + M_PI * rho, std::hypot(c + rho, h / 2)}, 4},
      {"circle", "type = \"circle\"\nradius = 0.05\n", 2, {2 * M_PI * 0.05}, 0},
      {"line", "type = \"line\"\ndelta = [0.1, -0.05]\n", 2, {std::hypot(0.1, 0.05)}, 0},
      {"polyline",
       "type = \"polyline\"\nsegments = [{to = [0.1, 0.0]}, {center = [0.1, 0.05], sweep_deg = 90}]\n"
       "stop_at_corners = false\n",
       2,
       {0.1 + 0.05 * M_PI / 2},
       1},
      {"polyline_corners",
       "type = \"polyline\"\nsegments = [{to = [0.1, 0.0]}, {center = [0.1, 0.05], sweep_deg = 90}]\n"
       "stop_at_corners = true\n",
       2,
       {0.1, 0.05 * M_PI / 2},
       1},
      {"waypoints", "type = \"waypoints\"\nfile = \"" + csv + "\"\n", 2, {z1 + z1 + z3}, 2},
      {"waypoints_stops", "type = \"waypoints\"\nfile = \"" + csv + "\"\nstop_at_points = true\n", 2, {z1, z1, z3}, 2},
      {"line3", "type = \"line\"\ndelta = [0.1, 0.0, 0.05]\n", 3, {std::hypot(0.1, 0.05)}, 0},
      {"circle3", "type = \"circle\"\nnormal = [1.0, 1.0, 0.0]\nradius = 0.05\n", 3, {2 * M_PI * 0.05}, 0},
      {"helix", "type = \"helix\"\n", 3, {2.0 * std::hypot(2 * M_PI * 0.04, 0.02)}, 0},
      {"helix_tilted",
       "type = \"helix\"\nradius = 0.03\npitch = 0.05\nturns = 1.5\naxis = [1.0, -1.0, 2.0]\n"
       "rpy_deg = [10.0, 20.0, 30.0]\n",
       3,
       {1.5 * std::hypot(2 * M_PI * 0.03, 0.05)},
       0},
  };
}

class PathAcceleration : public ::testing::TestWithParam<std::tuple<AccelerationCase, TimingLaw, TimingScope>> {};

TEST_P(PathAcceleration, AccelerationMatchesCentralDifferencesOfTheVelocity) {
  const auto& [kase, law, scope] = GetParam();
  const int dim = kase.dim;
  const double T = 10.0;
  const std::string toml = kase.toml + "timing = \"" + std::string(config_io::enum_name(law)) +
                           "\"\ntiming_scope = \"" + std::string(config_io::enum_name(scope)) + "\"\n";
  const auto path = make(toml, dim, T, Eigen::Vector3d(0.3, 0.1, 0.5));
  double total = 0.0;
  for (double len : kase.strokes) total += len;
  ASSERT_NEAR(path->length(), total, 1e-12) << "the test's stroke lengths are out of date";

  Eigen::VectorXd r(dim), v(dim), a(dim), r3(dim), v3(dim), rp(dim), vp(dim), rm(dim), vm(dim);
  std::vector<double> times;
  for (double t = 0.0011; t < T; t += 0.0037) times.push_back(t);
  std::vector<double> boundaries = {0.0};  // where the timing law starts or stops
  int sin2_jumps = 0;                      // samples on a stroke boundary under sin2 timing
  if (scope == TimingScope::kPerStroke) {
    double covered = 0.0;
    for (std::size_t k = 0; k + 1 < kase.strokes.size(); ++k) {
      covered += kase.strokes[k];
      const double b = T * covered / total;
      path->evaluate(b, r, v);
      ASSERT_LT(v.norm(), 1e-12) << "the test's strokes are out of date: not at rest at t = " << b;
      boundaries.push_back(b);
      if (law == TimingLaw::kSin2) {
        times.push_back(b);  // on it: r_d_ddot jumps there, so this sample straddles
        ++sin2_jumps;
      }
    }
  }
  boundaries.push_back(T);
  for (double b : boundaries) {
    for (double d : {-1e-3, -1e-4, 1e-4, 1e-3}) {
      if (b + d > 0.0 && b + d < T) times.push_back(b + d);
    }
  }

  const double h = 1e-5;
  // |analytic - central difference| at t.
  const auto error = [&](double t) {
    path->evaluate(t, r, v, a);
    path->evaluate(t + h, rp, vp);
    path->evaluate(t - h, rm, vm);
    return ((vp - vm) / (2 * h) - a).cwiseAbs().maxCoeff();
  };
  double scale = 0.0;  // the largest |r_d_ddot| along the path
  for (double t : times) {
    path->evaluate(t, r, v, a);
    scale = std::max(scale, a.cwiseAbs().maxCoeff());
    path->evaluate(t, r3, v3);
    ASSERT_EQ(r, r3) << "t = " << t;  // bit for bit
    ASSERT_EQ(v, v3) << "t = " << t;
  }
  ASSERT_GT(scale, 0.5 * total / (T * T));  // at least the mean |s''| of a rest-to-rest law is there
  const double tol = 1e-6 * scale;
  double worst = 0.0;
  int straddles = 0;
  for (double t : times) {
    const double e = error(t);
    if (e < tol) {
      worst = std::max(worst, e);
      continue;
    }
    ++straddles;  // a joint in (t - h, t + h): both sides of it, away from it
    const double before = error(t - 3 * h), after = error(t + 3 * h);
    EXPECT_LT(before, tol) << "t = " << t << " - 3h";
    EXPECT_LT(after, tol) << "t = " << t << " + 3h";
    worst = std::max({worst, before, after});
  }
  EXPECT_LE(straddles, kase.joints);
  EXPECT_GE(straddles, sin2_jumps);
  EXPECT_LT(worst, tol);
  std::ostringstream worst_text;
  worst_text << std::scientific << std::setprecision(1) << worst / scale;
  RecordProperty("worst_relative_error", worst_text.str());
  RecordProperty("straddles", straddles);
}

// Where a timing law starts (a stroke under per_stroke timing, or the whole path) r_d_ddot is the start value of that
// law: at rest, |r_d_ddot| = |s''| = sigma''(0) L_k / T_k^2 = sigma''(0) L^2 / (T^2 L_k), zero for cycloidal and
// quintic, (pi^2 / 2) L^2 / (T^2 L_k) for sin2; at t = T, the end value of the last law, sigma''(1) = -sigma''(0).
TEST_P(PathAcceleration, AtTheStartOfEachLawTheAccelerationIsTheLawsStartValue) {
  const auto& [kase, law, scope] = GetParam();
  const int dim = kase.dim;
  const double T = 10.0;
  const std::string toml = kase.toml + "timing = \"" + std::string(config_io::enum_name(law)) +
                           "\"\ntiming_scope = \"" + std::string(config_io::enum_name(scope)) + "\"\n";
  const auto path = make(toml, dim, T, Eigen::Vector3d(0.3, 0.1, 0.5));
  double total = 0.0;
  for (double len : kase.strokes) total += len;
  const double start = law == TimingLaw::kSin2 ? 0.5 * M_PI * M_PI : 0.0;  // sigma''(0)
  // (start time, length of the law's run); per_stroke: every stroke, whole: the path.
  std::vector<std::pair<double, double>> laws = {{0.0, total}};
  if (scope == TimingScope::kPerStroke) {
    laws.clear();
    double covered = 0.0;
    for (double len : kase.strokes) {
      laws.emplace_back(T * covered / total, len);
      covered += len;
    }
  }
  Eigen::VectorXd r(dim), v(dim), a(dim), rn(dim), vn(dim), an(dim);
  for (const auto& [t0, len] : laws) {
    path->evaluate(t0, r, v, a);
    const double expected = start * total * total / (T * T * len);
    EXPECT_NEAR(a.norm(), expected, 1e-12) << "t = " << t0;
    EXPECT_LT(v.norm(), 1e-12);
    // Along the direction the path then takes.
    path->evaluate(t0 + 1e-4, rn, vn, an);
    if (expected > 0.0) {
      EXPECT_NEAR(a.dot(vn) / (a.norm() * vn.norm()), 1.0, 1e-6) << "t = " << t0;
    }
  }
  path->evaluate(T, r, v, a);
  EXPECT_NEAR(a.norm(), start * total * total / (T * T * laws.back().second), 1e-12);
}

TEST_P(PathAcceleration, OutsideTheRunThePathRestsAtItsEnds) {
  const auto& [kase, law, scope] = GetParam();
  const int dim = kase.dim;
  const double T = 10.0;
  const std::string toml = kase.toml + "timing = \"" + std::string(config_io::enum_name(law)) +
                           "\"\ntiming_scope = \"" + std::string(config_io::enum_name(scope)) + "\"\n";
  const auto path = make(toml, dim, T, Eigen::Vector3d(0.3, 0.1, 0.5));
  Eigen::VectorXd r(dim), v(dim), a(dim), r_end(dim), v_end(dim);
  for (double end : {0.0, T}) {
    path->evaluate(end, r_end, v_end);
    for (double t : {end == 0.0 ? -1e-9 : T + 1e-9, end == 0.0 ? -3.0 : T + 3.0}) {
      path->evaluate(t, r, v, a);
      EXPECT_EQ(r, r_end);
      EXPECT_EQ(v, v_end);
      EXPECT_EQ(a, Eigen::VectorXd::Zero(dim)) << "t = " << t;
    }
  }
}

std::string acceleration_case_name(
    const ::testing::TestParamInfo<std::tuple<AccelerationCase, TimingLaw, TimingScope>>& param_info) {
  const auto& [kase, law, scope] = param_info.param;
  return std::string(kase.name) + "_" + std::string(config_io::enum_name(law)) + "_" +
         std::string(config_io::enum_name(scope));
}

INSTANTIATE_TEST_SUITE_P(TypesLawsScopes, PathAcceleration,
                         ::testing::Combine(::testing::ValuesIn(acceleration_cases()),
                                            ::testing::Values(TimingLaw::kCycloidal, TimingLaw::kSin2,
                                                              TimingLaw::kQuintic),
                                            ::testing::Values(TimingScope::kPerStroke, TimingScope::kWhole)),
                         acceleration_case_name);

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

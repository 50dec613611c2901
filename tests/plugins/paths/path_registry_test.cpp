// One conformance test over the path registry: every registered path, with its defaults (or, for a path with
// required keys, an example this test gives), on a planar arm and, where it applies, a spatial arm: the path starts
// at its origin (the end effector's initial position), r_d_dot matches central differences of r_d, and r_d ends at
// rest where the timing law says so.

#include <map>

#include <gtest/gtest.h>

#include "redres/control/path.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/model/robot.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/paths/letter_r.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

// Keys for the paths that have required ones (a new path with required keys must add its example here).
const std::map<std::string, std::map<int, std::string>>& examples() {
  static const std::map<std::string, std::map<int, std::string>> e = {
      {"line", {{2, "delta = [0.03, -0.02]"}, {3, "delta = [0.02, 0.01, -0.03]"}}},
      {"polyline", {{2, "segments = [{to = [0.02, 0.0]}, {center = [0.02, 0.01], sweep_deg = 90.0}]"}}},
      {"waypoints", {{2, "file = \"" + data_path("paths/zigzag.csv").string() + "\""}}},
  };
  return e;
}

struct Arm {
  const char* file;
  int dim;
};

TEST(PathRegistry, EveryPathStartsAtItsOriginAndItsVelocityIsTheDerivative) {
  int checked = 0;
  for (const auto* entry : path_registry().entries()) {
    if (entry->origin != "built-in") continue;
    bool required = false;
    for (const auto& k : entry->keys) required = required || k.presence != Presence::kOptional;
    for (const Arm arm : {Arm{"robots/paper_pushrod_6dof.toml", 2}, Arm{"robots/franka_panda.toml", 3}}) {
      SCOPED_TRACE(entry->type + " on " + arm.file);
      std::string keys;
      if (required) {
        const auto it = examples().find(entry->type);
        ASSERT_NE(it, examples().end()) << "give the new path '" << entry->type << "' an example in this test";
        const auto ex = it->second.find(arm.dim);
        if (ex == it->second.end()) continue;  // e.g. a planar-only shape on the spatial arm
        keys = ex->second;
      }
      const RobotModel robot = load_robot(source_path(arm.file));
      KinematicsData k(robot);
      compute_kinematics(robot, robot.home(), k, KinematicsLevel::kPosition);
      PathContext ctx;
      ctx.dim = arm.dim;
      ctx.start.head(arm.dim) = k.f.head(arm.dim);
      ctx.duration = 12.0;
      const auto file = parse_toml_string("type = \"" + entry->type + "\"\n" + keys + "\n", "<path>");
      std::unique_ptr<Path> path;
      try {
        path = make_path(TableReader::root(file, "path"), ctx);
      } catch (const ConfigError& e) {
        // Only a dimension the shape does not support may refuse.
        const std::string what = e.what();
        EXPECT_TRUE(what.find("spatial") != std::string::npos || what.find("planar") != std::string::npos) << what;
        continue;
      }
      ++checked;
      Eigen::VectorXd r(arm.dim), v(arm.dim), up(arm.dim), down(arm.dim), ignore(arm.dim);
      path->evaluate(0.0, r, v);
      Eigen::Vector3d start = Eigen::Vector3d::Zero();
      start.head(arm.dim) = r;
      EXPECT_LT((start - ctx.start).norm(), 1e-12);
      EXPECT_LT(v.norm(), 1e-12) << "every timing law starts from rest";
      const double h = 1e-6;
      double worst = 0.0;
      for (int i = 1; i < 600; ++i) {
        const double t = ctx.duration * i / 600.0 + 1e-4;  // off the stroke boundaries
        path->evaluate(t, r, v);
        path->evaluate(t + h, up, ignore);
        path->evaluate(t - h, down, ignore);
        worst = std::max(worst, ((up - down) / (2.0 * h) - v).norm());
      }
      EXPECT_LT(worst, 1e-6) << "largest |central difference - r_d_dot| (m/s)";
      path->evaluate(ctx.duration, r, v);
      EXPECT_LT(v.norm(), 1e-12) << "every timing law ends at rest";
    }
  }
  EXPECT_GE(checked, 9);
}

TEST(PathRegistry, PathsBuiltInCppEqualPathsReadFromToml) {
  PathContext ctx;
  ctx.dim = 2;
  ctx.start = Eigen::Vector3d(0.38, 1.22, 0.0);
  ctx.duration = 40.0;
  const auto file = parse_toml_string("type = \"letter_r\"\nheight = 0.1\ntiming = \"quintic\"\n", "<path>");
  const auto from_toml = make_path(TableReader::root(file, "path"), ctx);
  PathPlacement placement;
  placement.timing = TimingLaw::kQuintic;
  const auto from_cpp = make_path("letter_r", LetterRConfig{.height = 0.1}, placement, ctx);
  EXPECT_EQ(from_cpp->description(), from_toml->description());
  Eigen::VectorXd a(2), av(2), b(2), bv(2);
  for (double t = 0.0; t <= 40.0; t += 0.37) {
    from_toml->evaluate(t, a, av);
    from_cpp->evaluate(t, b, bv);
    EXPECT_EQ(a, b);
    EXPECT_EQ(av, bv);
  }
  // A Config of another type, or a placement that breaks its rules, is std::invalid_argument.
  EXPECT_THROW((void)make_path("letter_r", PathPlacement{}, placement, ctx), std::invalid_argument);
  PathPlacement absolute;
  absolute.placement = Placement::kAbsolute;
  EXPECT_THROW((void)make_path("letter_r", LetterRConfig{}, absolute, ctx), std::invalid_argument);
}

}  // namespace
}  // namespace redres

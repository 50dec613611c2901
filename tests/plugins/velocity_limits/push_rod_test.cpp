// The push-rod law (eq. 2) of the paper's arm against the formula computed by hand, and the `redres robot`
// command on the paper's arm (the reference values of docs/paper.md).

#include <sys/wait.h>

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "redres/model/robot.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

TEST(PushRodLaw, MatchesEquation2ByHandAtSeveralAngles) {
  const RobotModel arm = load_robot(source_path("robots/paper_pushrod_6dof.toml"));
  const double a[] = {0.250, 0.250, 0.190, 0.185, 0.174};  // Table I, joints 2-6
  const double b = 0.080, s = 2.5e-3, sigma = 10.0;
  for (int j = 1; j < 6; ++j) {
    for (double u : {0.0, 0.25, 0.5, 0.75, 1.0}) {
      const double th = arm.lower_limits()(j) + u * (arm.upper_limits()(j) - arm.lower_limits()(j));
      const double aj = a[j - 1];
      const double by_hand =
          s * sigma * std::sqrt(aj * aj + b * b + 2 * aj * b * std::sin(th)) / (aj * b * std::cos(th));
      const VelocityBounds v = arm.joint(j).velocity_limit->bounds(th);
      EXPECT_NEAR(v.upper, by_hand, 1e-12) << "joint " << j + 1 << " at " << th;
      EXPECT_NEAR(v.lower, -by_hand, 1e-12) << "joint " << j + 1 << " at " << th;
    }
  }
  // Joint 1 is the servo joint: +-25 pi / 24 rad/s everywhere.
  EXPECT_DOUBLE_EQ(arm.joint(0).velocity_limit->bounds(0.3).upper, 25.0 * M_PI / 24.0);
}

TEST(PushRodLaw, ARangeThatReachesCosZeroIsRejectedNamingTheAngle) {
  const auto file = parse_toml_string(
      "type = \"push_rod\"\na = 0.25\nb = 0.08\ns = 2.5e-3\nsigma_min = -10.0\n"
      "sigma_max = 10.0\n",
      "<law>");
  const auto law = velocity_limit_registry().create(TableReader::root(file));
  const auto bad = check_velocity_law(*law, 1.0, 2.0);
  ASSERT_TRUE(bad.has_value());
  EXPECT_NEAR(bad->theta, M_PI / 2, 1e-15);
  EXPECT_NE(bad->reason.find("cos(theta) = 0"), std::string::npos);
  EXPECT_FALSE(check_velocity_law(*law, -1.5, 1.5).has_value());
  const auto neg = check_velocity_law(*law, -2.0, -1.0);  // contains -pi/2
  ASSERT_TRUE(neg.has_value());
  EXPECT_NEAR(neg->theta, -M_PI / 2, 1e-15);
  // Where cos(theta) < 0 throughout, eq. 2 is defined and sigma^+- swap roles: still lower < 0 < upper.
  EXPECT_FALSE(check_velocity_law(*law, -4.0, -2.0).has_value());
}

std::pair<int, std::string> cli(const std::string& args) {
  const std::string cmd = "cd '" + std::string(REDRES_SOURCE_DIR) + "' && '" + REDRES_CLI + "' " + args + " 2>&1";
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  char buf[4096];
  while (p != nullptr && std::fgets(buf, sizeof buf, p) != nullptr) out += buf;
  const int status = p != nullptr ? pclose(p) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

TEST(RobotCommand, PrintsTheDesignSection4ValuesOfThePaperArm) {
  const auto [code, out] = cli("robot robots/paper_pushrod_6dof.toml");
  ASSERT_EQ(code, 0) << out;
  for (const char* s : {"f        [0.380830430, 1.225770312]", "w = det(JJ')      0.234131505",
                        "[0.000000000, 0.253141171, 0.505876530, 0.548125133, 0.403410318, 0.142114701]",
                        "-0.364311967", "0.382146972", "0.352452112", "0.356499022", "3.272492347"}) {
    EXPECT_NE(out.find(s), std::string::npos) << "missing '" << s << "' in:\n" << out;
  }
}

TEST(RobotCommand, JsonAndThetaFormulasAndErrors) {
  const auto [code, out] =
      cli("robot robots/paper_pushrod_6dof.toml --json --theta pi/4,pi/12,pi/12,pi/12,pi/36,pi/36");
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_NEAR(j["manipulability"].get<double>(), 0.234131505, 1e-9);
  EXPECT_NEAR(j["f"][0].get<double>(), 0.380830430, 1e-9);
  EXPECT_EQ(j["joints"].size(), 6u);
  const auto [c2, o2] = cli("robot robots/paper_pushrod_6dof.toml --theta 0.1,0.2");
  EXPECT_EQ(c2, 2);
  EXPECT_NE(o2.find("expected 6 comma-separated values"), std::string::npos) << o2;
  const std::string bad = data_path("robot_corpus/limits_reversed.toml").string();
  const auto [c3, o3] = cli("robot '" + bad + "'");
  EXPECT_EQ(c3, 2);
  EXPECT_EQ(o3.rfind(bad + ":6:10:", 0), 0u) << o3;
}

}  // namespace
}  // namespace redres

// One conformance test over every registered objective and constraint (and every velocity-limit law and
// engine): a new plugin is covered without new test code. Each plugin builds from its defaults, its
// configuration survives a round trip, its contributions are finite and of the right size on random states,
// and an analytic gradient (objectives with a potential) matches central differences.

#include <map>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "qp_util.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/model/velocity_limit.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

std::string to_text(const toml::table& t) {
  std::ostringstream s;
  s << t;
  return s.str();
}

std::vector<std::unique_ptr<RobotModel>> robots() {
  std::vector<std::unique_ptr<RobotModel>> out;
  for (const char* f : {"robots/paper_pushrod_6dof.toml", "robots/franka_panda.toml", "robots/planar_4link.toml"}) {
    out.push_back(std::make_unique<RobotModel>(load_robot(source_path(f))));
  }
  return out;
}

// A plugin from its defaults: a table holding only `type`, plus the keys of a plugin that has required ones (a new
// plugin with required keys must add them here).
toml::table defaults(const std::string& type) {
  static const std::map<std::string, std::string> required = {
      {"obstacle_avoidance",
       "obstacles = [{ shape = \"sphere\", radius = 0.1, xyz = [0.6, 0.6, 0.0] }]\ninfluence_distance = 2.0\n"},
  };
  const auto it = required.find(type);
  const std::string extra = it == required.end() ? "" : it->second;
  toml::table t = toml::parse(extra);
  t.insert("type", type);
  return t;
}

template <class Make>
auto round_trip(const toml::table& config, const RobotModel& robot, Make make) {
  const auto file = parse_toml_string(to_text(config), "<round trip>");
  return make(TableReader::root(file), robot);
}

// Random state inside the limits, with a random desired task point near f and a random desired velocity.
struct State {
  explicit State(const RobotModel& robot) : kin(robot), r_d(robot.reference_dim()), r_d_dot(robot.reference_dim()) {}
  KinematicsData kin;
  Eigen::VectorXd r_d, r_d_dot;
  Context ctx;
  void randomise(std::mt19937& rng, const RobotModel& robot, const Eigen::VectorXd* theta_in = nullptr) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Eigen::VectorXd theta(robot.dof());
    for (int j = 0; j < robot.dof(); ++j) {
      theta(j) = robot.lower_limits()(j) + (0.1 + 0.8 * u(rng)) * (robot.upper_limits()(j) - robot.lower_limits()(j));
    }
    if (theta_in != nullptr) theta = *theta_in;
    compute_kinematics(robot, theta, kin, KinematicsLevel::kAll);
    for (int r = 0; r < robot.reference_dim(); ++r) {
      r_d(r) = kin.f(r) + 0.01 * (u(rng) - 0.5);
      r_d_dot(r) = 0.1 * (u(rng) - 0.5);
    }
    ctx.robot = &robot;
    ctx.kinematics = &kin;
    ctx.r_d = &r_d;
    ctx.r_d_dot = &r_d_dot;
    ctx.T = 40.0;
    ctx.tau = 0.01;
    ctx.t = 40.0 * u(rng);
  }
};

// Builds the plugin from its defaults, checks its name and that its configuration survives a round trip and
// writes only documented keys.
template <class Entry, class Make>
auto build_and_round_trip(const Entry& entry, const RobotModel& robot, Make make) {
  const auto file = parse_toml_string(to_text(defaults(entry.type)), "<defaults>");
  auto p = make(TableReader::root(file), robot);
  EXPECT_EQ(p->type(), entry.type);
  EXPECT_EQ(p->name(), entry.type);
  const toml::table config = p->config();
  const auto again = round_trip(config, robot, make);
  EXPECT_EQ(to_text(again->config()), to_text(config));
  for (const auto& [k, v] : config) {
    const std::string key(k.str());
    if (key == "type" || key == "name" || key == "weight" || key == "active") continue;  // the common keys
    bool documented = false;
    for (const auto& spec : entry.keys) documented = documented || spec.name == key;
    EXPECT_TRUE(documented) << "key '" << key << "' is written but not listed";
  }
  return p;
}

TEST(PluginConformance, EveryObjective) {
  ASSERT_GE(objective_registry().entries().size(), 3u);
  std::mt19937 rng(5);
  int gradients_checked = 0;
  for (const auto& robot : robots()) {
    for (const auto* entry : objective_registry().entries()) {
      SCOPED_TRACE(entry->type + " on " + robot->name());
      const std::unique_ptr<Objective> p = build_and_round_trip(*entry, *robot, make_objective);
      // Contributions on random states.
      QpProblem qp;
      qp.resize(robot->dof(), 0, 0);
      State st(*robot);
      const std::unique_ptr<PluginData> data = p->make_data();
      for (int rep = 0; rep < 20; ++rep) {
        st.randomise(rng, *robot);
        qp.clear();
        QpBuilder b(qp);
        b.begin(0, p->weight(), 0, 0, 0, 0);
        p->contribute(st.ctx, b, data.get());
        EXPECT_TRUE(qp.W.allFinite() && qp.zeta.allFinite());
        EXPECT_TRUE(qp.W.isApprox(qp.W.transpose()));
        // An analytic gradient, where the objective has a potential: zeta = weight * grad P, against central
        // differences of P at the same t.
        if (!p->potential(st.ctx)) continue;
        const Eigen::VectorXd zeta = qp.zeta;
        const Eigen::VectorXd theta = st.kin.theta;
        Eigen::VectorXd fd(robot->dof());
        const double h = 1e-6;
        for (int i = 0; i < robot->dof(); ++i) {
          Eigen::VectorXd t = theta;
          t(i) += h;
          compute_kinematics(*robot, t, st.kin, KinematicsLevel::kAll);
          const double plus = *p->potential(st.ctx);
          t(i) -= 2 * h;
          compute_kinematics(*robot, t, st.kin, KinematicsLevel::kAll);
          const double minus = *p->potential(st.ctx);
          fd(i) = (plus - minus) / (2 * h);
        }
        ++gradients_checked;
        EXPECT_LE((zeta - p->weight() * fd).cwiseAbs().maxCoeff(), 1e-6 * (1.0 + fd.cwiseAbs().maxCoeff()))
            << "zeta " << zeta.transpose() << " vs central differences " << fd.transpose();
      }
    }
  }
  EXPECT_GT(gradients_checked, 0);
}

TEST(PluginConformance, EveryConstraint) {
  ASSERT_GE(constraint_registry().entries().size(), 3u);
  std::mt19937 rng(6);
  for (const auto& robot : robots()) {
    for (const auto* entry : constraint_registry().entries()) {
      SCOPED_TRACE(entry->type + " on " + robot->name());
      // The motion-limit constraints need the robot's limits (the Panda has them; the others refuse, naming a joint).
      if ((entry->type == "joint_acceleration_limits" && !robot->has_acceleration_limits()) ||
          (entry->type == "joint_jerk_limits" && !robot->has_jerk_limits())) {
        EXPECT_THROW((void)build_and_round_trip(*entry, *robot, make_constraint), std::exception);
        continue;
      }
      const std::unique_ptr<Constraint> p = build_and_round_trip(*entry, *robot, make_constraint);
      const int me = p->equality_rows(*robot), mi = p->inequality_rows(*robot);
      ASSERT_GE(me, 0);
      ASSERT_GE(mi, 0);
      QpProblem qp;
      qp.resize(robot->dof(), me, mi);
      State st(*robot);
      const std::unique_ptr<PluginData> data = p->make_data();
      for (int rep = 0; rep < 20; ++rep) {
        st.randomise(rng, *robot);
        qp.clear();
        QpBuilder b(qp);
        b.begin(0, 1.0, 0, me, 0, mi);
        p->contribute(st.ctx, b, data.get());
        EXPECT_TRUE(qp.J.allFinite() && qp.d.allFinite() && qp.A.allFinite() && qp.b.allFinite());
        EXPECT_FALSE(qp.lo.array().isNaN().any() || qp.hi.array().isNaN().any());
        // Constraints touch rows and bounds only, never the objective.
        EXPECT_EQ(qp.W.norm(), 0.0);
        EXPECT_EQ(qp.zeta.norm(), 0.0);
        // Something was contributed: rows or at least one finite bound.
        const bool bounds = (qp.lo.array() > -kNoBound).any() || (qp.hi.array() < kNoBound).any();
        EXPECT_TRUE(me + mi > 0 || bounds);
      }
    }
  }
}

// Velocity-limit laws need their own keys; each is built from a small valid example and checked over a range.
TEST(PluginConformance, EveryVelocityLimitLaw) {
  const std::map<std::string, std::string> examples = {
      {"constant", "lower = -1.0\nupper = 2.0\n"},
      {"push_rod", "a = 0.25\nb = 0.08\ns = 2.5e-3\nsigma_min = -10.0\nsigma_max = 10.0\n"},
      {"expression", "lower = \"-1 - 0.1*theta^2\"\nupper = \"1 + 0.5*cos(theta)\"\n"},
      {"table", "theta = [-1.0, 0.0, 1.0]\nlower = [-1.0, -2.0, -1.0]\nupper = [1.0, 2.0, 1.0]\n"},
  };
  for (const auto* entry : velocity_limit_registry().entries()) {
    SCOPED_TRACE(entry->type);
    const auto it = examples.find(entry->type);
    ASSERT_NE(it, examples.end()) << "add an example for the new law '" << entry->type << "' to this test";
    const auto file = parse_toml_string("type = \"" + entry->type + "\"\n" + it->second, "<example>");
    const TableReader r = TableReader::root(file);
    const auto law = velocity_limit_registry().create(r);
    EXPECT_NO_THROW(r.finish());
    EXPECT_EQ(law->type(), entry->type);
    EXPECT_FALSE(law->describe().empty());
    EXPECT_FALSE(check_velocity_law(*law, -1.0, 1.0).has_value());
    for (const auto& spec : entry->keys) EXPECT_FALSE(spec.help.empty()) << spec.name;
    // The configuration survives a round trip through TOML.
    const auto again = make_velocity_limit(TableReader::root(parse_toml_string(to_text(law->config()), "<rt>")));
    EXPECT_EQ(to_text(again->config()), to_text(law->config()));
    for (double th = -1.0; th <= 1.0; th += 0.125) {
      EXPECT_EQ(again->bounds(th).lower, law->bounds(th).lower);
      EXPECT_EQ(again->bounds(th).upper, law->bounds(th).upper);
    }
  }
}

TEST(PluginConformance, EveryEngineSolvesThePaperStep) {
  auto step = testing::make_paper_step();
  step->build(paper_theta0(), 10.0, Eigen::Vector2d(0.004, -0.003), Eigen::Vector2d::Zero());
  ASSERT_GE(engine_registry().entries().size(), 3u);
  for (const auto* entry : engine_registry().entries()) {
    SCOPED_TRACE(entry->type);
    auto engine = make_engine(entry->type);
    SolverResult r;
    engine->setup(6, 2, 0, r);
    engine->solve(step->qp, r);
    EXPECT_EQ(r.info.status, SolverStatus::kSolved) << r.info.diagnosis;
    EXPECT_LE(testing::kkt_residual(step->qp, r), 1e-5);
  }
}

}  // namespace
}  // namespace redres

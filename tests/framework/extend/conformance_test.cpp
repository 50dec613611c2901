// The registry conformance checks (also `redres plugins --check`): every built-in plugin passes them, they cover
// every registered type, and they catch the faults they are for.

#include <set>

#include <gtest/gtest.h>

#include "config/registration_scope.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/control/path.hpp"
#include "redres/control/plugin.hpp"
#include "redres/control/task.hpp"
#include "redres/extend/conformance.hpp"
#include "redres/model/velocity_limit.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"
#include "redres/qp/lvi.hpp"

namespace redres {
namespace {

TEST(Conformance, EveryBuiltInPluginPassesAndEveryTypeIsChecked) {
  const std::vector<ConformanceResult> results = check_registries("built-in");
  std::set<std::string> checked;
  std::set<std::pair<std::string, std::string>> kinds_checks;
  for (const auto& r : results) {
    EXPECT_TRUE(r.ok) << r.kind << " '" << r.type << "': " << r.check << ": " << r.detail;
    checked.insert(r.kind + ":" + r.type);
    kinds_checks.insert({r.type, r.check});
  }
  const auto expect_all = [&](const auto& registry, const std::string& kind) {
    for (const auto* e : registry.entries()) {
      if (e->origin == "built-in") {
        EXPECT_EQ(checked.count(kind + ":" + e->type), 1u) << kind << " " << e->type;
      }
    }
  };
  expect_all(objective_registry(), "objective");
  expect_all(constraint_registry(), "constraint");
  expect_all(task_registry(), "task");
  expect_all(velocity_limit_registry(), "velocity-limit law");
  expect_all(path_registry(), "path");
  expect_all(engine_registry(), "engine");
  // The substantive checks ran, not only "defaults".
  for (const char* type : {"manipulability", "joint_centering", "min_velocity_norm"}) {
    EXPECT_EQ(kinds_checks.count({type, "gradient"}), 1u) << type;
    EXPECT_EQ(kinds_checks.count({type, "round trip"}), 1u) << type;
  }
  for (const char* type : {"task_tracking", "joint_angle_margin", "joint_velocity_limits"}) {
    EXPECT_EQ(kinds_checks.count({type, "finite"}), 1u) << type;
  }
  for (const char* type : {"letter_r", "circle", "helix"}) EXPECT_EQ(kinds_checks.count({type, "r_d_dot"}), 1u) << type;
  for (const char* type : {"projection", "newton", "nlopt"})
    EXPECT_EQ(kinds_checks.count({type, "solves"}), 1u) << type;
}

// Faulty plugins, registered under an origin of their own and removed afterwards.
struct GainConfig {
  double gain = 1.0;
  static const Schema<GainConfig>& schema() {
    static const Schema<GainConfig> s{{field("gain", &GainConfig::gain, "", "gain")}};
    return s;
  }
};

// zeta = 2 grad P: the gradient check must catch the factor.
class WrongGradient final : public Configured<Objective, GainConfig> {
 public:
  static constexpr const char* kType = "faulty_wrong_gradient";
  WrongGradient(const Config& c, const RobotModel& robot) : Configured(kType, c), n_(robot.dof()) {}
  std::optional<double> potential(const Context& ctx) const override {
    return 0.5 * config_.gain * ctx.theta().squaredNorm();
  }

 private:
  std::unique_ptr<PluginData> make_data() const override { return std::make_unique<Workspace>(n_, 1); }
  void add_to(const Context& ctx, QpBuilder& b, PluginData* data) const override {
    Eigen::VectorXd& z = static_cast<Workspace&>(*data)[0];
    z = 2.0 * config_.gain * ctx.theta();
    b.add_linear(z);
  }
  int n_;
};

// Writes a key its schema does not list, and a bound that is NaN.
class Undocumented final : public Constraint {
 public:
  static constexpr const char* kType = "faulty_undocumented";
  Undocumented(const GainConfig& /*c*/, const RobotModel& /*robot*/) : Constraint(kType) {}

 private:
  void add_to(const Context& /*ctx*/, QpBuilder& /*b*/, PluginData* /*data*/) const override {}
  void write_config(toml::table& out) const override { out.insert("secret", 1.0); }
};

// An engine that returns zeros and claims success.
class Liar final : public LviEngine {
 public:
  std::string_view name() const override { return "faulty_liar"; }

 private:
  void do_setup(int /*n*/, int /*m_e*/, int /*m_i*/) override {}
  void do_solve(const QpProblem& /*qp*/, SolverResult& result) override {
    result.x.setZero();
    result.info.status = SolverStatus::kSolved;
    result.info.iterations = 1;
    result.info.residual = 0.0;
    result.info.engine = name();
  }
};

TEST(Conformance, CatchesAWrongGradientAnUndocumentedKeyAndAWrongEngine) {
  const std::string origin = "conformance-test-faulty";
  RegistrationScope scope{origin, {}, 0};
  current_registration_scope() = &scope;
  (void)objective_registry().add_plugin<WrongGradient>("faulty");
  (void)constraint_registry().add<GainConfig>(
      "faulty_undocumented", "faulty", [](const GainConfig& c, const RobotModel& robot) -> std::unique_ptr<Constraint> {
        return std::make_unique<Undocumented>(c, robot);
      });
  (void)engine_registry().add<GainConfig>(
      "faulty_liar", "faulty", [](const GainConfig& /*c*/, const SolverSettings& s) -> std::unique_ptr<LviEngine> {
        auto e = std::make_unique<Liar>();
        e->set_settings(s);
        return e;
      });
  current_registration_scope() = nullptr;
  ASSERT_EQ(scope.added, 3);
  ASSERT_TRUE(scope.errors.empty());

  std::set<std::string> failed;
  for (const auto& r : check_registries(origin)) {
    if (!r.ok) failed.insert(r.type + ": " + r.check);
  }
  for (RegistryBase* r : RegistryBase::all()) r->remove_origin(origin);
  EXPECT_EQ(failed.count("faulty_wrong_gradient: gradient"), 1u);
  EXPECT_EQ(failed.count("faulty_undocumented: documented keys"), 1u);
  EXPECT_EQ(failed.count("faulty_liar: solves"), 1u);
  EXPECT_EQ(objective_registry().find("faulty_wrong_gradient"), nullptr);
}

}  // namespace
}  // namespace redres

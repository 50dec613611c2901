/// `manipulability`: the manipulability-maximising term of eq. 5, zeta += -weight p(t) q with q = grad w.
/// Together with `min_velocity_norm` (W = I) it is the paper's index |x - p q|^2 / 2 up to a constant (eq. 4).
/// The measure is w = det(J J') (`det`, the paper) or Yoshikawa's sqrt(det(J J')) (`yoshikawa`); its gradient
/// comes from the kinematics (adjugate / SVD forms, exact at singularities).
///
/// Coefficient schedules p(t), t in [0, T]:
/// - `constant`: p(t) = p;
/// - `sine`: p(t) = p sin(pi t / T) (the paper's TVCMM with p = p_1 = 2; p(0) = p(T) = 0);
/// - `smoothstep`: p(t) = p s(t / t_r) while t < t_r, p while t_r <= t <= T - t_r, p s((T - t) / t_r) after,
///   with s(u) = 3u^2 - 2u^3 and t_r = ramp_fraction T;
/// - `expression`: p(t) = formula of t and T (muParser).
///
/// TOML keys: `measure` ("det"), `schedule` ("sine"), `p` (2.0), `ramp_fraction` (0.25, smoothstep only),
/// `formula` (expression only, e.g. "2*sin(pi*t/T)^2").

#include <cmath>

#include "redres/formula.hpp"
#include "redres/plugin.hpp"

namespace redres {
namespace {

constexpr double kPi = 3.14159265358979323846;

class Manipulability final : public Objective {
 public:
  explicit Manipulability(const TableReader& config)
      : Objective(config),
        measure_(config.choice("measure", {"det", "yoshikawa"}, "det")),
        schedule_(config.choice("schedule", {"constant", "sine", "smoothstep", "expression"}, "sine")) {
    if (schedule_ == "expression") {
      if (config.has("p")) config.fail("p", "is not used with schedule = \"expression\"; write it into `formula`");
      try {
        formula_ = std::make_unique<Formula>(config.string("formula"), std::vector<std::string>{"t", "T"});
      } catch (const std::invalid_argument& e) {
        config.fail("formula", std::string("expected a formula of t and T: ") + e.what());
      }
    } else {
      if (config.has("formula")) config.fail("formula", "is only used with schedule = \"expression\"");
      p_ = config.number("p", 2.0);
    }
    if (schedule_ == "smoothstep") {
      ramp_fraction_ = config.number("ramp_fraction", 0.25);
      if (!(ramp_fraction_ > 0.0 && ramp_fraction_ <= 0.5)) {
        config.fail("ramp_fraction", "expected 0 < ramp_fraction <= 0.5 (fraction of T for each ramp)");
      }
    } else if (config.has("ramp_fraction")) {
      config.fail("ramp_fraction", "is only used with schedule = \"smoothstep\"");
    }
  }

  /// The coefficient p(t).
  double coefficient(double t, double T) const {
    if (schedule_ == "constant") return p_;
    if (schedule_ == "expression") return formula_->evaluate({t, T});
    if (!(T > 0.0)) return 0.0;
    if (schedule_ == "sine") return p_ * std::sin(kPi * t / T);
    const double tr = ramp_fraction_ * T;
    const auto s = [](double u) {
      u = std::clamp(u, 0.0, 1.0);
      return u * u * (3.0 - 2.0 * u);
    };
    return p_ * std::min(s(t / tr), s((T - t) / tr));
  }

  KinematicsLevel kinematics_level() const override {
    return measure_ == "det" ? KinematicsLevel::kManipulability : KinematicsLevel::kAll;
  }

  std::optional<double> potential(const Context& ctx) const override {
    const double value = measure_ == "det" ? ctx.kinematics->w : ctx.kinematics->mu;
    return -coefficient(ctx.t, ctx.T) * value;
  }

 private:
  void add_to(const Context& ctx, QpBuilder& builder) const override {
    const double p = coefficient(ctx.t, ctx.T);
    Eigen::VectorXd& z = builder.scratch();
    z = -p * (measure_ == "det" ? ctx.kinematics->grad_w : ctx.kinematics->grad_mu);
    builder.add_linear(z);
  }

  void write_config(toml::table& out) const override {
    out.insert("measure", measure_);
    out.insert("schedule", schedule_);
    if (formula_) {
      out.insert("formula", formula_->text());
    } else {
      out.insert("p", p_);
    }
    if (schedule_ == "smoothstep") out.insert("ramp_fraction", ramp_fraction_);
  }

  std::string measure_;
  std::string schedule_;
  double p_ = 2.0;
  double ramp_fraction_ = 0.25;
  std::unique_ptr<Formula> formula_;
};

const bool kRegistered = objective_registry().add({
    "manipulability",
    "zeta += -p(t) grad w (eq. 5): maximises det(JJ') or sqrt(det(JJ')) with a coefficient schedule",
    {{"measure", "\"det\"", "\"det\" (w = det(JJ'), the paper) or \"yoshikawa\" (sqrt(det(JJ')))"},
     {"schedule", "\"sine\"", "\"constant\", \"sine\" (p sin(pi t/T)), \"smoothstep\" or \"expression\""},
     {"p", "2.0", "coefficient magnitude (constant, sine, smoothstep)"},
     {"ramp_fraction", "0.25", "smoothstep: ramp length as a fraction of T"},
     {"formula", "(none)", "expression schedule only: p(t) as a formula of t and T"}},
    [](const TableReader& r, const RobotModel& /*robot*/) -> std::unique_ptr<Objective> {
      return std::make_unique<Manipulability>(r);
    },
});

}  // namespace
}  // namespace redres

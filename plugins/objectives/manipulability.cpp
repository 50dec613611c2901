#include "redres/objectives/manipulability.hpp"
#include "redres/common/hot.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace redres {

const Schema<ManipulabilityConfig>& ManipulabilityConfig::schema() {
  using C = ManipulabilityConfig;
  static const Schema<C> s{
      {field("measure", &C::measure, "",
             "w = det(JJ') (the paper), Yoshikawa's sqrt(det(JJ')), or log det(JJ') (scale-free)"),
       field("schedule", &C::schedule, "", "p(t): constant p, p sin(pi t/T), smoothstep ramps, or a formula"),
       field("p", &C::p, "", "coefficient magnitude (not used by the expression schedule)", between(-1e6, 1e6)),
       field("ramp_fraction", &C::ramp_fraction, "", "smoothstep: each ramp's share of T",
             rule<double>("in (0, 0.5]", [](double v) { return v > 0.0 && v <= 0.5; })),
       field("formula", &C::formula, "",
             "expression schedule: p(t) as a formula of t and T, e.g. \"2*sin(pi*t/T)^2\"")},
      [](const C& c) {
        if (c.schedule == C::Schedule::kExpression && !c.formula) {
          throw FieldError("formula", "is required with schedule = \"expression\"");
        }
        if (c.schedule != C::Schedule::kExpression && c.formula) {
          throw FieldError("formula", "is only used with schedule = \"expression\"");
        }
        if (c.formula) {
          try {
            (void)Formula(*c.formula, {"t", "T"});
          } catch (const std::invalid_argument& e) {
            throw FieldError("formula", std::string("expected a formula of t and T: ") + e.what());
          }
        }
      },
      {}};
  return s;
}

Manipulability::Manipulability(const Config& config, const RobotModel& /*robot*/) : Configured(kType, config) {
  if (config_.formula) formula_ = std::make_unique<Formula>(*config_.formula, std::vector<std::string>{"t", "T"});
}

void Manipulability::check_run(double T, double tau) const {
  if (config_.schedule != Schedule::kExpression) return;
  const auto steps = static_cast<long>(std::llround(T / tau));
  for (long k = 0; k <= steps; ++k) {
    const double t = k == steps ? T : static_cast<double>(k) * tau;
    const double p = formula_->evaluate({t, T});
    if (!std::isfinite(p)) {
      std::ostringstream m;
      m << "expected p(t) finite at every step time of the run, got ";
      if (std::isnan(p)) {
        m << "nan";  // not "-nan": the sign of a NaN means nothing here
      } else {
        m << p;
      }
      m << " at t = " << t << " s (step " << k << " of " << steps << ", T = " << T << " s)";
      throw FieldError("formula", m.str());
    }
  }
}

REDRES_HOT double Manipulability::coefficient(double t, double T) const {
  const double p = config_.p;
  switch (config_.schedule) {
    case Schedule::kConstant: return p;
    case Schedule::kExpression: return formula_->evaluate({t, T});
    case Schedule::kSine: return T > 0.0 ? p * std::sin(std::numbers::pi * t / T) : 0.0;
    case Schedule::kSmoothstep: {
      if (!(T > 0.0)) return 0.0;
      const double tr = config_.ramp_fraction * T;
      const auto s = [](double u) {
        u = std::clamp(u, 0.0, 1.0);
        return u * u * (3.0 - 2.0 * u);
      };
      return p * std::min(s(t / tr), s((T - t) / tr));
    }
  }
  return 0.0;
}

KinematicsLevel Manipulability::kinematics_level() const {
  return config_.measure == Measure::kYoshikawa ? KinematicsLevel::kAll : KinematicsLevel::kGradient;
}

namespace {
// log det(JJ') and its gradient divide by w: floored, so that an exact singularity gives a large, finite push.
constexpr double kLogFloor = 1e-300;
}  // namespace

std::optional<double> Manipulability::potential(const Context& ctx) const {
  const KinematicsData& k = *ctx.kinematics;
  const double value = config_.measure == Measure::kDet         ? k.w
                       : config_.measure == Measure::kYoshikawa ? k.mu
                                                                : std::log(std::max(k.w, kLogFloor));
  return -coefficient(ctx.t, ctx.T) * value;
}

REDRES_HOT void Manipulability::add_to(const Context& ctx, QpBuilder& builder, PluginData* /*data*/) const {
  const double p = coefficient(ctx.t, ctx.T);
  const KinematicsData& k = *ctx.kinematics;
  switch (config_.measure) {
    case Measure::kDet: builder.add_linear(-p, k.grad_w); break;
    case Measure::kYoshikawa: builder.add_linear(-p, k.grad_mu); break;
    case Measure::kLogDet: builder.add_linear(-p / std::max(k.w, kLogFloor), k.grad_w); break;
  }
}

namespace {
const bool kManipulabilityRegistered = objective_registry().add_plugin<Manipulability>(
    "zeta += -p(t) grad w (eq. 5): maximises det(JJ'), sqrt(det(JJ')) or log det(JJ') with a coefficient schedule");
}  // namespace

}  // namespace redres

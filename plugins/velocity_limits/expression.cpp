#include "redres/velocity_limits/expression.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"

namespace redres {

namespace {
bool parses(const std::string& text) {
  try {
    (void)Formula(text, {"theta"});
    return true;
  } catch (const std::invalid_argument&) {
    return false;
  }
}

Formula compile(const std::string& text, const char* key) {
  try {
    return Formula(text, {"theta"});
  } catch (const std::invalid_argument& e) {
    throw FieldError(key, std::string("expected a formula of theta: ") + e.what());
  }
}
}  // namespace

const Schema<ExpressionLawConfig>& ExpressionLawConfig::schema() {
  using C = ExpressionLawConfig;
  static const Schema<C> s{
      {field("lower", &C::lower, "rad/s^k or m/s^k", "formula of theta for the lower limit").required(),
       field("upper", &C::upper, "rad/s^k or m/s^k", "formula of theta for the upper limit").required()},
      [](const C& c) {
        // Compiled here so that a syntax error names its key (and, from TOML, its file:line:col).
        if (!parses(c.lower)) (void)compile(c.lower, "lower");
        if (!parses(c.upper)) (void)compile(c.upper, "upper");
      },
      {}};
  return s;
}

ExpressionLaw::ExpressionLaw(const Config& config)
    : Configured(kType, config), lower_(compile(config_.lower, "lower")), upper_(compile(config_.upper, "upper")) {}

std::string ExpressionLaw::describe() const {
  return "expression(lower=\"" + config_.lower + "\", upper=\"" + config_.upper + "\")";
}

namespace {
const bool kExpressionRegistered =
    velocity_limit_registry().add_plugin<ExpressionLaw>("limits given as muParser formulas of theta");
}  // namespace

}  // namespace redres

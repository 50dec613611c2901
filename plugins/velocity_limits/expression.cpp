/// `expression`: the limits are formulas of the joint position `theta`, evaluated with muParser
/// (e.g. upper = "1.5 + 0.5*cos(theta)"). The constants `pi` and `e` are defined.
/// TOML keys: `lower` (formula, rad/s or m/s, required), `upper` (formula, required).

#include <stdexcept>

#include "redres/formula.hpp"
#include "redres/velocity_limit.hpp"

namespace redres {
namespace {

Formula compile(const TableReader& r, const char* key) {
  const std::string text = r.string(key);
  try {
    return Formula(text, {"theta"});
  } catch (const std::invalid_argument& e) {
    r.fail(key, std::string("expected a formula of theta: ") + e.what());
  }
}

class ExpressionLaw final : public VelocityLimitLaw {
 public:
  explicit ExpressionLaw(const TableReader& r) : lower_(compile(r, "lower")), upper_(compile(r, "upper")) {}

  VelocityBounds bounds(double theta) const override { return {lower_.evaluate({theta}), upper_.evaluate({theta})}; }
  std::string type() const override { return "expression"; }
  std::string describe() const override {
    return "expression(lower=\"" + lower_.text() + "\", upper=\"" + upper_.text() + "\")";
  }

 private:
  Formula lower_;
  Formula upper_;
};

const bool kRegistered = velocity_limit_registry().add({
    "expression",
    "limits given as muParser formulas of theta",
    {{"lower", "", "formula of theta for the lower limit (rad/s or m/s)"},
     {"upper", "", "formula of theta for the upper limit"}},
    [](const TableReader& r) -> std::unique_ptr<VelocityLimitLaw> { return std::make_unique<ExpressionLaw>(r); },
});

}  // namespace
}  // namespace redres

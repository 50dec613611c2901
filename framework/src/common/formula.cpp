#include "redres/common/formula.hpp"

#include <array>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <muParser.h>

namespace redres {

namespace {
constexpr std::size_t kMaxVariables = 8;
}  // namespace

struct Formula::Impl {
  std::string text;
  std::vector<std::string> names;
  std::array<double, kMaxVariables> values{};
  mu::Parser parser;
};

Formula::Formula(std::string text, std::vector<std::string> variables) : impl_(std::make_unique<Impl>()) {
  if (variables.size() > kMaxVariables) {
    throw std::invalid_argument("Formula: at most " + std::to_string(kMaxVariables) + " variables");
  }
  impl_->text = std::move(text);
  impl_->names = std::move(variables);
  try {
    for (std::size_t k = 0; k < impl_->names.size(); ++k) impl_->parser.DefineVar(impl_->names[k], &impl_->values[k]);
    impl_->parser.DefineConst("pi", std::numbers::pi);
    impl_->parser.DefineConst("e", std::numbers::e);
    impl_->parser.SetExpr(impl_->text);
    (void)impl_->parser.Eval();  // compiles now, so syntax errors and unknown names surface at load
    // muParser also takes "a, b" (several results, the last one used) and "x = 5" (an assignment to a variable):
    // neither is a formula of one value.
    if (impl_->parser.GetNumResults() != 1) {
      throw std::invalid_argument("\"" + impl_->text + "\" is not a valid formula: expected one expression, got " +
                                  std::to_string(impl_->parser.GetNumResults()) + " separated by commas");
    }
    for (std::size_t i = 0; i < impl_->text.size(); ++i) {
      const char c = impl_->text[i];
      const char before = i > 0 ? impl_->text[i - 1] : ' ',
                 after = i + 1 < impl_->text.size() ? impl_->text[i + 1] : ' ';
      if (c == '=' && before != '=' && before != '<' && before != '>' && before != '!' && after != '=') {
        throw std::invalid_argument("\"" + impl_->text +
                                    "\" is not a valid formula: '=' assigns to a variable (compare with ==)");
      }
    }
  } catch (const mu::Parser::exception_type& e) {
    std::string known;
    for (const auto& n : impl_->names) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("\"" + impl_->text + "\" is not a valid formula: " + e.GetMsg() +
                                " (variables: " + (known.empty() ? "none" : known) + "; constants: pi, e)");
  }
}

Formula::~Formula() = default;
Formula::Formula(Formula&&) noexcept = default;
Formula& Formula::operator=(Formula&&) noexcept = default;

double Formula::evaluate(std::initializer_list<double> values) const {
  std::size_t k = 0;
  for (double v : values) {
    if (k < kMaxVariables) impl_->values[k] = v;
    ++k;
  }
  if (k != impl_->names.size()) return std::numeric_limits<double>::quiet_NaN();
  try {
    return impl_->parser.Eval();
  } catch (const mu::Parser::exception_type&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
}

const std::string& Formula::text() const noexcept { return impl_->text; }

double evaluate_constant(const std::string& text) {
  const Formula f(text, {});
  return f.evaluate({});
}

}  // namespace redres

#include "redres/plugin.hpp"

#include <cmath>
#include <sstream>

namespace redres {

// ---------------------------------------------------------------------------------------------------------------
// QpBuilder

void QpBuilder::begin(int source, double weight, int eq_offset, int eq_rows, int in_offset, int in_rows) {
  source_ = source;
  weight_ = weight;
  eq_offset_ = eq_offset;
  eq_rows_ = eq_rows;
  in_offset_ = in_offset;
  in_rows_ = in_rows;
}

void QpBuilder::add_identity(double scale) { qp_->W.diagonal().array() += weight_ * scale; }

void QpBuilder::add_diagonal(const Eigen::Ref<const Eigen::VectorXd>& diagonal) {
  REDRES_REQUIRE(diagonal.size() == qp_->n(), "QpBuilder::add_diagonal", "diagonal.size() == n");
  qp_->W.diagonal() += weight_ * diagonal;
}

void QpBuilder::add_hessian(const Eigen::Ref<const Eigen::MatrixXd>& H) {
  REDRES_REQUIRE(H.rows() == qp_->n() && H.cols() == qp_->n(), "QpBuilder::add_hessian", "H is n x n");
  qp_->W += weight_ * H;
  for (Eigen::Index c = 0; c < H.cols(); ++c) {
    for (Eigen::Index r = 0; r < H.rows(); ++r) {
      if (r != c && H(r, c) != 0.0) qp_->w_diagonal = false;
    }
  }
}

void QpBuilder::add_linear(const Eigen::Ref<const Eigen::VectorXd>& z) {
  REDRES_REQUIRE(z.size() == qp_->n(), "QpBuilder::add_linear", "z.size() == n");
  qp_->zeta += weight_ * z;
}

void QpBuilder::intersect_bound(int joint, double lower, double upper) {
  REDRES_REQUIRE(joint >= 0 && joint < qp_->n(), "QpBuilder::intersect_bound", "0 <= joint < n");
  REDRES_REQUIRE(!std::isnan(lower) && !std::isnan(upper), "QpBuilder::intersect_bound",
                 "bounds of joint " + std::to_string(joint + 1) + " are not NaN");
  const auto j = static_cast<std::size_t>(joint);
  if (lower > qp_->lo(joint)) {
    qp_->lo(joint) = lower;
    qp_->lo_source[j] = source_;
  }
  if (upper < qp_->hi(joint)) {
    qp_->hi(joint) = upper;
    qp_->hi_source[j] = source_;
  }
}

void QpBuilder::intersect_bounds(const Eigen::Ref<const Eigen::VectorXd>& lower,
                                 const Eigen::Ref<const Eigen::VectorXd>& upper) {
  REDRES_REQUIRE(lower.size() == qp_->n() && upper.size() == qp_->n(), "QpBuilder::intersect_bounds",
                 "lower and upper have n entries");
  for (int i = 0; i < qp_->n(); ++i) intersect_bound(i, lower(i), upper(i));
}

// ---------------------------------------------------------------------------------------------------------------
// Plugins

Plugin::Plugin(const TableReader& config)
    : type_(config.string("type")),
      name_(config.string("name", type_)),
      weight_(config.number("weight", 1.0)),
      active_(config.boolean("active", true)) {
  if (!(weight_ >= 0.0)) config.fail("weight", "expected a weight >= 0");
  if (name_.empty()) config.fail("name", "expected a non-empty name");
}

toml::table Plugin::config() const {
  toml::table out;
  out.insert("type", type_);
  out.insert("name", name_);
  out.insert("weight", weight_);
  out.insert("active", active_);
  write_config(out);
  return out;
}

namespace {

[[noreturn]] void bad_output(const char* kind, const std::string& name, const std::string& what) {
  throw std::invalid_argument(std::string(kind) + " '" + name + "' produced an invalid QP: " + what);
}

template <class M>
void check_finite(const M& m, const char* kind, const std::string& name, const char* what) {
  for (Eigen::Index c = 0; c < m.cols(); ++c) {
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      if (!std::isfinite(m(r, c))) {
        std::ostringstream s;
        s << what << "(" << r << ", " << c << ") = " << m(r, c) << " is not finite";
        bad_output(kind, name, s.str());
      }
    }
  }
}

}  // namespace

void Objective::contribute(const Context& ctx, QpBuilder& builder) const {
  if (!active()) return;
  add_to(ctx, builder);
  const QpProblem& qp = builder.problem();
  check_finite(qp.W, "objective", name(), "W");
  check_finite(qp.zeta, "objective", name(), "zeta");
  if (!qp.W.isApprox(qp.W.transpose(), 1e-12)) bad_output("objective", name(), "W is not symmetric");
}

void Constraint::contribute(const Context& ctx, QpBuilder& builder) const {
  if (!active()) return;
  add_to(ctx, builder);
  if (weight() != 1.0) {
    builder.equality_matrix() *= weight();
    builder.equality_rhs() *= weight();
    builder.inequality_matrix() *= weight();
    builder.inequality_rhs() *= weight();
  }
  const QpProblem& qp = builder.problem();
  check_finite(qp.J, "constraint", name(), "J");
  check_finite(qp.d, "constraint", name(), "d");
  check_finite(qp.A, "constraint", name(), "A");
  check_finite(qp.b, "constraint", name(), "b");
}

ObjectiveRegistry& objective_registry() {
  static ObjectiveRegistry registry("objective");
  return registry;
}

ConstraintRegistry& constraint_registry() {
  static ConstraintRegistry registry("constraint");
  return registry;
}

std::unique_ptr<Objective> make_objective(const TableReader& config, const RobotModel& robot) {
  auto p = objective_registry().create(config, robot);
  config.finish();
  return p;
}

std::unique_ptr<Constraint> make_constraint(const TableReader& config, const RobotModel& robot) {
  auto p = constraint_registry().create(config, robot);
  config.finish();
  return p;
}

Eigen::VectorXd read_per_joint(const TableReader& config, std::string_view key, double fallback, int n) {
  if (!config.has(key)) return Eigen::VectorXd::Constant(n, fallback);
  const toml::node* node = config.raw().get(key);
  if (!node->is_array() && !node->is_number()) {
    config.fail(key, "expected a number or an array of " + std::to_string(n) + " numbers, got " +
                         describe_type(*node));
  }
  if (node->is_array()) {
    const std::vector<double> v = config.numbers(key, static_cast<std::size_t>(n));
    return Eigen::Map<const Eigen::VectorXd>(v.data(), n);
  }
  return Eigen::VectorXd::Constant(n, config.number(key));
}

void write_per_joint(toml::table& out, std::string_view key, const Eigen::VectorXd& values) {
  if (values.size() > 0 && (values.array() == values(0)).all()) {
    out.insert(key, values(0));
    return;
  }
  toml::array arr;
  for (Eigen::Index i = 0; i < values.size(); ++i) arr.push_back(values(i));
  out.insert(key, std::move(arr));
}

}  // namespace redres

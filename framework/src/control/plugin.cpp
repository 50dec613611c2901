#include "redres/control/plugin.hpp"
#include "common/text.hpp"

#include <cmath>
#include <sstream>

namespace redres {

Plugin::Plugin(std::string type) : type_(std::move(type)), name_(type_) {}

void Plugin::set_name(std::string name) {
  REDRES_REQUIRE(!name.empty(), "Plugin::set_name", "the name of a '" + type_ + "' plugin is not empty");
  name_ = std::move(name);
}

void Plugin::write_common(toml::table& out) const {
  out.insert("type", type_);
  out.insert("name", name_);
  out.insert("active", active_);
}

toml::table Plugin::config() const {
  toml::table out;
  write_common(out);
  write_config(out);
  return out;
}

void Objective::set_weight(double weight) {
  REDRES_REQUIRE(std::isfinite(weight) && weight >= 0.0, "Objective::set_weight",
                 "the weight of '" + name() + "' is finite and >= 0");
  weight_ = weight;
}

void Objective::set_priority(int priority) {
  REDRES_REQUIRE(priority >= 0, "Objective::set_priority", "the priority of '" + name() + "' is >= 0");
  priority_ = priority;
}

void Objective::write_common(toml::table& out) const {
  Plugin::write_common(out);
  out.insert("weight", weight_);
  if (priority_ != 0) out.insert("priority", priority_);  // a one-level scheme's configuration as it always was
}

namespace {

[[noreturn]] void bad_output(const char* kind, const Plugin& plugin, const std::string& what) {
  const std::string at = plugin.source().empty() ? "" : " (" + plugin.source() + ")";
  throw std::invalid_argument(std::string(kind) + " '" + plugin.name() + "'" + at + " produced an invalid QP: " + what);
}

template <class M>
void check_finite(const M& m, const char* kind, const Plugin& name, const char* what) {
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

// The checks after a contribution look at what the plugin can have written, and only at that: zeta if it added to it,
// the part of W it added to (nothing, the diagonal, or all of it, then also its symmetry), and a constraint's own
// rows. The scans are finite_probe() (qp.hpp); name_culprit names the entry on failure.

// x * 0 summed over rows [offset, offset + rows) of M (column-major) and of v.
double rows_probe(const Eigen::MatrixXd& M, const Eigen::VectorXd& v, int offset, int rows) {
  double acc = finite_probe(v.data() + offset, rows);
  for (Eigen::Index c = 0; c < M.cols(); ++c) acc += finite_probe(M.data() + c * M.rows() + offset, rows);
  return acc;
}

// The full check with the names of the culprits; runs only when the fast scan below finds a non-finite entry.
[[gnu::cold]] [[gnu::noinline]] void name_culprit(const QpBuilder& builder, const char* kind, const Plugin& name) {
  const QpProblem& qp = builder.problem();
  if (builder.wrote_zeta()) check_finite(qp.zeta, kind, name, "zeta");
  if (builder.written_w() != QpBuilder::WrittenW::kNone) check_finite(qp.W, kind, name, "W");
  // A constraint's own rows; entries are named by its own row (0-based), e.g. "its J(1, 4)".
  check_finite(qp.J.middleRows(builder.eq_offset(), builder.eq_rows()), kind, name, "its J");
  check_finite(qp.d.segment(builder.eq_offset(), builder.eq_rows()), kind, name, "its d");
  check_finite(qp.A.middleRows(builder.in_offset(), builder.in_rows()), kind, name, "its A");
  check_finite(qp.b.segment(builder.in_offset(), builder.in_rows()), kind, name, "its b");
}

void check_contribution(const QpBuilder& builder, const char* kind, const Plugin& name) {
  const QpProblem& qp = builder.problem();
  const Eigen::Index n = qp.zeta.size();
  double acc = builder.wrote_zeta() ? finite_probe(qp.zeta.data(), n) : 0.0;
  switch (builder.written_w()) {
    case QpBuilder::WrittenW::kNone: break;
    case QpBuilder::WrittenW::kDiagonal:
      for (Eigen::Index i = 0; i < n; ++i) acc += qp.W(i, i) * 0.0;
      break;
    case QpBuilder::WrittenW::kFull:
      acc += finite_probe(qp.W.data(), qp.W.size());
      if (acc == 0.0 && !qp.W.isApprox(qp.W.transpose(), 1e-12)) bad_output(kind, name, "W is not symmetric");
      break;
  }
  if (builder.eq_rows() > 0) acc += rows_probe(qp.J, qp.d, builder.eq_offset(), builder.eq_rows());
  if (builder.in_rows() > 0) acc += rows_probe(qp.A, qp.b, builder.in_offset(), builder.in_rows());
  if (acc != 0.0) name_culprit(builder, kind, name);
}

}  // namespace

void Objective::contribute(const Context& ctx, QpBuilder& builder, PluginData* data) const {
  if (!active()) return;
  add_to(ctx, builder, data);
  check_contribution(builder, "objective", *this);
}

void Constraint::contribute(const Context& ctx, QpBuilder& builder, PluginData* data) const {
  if (!active()) return;
  add_to(ctx, builder, data);
  check_contribution(builder, "constraint", *this);
}

ObjectiveRegistry& objective_registry() {
  static ObjectiveRegistry registry("objective");
  return registry;
}

ConstraintRegistry& constraint_registry() {
  static ConstraintRegistry registry("constraint");
  return registry;
}

namespace {

// The common keys, as a schema of their own so that the listing and the reading share one definition.
struct ObjectiveCommon {
  std::optional<std::string> name;
  double weight = 1.0;
  int priority = 0;
  bool active = true;
  static const Schema<ObjectiveCommon>& schema() {
    static const Schema<ObjectiveCommon> s{
        {field("name", &ObjectiveCommon::name, "", "instance name, used in diagnoses (default: the type)"),
         field("weight", &ObjectiveCommon::weight, "", "scales W and zeta", between(0.0, 1e6)),
         field("priority", &ObjectiveCommon::priority, "",
               "its level (0 the highest; docs/tasks.md): the levels below keep this level's optimum",
               between<int>(0, 100)),
         field("active", &ObjectiveCommon::active, "", "false builds the plugin but leaves it out of the QP")}};
    return s;
  }
};

struct ConstraintCommon {
  std::optional<std::string> name;
  bool active = true;
  static const Schema<ConstraintCommon>& schema() {
    static const Schema<ConstraintCommon> s{
        {field("name", &ConstraintCommon::name, "", "instance name, used in diagnoses (default: the type)"),
         field("active", &ConstraintCommon::active, "", "false builds the plugin but leaves it out of the QP")}};
    return s;
  }
};

}  // namespace

const std::vector<KeyInfo>& objective_common_keys() {
  static const std::vector<KeyInfo> keys = describe_keys(ObjectiveCommon::schema());
  return keys;
}

const std::vector<KeyInfo>& constraint_common_keys() {
  static const std::vector<KeyInfo> keys = describe_keys(ConstraintCommon::schema());
  return keys;
}

namespace {
// The common keys every plugin has: its instance name (when given) and whether it is active.
template <class Common>
void apply_common(const TableReader& config, const Common& common, Plugin& p) {
  if (common.name) {
    if (common.name->empty()) config.fail("name", "expected a non-empty name");
    if (const std::string why = column_name_problem(*common.name); !why.empty()) config.fail("name", why);
    p.set_name(*common.name);
  }
  p.set_active(common.active);
}
}  // namespace

std::unique_ptr<Objective> make_objective(const TableReader& config, const RobotModel& robot) {
  ObjectiveCommon common;
  read_config(config, ObjectiveCommon::schema(), common);
  auto p = objective_registry().create(config, robot);
  config.finish();
  apply_common(config, common, *p);
  p->set_weight(common.weight);
  p->set_priority(common.priority);
  return p;
}

std::unique_ptr<Constraint> make_constraint(const TableReader& config, const RobotModel& robot) {
  if (config.has("weight")) {
    config.fail("weight", "constraints are hard and have no weight (only objectives are weighted); remove the key");
  }
  ConstraintCommon common;
  read_config(config, ConstraintCommon::schema(), common);
  auto p = constraint_registry().create(config, robot);
  config.finish();
  apply_common(config, common, *p);
  return p;
}

}  // namespace redres

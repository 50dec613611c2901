#include "redres/tasks/posture.hpp"

#include <algorithm>
#include <cmath>

#include "redres/run/trajectory.hpp"

namespace redres {

const Schema<PostureConfig>& PostureConfig::schema() {
  using C = PostureConfig;
  static const Schema<C> s{
      {field("target", &C::target, "rad or m", "the configuration: one number or one per joint (default: home)"),
       field("weights", &C::weights, "", "per joint: one number or one per joint (0 leaves a joint out)",
             at_least<PerJoint>(0.0)),
       field("gain", &C::gain, "1/s", "feedback gain K", at_least(0.0))}};
  return s;
}

Posture::Posture(const Config& config, const RobotModel& robot) : Configured(kType, config) {
  set_dof(robot.dof());
  target_ = config_.target ? config_.target->resolve(robot.dof(), "target") : robot.home();
  const Eigen::VectorXd w = config_.weights.resolve(robot.dof(), "weights");
  std::vector<double> scale;
  for (int j = 0; j < robot.dof(); ++j) {
    if (w(j) <= 0.0) continue;
    joints_.push_back(j);
    names_.push_back(robot.joint(j).name);
    prismatic_.push_back(robot.joint(j).type == JointType::kPrismatic);
    scale.push_back(std::sqrt(w(j)));
  }
  if (joints_.empty()) throw FieldError("weights", "every weight is 0: the task would hold no joint");
  scale_ = Eigen::Map<const Eigen::VectorXd>(scale.data(), static_cast<Eigen::Index>(scale.size()));
}

void Posture::check_mode() const {
  if (mode() == TaskMode::kInequality) {
    throw FieldError("mode",
                     "a posture is a target, not bounds: use \"soft\" or \"equality\" (the joint limits are "
                     "the constraints')");
  }
}

std::string Posture::row_name(int r) const { return names_[static_cast<std::size_t>(r)]; }

std::string Posture::row_unit(int r) const { return prismatic_[static_cast<std::size_t>(r)] ? "m" : "rad"; }

void Posture::compute(const Context& ctx, TaskData& data) const {
  TaskTerms& t = data.rows;
  const Eigen::VectorXd& theta = ctx.theta();
  for (int r = 0; r < rows(); ++r) {
    const int j = joints_[static_cast<std::size_t>(r)];
    const double e = target_(j) - theta(j);
    t.J(r, j) = scale_(r);  // the other entries stay 0 from size_rows()
    t.d(r) = scale_(r) * config_.gain * e;
    t.error(r) = e;
  }
}

std::vector<std::string> Posture::recorded_columns() const { return {name() + "_error"}; }

void Posture::record(const PluginData* data, double* values) const {
  values[0] = static_cast<const TaskData&>(*data).rows.error.norm();
}

void Posture::summarise(const RobotModel& /*robot*/, const Trajectory& run, const PluginData* /*data*/,
                        std::vector<Metric>& out) const {
  const std::size_t c = own_column(run, name(), name() + "_error");
  double w = 0.0;
  for (std::size_t row = 0; row < run.size(); ++row) w = std::max(w, run(row, c));
  out.push_back({"max_error", {w}, "rad"});
}

namespace {
const bool kPostureRegistered =
    task_registry().add_plugin<Posture>("the joints towards a configuration, weighted per joint (theta_ref - theta)");
}  // namespace

}  // namespace redres

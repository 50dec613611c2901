#include "qp_util.hpp"

#include <cmath>

#include <Eigen/QR>

#include "redres/parsers/robot_toml.hpp"
#include "scenario_text.hpp"
#include "test_util.hpp"

namespace redres::testing {

RandomQp random_qp(std::mt19937& rng, int n, int m_e, int m_i, bool dense_w) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.5, 2.0), width(0.0, 1.0), coin(0.0, 1.0);
  RandomQp out;
  QpProblem& qp = out.qp;
  qp.resize(n, m_e, m_i);
  qp.source_names = {"random"};
  out.feasible.resize(n);
  for (int i = 0; i < n; ++i) out.feasible(i) = u(rng);
  if (dense_w) {
    Eigen::MatrixXd B(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) B(i, j) = u(rng);
    qp.W = B * B.transpose() / n + 0.5 * Eigen::MatrixXd::Identity(n, n);
    qp.w_diagonal = false;
  } else {
    for (int i = 0; i < n; ++i) qp.W(i, i) = pos(rng);
  }
  for (int i = 0; i < n; ++i) qp.zeta(i) = 2.0 * u(rng);
  // J with orthonormal rows scaled by [0.5, 1.5]: random, and conditioned like a Jacobian away from singularity.
  if (m_e > 0) {
    Eigen::MatrixXd B(n, m_e);
    for (int r = 0; r < m_e; ++r)
      for (int i = 0; i < n; ++i) B(i, r) = u(rng);
    const Eigen::MatrixXd Q =
        Eigen::HouseholderQR<Eigen::MatrixXd>(B).householderQ() * Eigen::MatrixXd::Identity(n, m_e);
    for (int r = 0; r < m_e; ++r) qp.J.row(r) = (1.0 + 0.5 * u(rng)) * Q.col(r).transpose();
  }
  qp.d = qp.J * out.feasible;
  for (int r = 0; r < m_i; ++r)
    for (int i = 0; i < n; ++i) qp.A(r, i) = u(rng);
  for (int r = 0; r < m_i; ++r) qp.b(r) = qp.A.row(r).dot(out.feasible) + 0.5 * width(rng);
  for (int i = 0; i < n; ++i) {
    // About a third of the boxes are narrow, so that bounds are active in a good share of the problems.
    const double scale = coin(rng) < 0.33 ? 0.05 : 1.0;
    qp.lo(i) = out.feasible(i) - scale * width(rng);
    qp.hi(i) = out.feasible(i) + scale * width(rng);
    qp.lo_source[static_cast<std::size_t>(i)] = 0;
    qp.hi_source[static_cast<std::size_t>(i)] = 0;
  }
  qp.eq_source.assign(static_cast<std::size_t>(m_e), 0);
  qp.in_source.assign(static_cast<std::size_t>(m_i), 0);
  return out;
}

double kkt_residual(const QpProblem& qp, const SolverResult& r) {
  const Eigen::VectorXd& x = r.x;
  double worst = 0.0;
  if (qp.m_eq() > 0) worst = std::max(worst, (qp.J * x - qp.d).cwiseAbs().maxCoeff());
  if (qp.m_in() > 0) {
    const Eigen::VectorXd slack = qp.b - qp.A * x;
    for (int k = 0; k < qp.m_in(); ++k) {
      // Complementarity and signs at once: z >= 0, slack >= 0, z * slack = 0  <=>  min(z, slack) = 0.
      worst = std::max(worst, std::abs(std::min(r.z(k), slack(k))));
    }
  }
  // Stationarity with the box multipliers eliminated: x = P_[lo,hi](x - g), g = W x + zeta - J'y + A'z.
  const Eigen::VectorXd g = qp.W * x + qp.zeta - qp.J.transpose() * r.y + qp.A.transpose() * r.z;
  for (int i = 0; i < qp.n(); ++i) {
    worst = std::max({worst, qp.lo(i) - x(i), x(i) - qp.hi(i)});
    worst = std::max(worst, std::abs(x(i) - std::clamp(x(i) - g(i), qp.lo(i), qp.hi(i))));
  }
  return worst;
}

double qp_objective(const QpProblem& qp, const Eigen::VectorXd& x) { return 0.5 * x.dot(qp.W * x) + qp.zeta.dot(x); }

const char* const kPaperSchemeToml = R"(
[[objectives]]
type = "min_velocity_norm"

[[objectives]]
type = "manipulability"
measure = "det"
schedule = "sine"
p = 2.0

[[constraints]]
type = "task_tracking"
gain = 8.0

[[constraints]]
type = "joint_angle_margin"
kappa = 4.0
margin = 0.0349

[[constraints]]
type = "joint_velocity_limits"
)";

std::unique_ptr<PaperStep> make_paper_step(const std::string& scheme_toml) {
  auto s = std::make_unique<PaperStep>();
  s->robot = std::make_unique<RobotModel>(load_robot(source_path("robots/paper_pushrod_6dof.toml")));
  s->scheme = scheme_from_text(scheme_toml.empty() ? kPaperSchemeToml : scheme_toml, *s->robot, "<scheme>");
  s->kin = std::make_unique<KinematicsData>(*s->robot);
  s->r_d = Eigen::VectorXd::Zero(2);
  s->r_d_dot = Eigen::VectorXd::Zero(2);
  s->data = s->scheme->make_data();
  s->scheme->setup(s->qp, s->data);
  s->ctx.robot = s->robot.get();
  s->ctx.kinematics = s->kin.get();
  s->ctx.r_d = &s->r_d;
  s->ctx.r_d_dot = &s->r_d_dot;
  s->ctx.T = 40.0;
  s->ctx.tau = 0.01;
  return s;
}

void paper_family_qp(std::mt19937& rng, PaperStep& step, double speed) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const RobotModel& robot = *step.robot;
  Eigen::VectorXd theta(robot.dof());
  for (int j = 0; j < robot.dof(); ++j) {
    const double lo = robot.lower_limits()(j) + 0.036, hi = robot.upper_limits()(j) - 0.036;
    theta(j) = lo + (hi - lo) * u(rng);
  }
  const double angle = 2.0 * M_PI * u(rng);
  const double v = speed * u(rng);
  const double e_angle = 2.0 * M_PI * u(rng);
  const double e = 1e-3 * u(rng);
  step.build(theta, 40.0 * u(rng), Eigen::Vector2d(v * std::cos(angle), v * std::sin(angle)),
             Eigen::Vector2d(e * std::cos(e_angle), e * std::sin(e_angle)));
}

void PaperStep::build(const Eigen::VectorXd& theta, double t, const Eigen::Vector2d& rd_dot,
                      const Eigen::Vector2d& dr) {
  compute_kinematics(*robot, theta, *kin, scheme->kinematics_level());
  ctx.t = t;
  r_d = kin->f + dr;
  r_d_dot = rd_dot;
  scheme->build(ctx, qp, data);
}

}  // namespace redres::testing

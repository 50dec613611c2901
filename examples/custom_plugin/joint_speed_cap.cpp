// An out-of-tree constraint plugin, built against an installed redres (find_package(redres)), and a small
// control loop that uses it from a TOML file.
//
//   custom_plugin_example [scheme.toml]
//
// `joint_speed_cap` keeps the speed of chosen joints within +-cap as inequality rows (2 rows per joint):
//   x_j <= cap  and  -x_j <= cap.
// TOML keys: `joints` (1-based joint numbers, default [1]), `cap` (rad/s, > 0, default 0.05).

#include <algorithm>
#include <iostream>

#include <redres/lvi.hpp>
#include <redres/scheme.hpp>

namespace {

class JointSpeedCap final : public redres::Constraint {
 public:
  JointSpeedCap(const redres::TableReader& config, const redres::RobotModel& robot)
      : Constraint(config), cap_(config.number("cap", 0.05)) {
    if (!(cap_ > 0.0)) config.fail("cap", "expected a speed cap > 0 rad/s");
    const std::vector<double> joints = config.has("joints") ? config.numbers("joints") : std::vector<double>{1.0};
    for (double j : joints) {
      if (j != static_cast<int>(j) || j < 1 || j > robot.dof()) {
        config.fail("joints", "expected joint numbers from 1 to " + std::to_string(robot.dof()));
      }
      joints_.push_back(static_cast<int>(j) - 1);
    }
  }
  int inequality_rows(const redres::RobotModel&) const override { return 2 * static_cast<int>(joints_.size()); }

 private:
  void add_to(const redres::Context&, redres::QpBuilder& builder) const override {
    auto A = builder.inequality_matrix();
    A.setZero();
    for (std::size_t k = 0; k < joints_.size(); ++k) {
      A(static_cast<Eigen::Index>(2 * k), joints_[k]) = 1.0;
      A(static_cast<Eigen::Index>(2 * k + 1), joints_[k]) = -1.0;
    }
    builder.inequality_rhs().setConstant(cap_);
  }
  void write_config(toml::table& out) const override {
    toml::array joints;
    for (int j : joints_) joints.push_back(j + 1);
    out.insert("joints", std::move(joints));
    out.insert("cap", cap_);
  }

  double cap_;
  std::vector<int> joints_;
};

// Registers the plugin by name, exactly as the built-in ones do.
const bool kRegistered = redres::constraint_registry().add({
    "joint_speed_cap",
    "|x_j| <= cap for chosen joints (inequality rows)",
    {{"joints", "[1]", "1-based joint numbers"}, {"cap", "0.05", "speed cap (rad/s)"}},
    [](const redres::TableReader& r, const redres::RobotModel& robot) -> std::unique_ptr<redres::Constraint> {
      return std::make_unique<JointSpeedCap>(r, robot);
    },
});

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string file = argc > 1 ? argv[1] : REDRES_EXAMPLE_SCHEME;
    const auto toml = redres::parse_toml_file(file);
    const redres::TableReader root = redres::TableReader::root(toml);
    const redres::RobotModel robot = redres::load_robot(root.path("robot"));
    const redres::Scheme scheme = redres::Scheme::from_toml(root, robot);
    auto engine = redres::make_engine(root.table("solver"));
    root.finish();

    // Setup: every buffer is sized here, once.
    redres::QpProblem qp;
    scheme.setup(qp);
    redres::SolverResult result;
    engine->setup(qp.n(), qp.m_eq(), qp.m_in(), result);
    redres::KinematicsData kin(robot);
    Eigen::VectorXd theta = robot.home();
    compute_kinematics(robot, theta, kin, scheme.kinematics_level());
    const Eigen::VectorXd start = kin.f;
    Eigen::VectorXd r_d = start, r_d_dot = Eigen::VectorXd::Zero(robot.task_dim());
    redres::Context ctx{0.0, 2.0, 0.01, &robot, &kin, &r_d, &r_d_dot};

    // Move the end effector at 0.02 m/s along -x for 2 s; joint 1 may turn at 0.05 rad/s at most.
    int failures = 0;
    double max_speed = 0.0;
    for (int k = 0; k < 200; ++k) {
      ctx.t = k * ctx.tau;
      r_d_dot(0) = -0.02;
      r_d(0) = start(0) - 0.02 * ctx.t;
      compute_kinematics(robot, theta, kin, scheme.kinematics_level());
      scheme.build(ctx, qp);
      engine->solve(qp, result);
      if (result.info.status != redres::SolverStatus::kSolved) ++failures;
      max_speed = std::max(max_speed, std::abs(result.x(0)));
      theta += ctx.tau * result.x;
    }
    std::cout << "joint_speed_cap example: 200 steps, " << failures << " failed, engine " << result.info.engine
              << ", max |theta_dot_1| " << max_speed << " rad/s (cap 0.05), final error "
              << (kin.f - r_d).norm() << " m\n";
    return failures == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
}

// What a plugin writes into the step's QP is checked by Scheme::build, whatever it wrote and wherever: a NaN or an
// infinity in zeta, in W (on or off its diagonal), in a constraint's rows or right-hand sides, a NaN bound, and a W
// that is not symmetric are std::invalid_argument naming the plugin and the entry; finite contributions pass. A
// plugin whose NaN the checked second build cannot reproduce is reported as such.

#include <limits>

#include <gtest/gtest.h>

#include "redres/control/plugin.hpp"
#include "redres/control/scheme.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// An objective that adds one chosen entry to zeta, W's diagonal or W (as a symmetric or a lopsided Hessian).
class Writer final : public Objective {
 public:
  enum class Where { kZeta, kDiagonal, kHessian, kLopsided };
  Writer(Where where, double value) : Objective("writer"), where_(where), value_(value) {}

 private:
  void add_to(const Context& ctx, QpBuilder& b, PluginData* /*data*/) const override {
    const int n = ctx.robot->dof();
    Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
    Eigen::MatrixXd H = Eigen::MatrixXd::Identity(n, n);
    switch (where_) {
      case Where::kZeta:
        v(2) = value_;
        b.add_linear(v);
        break;
      case Where::kDiagonal:
        v.setOnes();
        v(1) = value_;
        b.add_diagonal(v);
        break;
      case Where::kHessian:
        H(0, 3) = H(3, 0) = value_;
        b.add_hessian(H);
        break;
      case Where::kLopsided:
        H(0, 3) = value_;
        b.add_hessian(H);
        break;
    }
  }
  void write_config(toml::table&) const override {}
  Where where_;
  double value_;
};

// A constraint with one equality and one inequality row; one entry is `value`.
class RowWriter final : public Constraint {
 public:
  enum class Where { kJ, kD, kA, kB };
  RowWriter(Where where, double value) : Constraint("row_writer"), where_(where), value_(value) {}
  int equality_rows(const RobotModel&) const override { return 1; }
  int inequality_rows(const RobotModel&) const override { return 1; }

 private:
  void add_to(const Context&, QpBuilder& b, PluginData* /*data*/) const override {
    b.equality_matrix().setOnes();
    b.equality_rhs().setZero();
    b.inequality_matrix().setOnes();
    b.inequality_rhs().setOnes();
    switch (where_) {
      case Where::kJ: b.equality_matrix()(0, 4) = value_; break;
      case Where::kD: b.equality_rhs()(0) = value_; break;
      case Where::kA: b.inequality_matrix()(0, 1) = value_; break;
      case Where::kB: b.inequality_rhs()(0) = value_; break;
    }
  }
  void write_config(toml::table&) const override {}
  Where where_;
  double value_;
};

// A constraint that adds to zeta (constraints may, like objectives) or intersects the bounds with a NaN at joint 3.
class ZetaAndBoundWriter final : public Constraint {
 public:
  enum class Where { kZeta, kBound };
  explicit ZetaAndBoundWriter(Where where) : Constraint("zeta_writer"), where_(where) {}

 private:
  void add_to(const Context& ctx, QpBuilder& b, PluginData* /*data*/) const override {
    const int n = ctx.robot->dof();
    Eigen::VectorXd lo = Eigen::VectorXd::Constant(n, -1.0), hi = Eigen::VectorXd::Constant(n, 1.0);
    if (where_ == Where::kZeta) {
      lo(4) = kNaN;
      b.add_linear(lo);
    } else {
      hi(2) = kNaN;
      b.intersect_bounds(lo, hi);
    }
  }
  void write_config(toml::table&) const override {}
  Where where_;
};

// An objective whose first contribution is NaN and every later one finite: what the checked second build cannot
// reproduce.
class Flaky final : public Objective {
 public:
  Flaky() : Objective("flaky") {}

 private:
  void add_to(const Context& ctx, QpBuilder& b, PluginData* /*data*/) const override {
    Eigen::VectorXd z = Eigen::VectorXd::Zero(ctx.robot->dof());
    if (calls_++ == 0) z(0) = kNaN;
    b.add_linear(z);
  }
  void write_config(toml::table&) const override {}
  mutable int calls_ = 0;
};

std::string build_error(std::unique_ptr<Objective> objective, std::unique_ptr<Constraint> constraint) {
  const RobotModel robot = load_robot(source_path("robots/paper_pushrod_6dof.toml"));
  std::vector<std::unique_ptr<Objective>> objectives;
  std::vector<std::unique_ptr<Constraint>> constraints;
  if (objective) objectives.push_back(std::move(objective));
  if (constraint) constraints.push_back(std::move(constraint));
  const Scheme scheme(robot, std::move(objectives), std::move(constraints));
  QpProblem qp;
  SchemeData scheme_data = scheme.make_data();
  scheme.setup(qp, scheme_data);
  KinematicsData k(robot);
  compute_kinematics(robot, robot.home(), k, KinematicsLevel::kAll);
  Eigen::VectorXd r_d = k.f, r_d_dot = Eigen::VectorXd::Zero(2);
  const Context ctx{0.0, 1.0, 0.01, &robot, &k, &r_d, &r_d_dot};
  try {
    scheme.build(ctx, qp, scheme_data);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(PluginOutput, NonFiniteObjectiveTermsNameThePluginAndTheEntry) {
  using W = Writer::Where;
  for (double bad : {kNaN, kInf, -kInf}) {
    EXPECT_NE(build_error(std::make_unique<Writer>(W::kZeta, bad), nullptr)
                  .find("objective 'writer' produced an "
                        "invalid QP: zeta(2, 0)"),
              std::string::npos);
    EXPECT_NE(build_error(std::make_unique<Writer>(W::kDiagonal, bad), nullptr).find("W(1, 1)"), std::string::npos);
    EXPECT_NE(build_error(std::make_unique<Writer>(W::kHessian, bad), nullptr).find("W(3, 0)"), std::string::npos);
  }
  EXPECT_NE(build_error(std::make_unique<Writer>(W::kLopsided, 0.5), nullptr).find("W is not symmetric"),
            std::string::npos);
  for (W where : {W::kZeta, W::kDiagonal, W::kHessian}) {
    EXPECT_EQ(build_error(std::make_unique<Writer>(where, 0.25), nullptr), "");
  }
}

TEST(PluginOutput, NonFiniteConstraintRowsNameThePluginAndItsRow) {
  using R = RowWriter::Where;
  const std::pair<R, const char*> cases[] = {
      {R::kJ, "its J(0, 4)"}, {R::kD, "its d(0, 0)"}, {R::kA, "its A(0, 1)"}, {R::kB, "its b(0, 0)"}};
  for (const auto& [where, entry] : cases) {
    for (double bad : {kNaN, kInf}) {
      const std::string e = build_error(nullptr, std::make_unique<RowWriter>(where, bad));
      EXPECT_NE(e.find("constraint 'row_writer' produced an invalid QP: " + std::string(entry)), std::string::npos)
          << e;
    }
    EXPECT_EQ(build_error(nullptr, std::make_unique<RowWriter>(where, 2.0)), "");
  }
}

TEST(PluginOutput, AConstraintsZetaAndBoundsAreCheckedAndAnIrreproducibleNanIsNamed) {
  using Z = ZetaAndBoundWriter::Where;
  const std::string zeta = build_error(nullptr, std::make_unique<ZetaAndBoundWriter>(Z::kZeta));
  EXPECT_NE(zeta.find("constraint 'zeta_writer' produced an invalid QP: zeta(4, 0)"), std::string::npos) << zeta;
  const std::string bound = build_error(nullptr, std::make_unique<ZetaAndBoundWriter>(Z::kBound));
  EXPECT_NE(bound.find("a bound of joint 3 is NaN"), std::string::npos) << bound;
  const std::string flaky = build_error(std::make_unique<Flaky>(), nullptr);
  EXPECT_NE(flaky.find("a second build did not reproduce"), std::string::npos) << flaky;
}

}  // namespace
}  // namespace redres

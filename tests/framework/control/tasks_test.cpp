// Tasks and strict priorities (control/task.hpp, control/cascade.hpp, docs/tasks.md):
// - a frame task's rows are the derivative of its error (central differences), for position, orientation and axis
//   rows, and its orientation error is the rotation vector of R_d R';
// - at random states of random chains with random levels of tasks (rapidcheck), the controller's cascade agrees with
//   an independent lexicographic solve (a cascade of NLopt SLSQP problems) to 1e-7, and each level's answer meets its
//   KKT conditions with the higher levels' optima held;
// - two conflicting tasks: the higher one is met to 1e-9, the lower one as well as it can be, and swapping the
//   priorities swaps the outcome;
// - a soft task with a very large weight approaches the hard one;
// - one level is the single QP of before; a lower level that cannot be solved keeps the higher levels' answer.

#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "lexicographic_reference.hpp"
#include "random_chain.hpp"
#include "redres/constraints/joint_velocity_limits.hpp"
#include "redres/control/controller.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/model/frames.hpp"
#include "redres/objectives/min_velocity_norm.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/tasks/frame_task.hpp"
#include "redres/tasks/posture.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

std::unique_ptr<Task> frame_task(const RobotModel& robot, const std::string& name, FrameTaskConfig c, TaskMode mode,
                                 int priority, double weight = 1.0) {
  auto t = std::make_unique<FrameTask>(c, robot);
  t->set_name(name);
  t->set_mode(mode);
  t->set_priority(priority);
  t->set_weight(weight);
  t->check_mode();
  return t;
}

std::unique_ptr<Objective> min_norm(const RobotModel& robot, int priority) {
  auto o = std::make_unique<MinVelocityNorm>(MinVelocityNorm::Config{}, robot);
  o->set_priority(priority);
  return o;
}

// A controller over its own scheme and engine, stepped with caller-supplied (unused) r_d.
struct Rig {
  std::unique_ptr<Scheme> scheme;
  std::unique_ptr<LviEngine> engine;
  std::unique_ptr<Controller> ctrl;
  StepOutput out;

  Rig(const RobotModel& robot, std::vector<std::unique_ptr<Objective>> objectives,
      std::vector<std::unique_ptr<Constraint>> constraints, std::vector<std::unique_ptr<Task>> tasks,
      double eps = Scheme::kDefaultRegularization, double tolerance = 1e-12) {
    scheme = std::make_unique<Scheme>(robot, std::move(objectives), std::move(constraints), std::move(tasks));
    scheme->set_regularization(eps);
    SolverSettings s;
    s.tolerance = tolerance;
    engine = make_engine("newton", s);
    ctrl = std::make_unique<Controller>(robot, *scheme, *engine, nullptr, 10.0, 0.01);
    out = ctrl->make_output();
  }
  const Eigen::VectorXd& step(const Eigen::VectorXd& theta) {
    const Eigen::VectorXd r = Eigen::VectorXd::Zero(ctrl->robot().reference_dim());
    ctrl->step(theta, 0.0, r, r, out);
    return out.theta_dot;
  }
  [[nodiscard]] const TaskTerms& terms(std::size_t k) const {
    return static_cast<const TaskData&>(*ctrl->plugin_data().tasks[k]).rows;
  }
};

// ---------------------------------------------------------------------------------------------------------------
// A frame task's rows against central differences of its error.

// e(theta) of every row of `task` (its reference captured at theta0, or fixed).
Eigen::VectorXd task_error(const RobotModel& robot, const Task& task, PluginData& data, const Eigen::VectorXd& theta) {
  KinematicsData k(robot);
  compute_kinematics(robot, theta, k, KinematicsLevel::kJacobian);
  Context ctx;
  ctx.robot = &robot;
  ctx.kinematics = &k;
  ctx.T = 1.0;
  ctx.tau = 0.01;
  task.evaluate(ctx, static_cast<TaskData&>(data));
  return static_cast<TaskData&>(data).rows.error;
}

// The largest |de/dtheta dir + J dir| over random directions, by central differences at theta (the reference is
// captured at `at` first).
double derivative_gap(const RobotModel& robot, const Task& task, const Eigen::VectorXd& at,
                      const Eigen::VectorXd& theta) {
  auto data = task.make_data();
  task.start(data.get());
  (void)task_error(robot, task, *data, at);  // captures a "start" reference at `at`
  (void)task_error(robot, task, *data, theta);
  const Eigen::MatrixXd J = static_cast<TaskData&>(*data).rows.J;
  double worst = 0.0;
  const double h = 1e-6;
  for (int c = 0; c < robot.dof(); ++c) {
    Eigen::VectorXd plus = theta, minus = theta;
    plus(c) += h;
    minus(c) -= h;
    const Eigen::VectorXd de = (task_error(robot, task, *data, plus) - task_error(robot, task, *data, minus)) / (2 * h);
    worst = std::max(worst, (de + J.col(c)).cwiseAbs().maxCoeff());
  }
  return worst;
}

RC_GTEST_PROP(Tasks, AFrameTasksRowsAreTheDerivativeOfItsError, ()) {
  const int n = *rc::gen::inRange(3, 8);
  const RobotModel robot(testing::random_spatial(n, TaskRows::kPosition));
  const Eigen::VectorXd theta = testing::random_theta(robot);
  FrameTaskConfig c;
  c.frame =
      robot.frames()[static_cast<std::size_t>(*rc::gen::inRange(0, static_cast<int>(robot.frames().size())))].name;
  c.point = {testing::draw(-0.2, 0.2), testing::draw(-0.2, 0.2), testing::draw(-0.2, 0.2)};
  c.reference = "fixed";
  c.position = {testing::draw(-1, 1), testing::draw(-1, 1), testing::draw(-1, 1)};
  c.rows = {"x", "y", "z"};
  const auto position = frame_task(robot, "p", c, TaskMode::kEquality, 0);
  // Position rows: everywhere.
  RC_ASSERT(derivative_gap(robot, *position, theta, theta) < 1e-6);
  // Orientation and axis rows, at their reference (where log(R_d R') is differentiated as -omega).
  c.reference = "start";
  c.position.reset();
  c.rows = {"x", "wx", "wy", "wz"};
  const auto pose = frame_task(robot, "o", c, TaskMode::kEquality, 0);
  RC_ASSERT(derivative_gap(robot, *pose, theta, theta) < 1e-6);
  c.rows = {"axis"};
  c.axis = {testing::draw(-1, 1), testing::draw(-1, 1), 1.0};
  const auto axis = frame_task(robot, "a", c, TaskMode::kEquality, 0);
  RC_ASSERT(derivative_gap(robot, *axis, theta, theta) < 1e-6);
}

TEST(Tasks, TheOrientationErrorIsTheRotationVectorOfTheReferenceTimesTheInverse) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  FrameTaskConfig c;
  c.frame = "panda_joint4";
  c.rows = {"wx", "wy", "wz"};
  c.reference = "fixed";
  c.rpy = {0.3, -0.2, 1.1};
  const auto task = frame_task(robot, "o", c, TaskMode::kEquality, 0);
  auto data = task->make_data();
  const Eigen::VectorXd theta = robot.home();
  const Eigen::VectorXd e = task_error(robot, *task, *data, theta);
  KinematicsData k(robot);
  compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
  const Eigen::Matrix3d R = frame_pose(robot, k, robot.find_frame("panda_joint4")).linear();
  const Eigen::Matrix3d R_d =
      (Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  // Turning the frame by e (world axes) brings it onto the reference.
  EXPECT_LT((rotation_from_vector(e) * R - R_d).norm(), 1e-12);
  // d = K e for a fixed reference (gain 1).
  EXPECT_LT((static_cast<TaskData&>(*data).rows.d - e).norm(), 1e-15);
}

// ---------------------------------------------------------------------------------------------------------------
// The cascade against the independent lexicographic reference.

// The stacked rows of the given tasks (soft and equality tasks scaled by sqrt(weight)).
void stack(const Rig& rig, const std::vector<std::size_t>& tasks, testing::ReferenceLevel& level, int n) {
  int eq = 0, in = 0;
  for (std::size_t k : tasks) {
    const Task& t = *rig.scheme->tasks()[k];
    (t.mode() == TaskMode::kInequality ? in : eq) += t.mode() == TaskMode::kInequality ? t.inequality_rows() : t.rows();
  }
  level.J = Eigen::MatrixXd::Zero(eq, n);
  level.d = Eigen::VectorXd::Zero(eq);
  level.G = Eigen::MatrixXd::Zero(in, n);
  level.h = Eigen::VectorXd::Zero(in);
  eq = in = 0;
  for (std::size_t k : tasks) {
    const Task& t = *rig.scheme->tasks()[k];
    const TaskTerms& terms = rig.terms(k);
    if (t.mode() == TaskMode::kInequality) {
      for (int r = 0; r < t.rows(); ++r) {
        if (t.has_upper(r)) {
          level.G.row(in) = terms.J.row(r);
          level.h(in++) = terms.hi(r);
        }
        if (t.has_lower(r)) {
          level.G.row(in) = -terms.J.row(r);
          level.h(in++) = -terms.lo(r);
        }
      }
    } else {
      const double s = std::sqrt(t.weight());
      level.J.middleRows(eq, t.rows()) = s * terms.J;
      level.d.segment(eq, t.rows()) = s * terms.d;
      eq += t.rows();
    }
  }
}

double level_value(const testing::ReferenceLevel& level, const Eigen::VectorXd& x) {
  double f = level.J.rows() > 0 ? (level.J * x - level.d).squaredNorm() : 0.0;
  if (level.G.rows() > 0) f += (level.G * x - level.h).cwiseMax(0.0).squaredNorm();
  return f;
}

RC_GTEST_PROP(Tasks, TheCascadeAgreesWithAnIndependentLexicographicSolve, ()) {
  const bool planar = *rc::gen::arbitrary<bool>();
  const int n = *rc::gen::inRange(4, 8);
  const RobotModel robot(planar ? testing::random_planar(n, TaskRows::kPosition)
                                : testing::random_spatial(n, TaskRows::kPosition));
  const Eigen::VectorXd theta = testing::random_theta(robot);
  KinematicsData k(robot);
  compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
  const int levels = *rc::gen::inRange(2, 4);
  std::vector<std::unique_ptr<Task>> tasks;
  std::vector<std::vector<std::size_t>> by_level(static_cast<std::size_t>(levels));
  const std::vector<std::string> all_rows =
      planar ? std::vector<std::string>{"x", "y", "wz"} : std::vector<std::string>{"x", "y", "z", "wx", "wy", "wz"};
  for (int l = 0; l < levels; ++l) {
    // Each level is one kind: equality tasks, soft tasks, or an inequality task (docs/tasks.md: within a level the
    // equality and inequality rows are hard for its soft terms; the reference has no such order within a level).
    const int kind = *rc::gen::inRange(0, 3);
    const int count = kind == 2 ? 1 : *rc::gen::inRange(1, 3);
    for (int t = 0; t < count; ++t) {
      FrameTaskConfig c;
      const int frame = *rc::gen::inRange(0, static_cast<int>(robot.frames().size()));
      c.frame = robot.frames()[static_cast<std::size_t>(frame)].name;
      c.reference = "fixed";
      const Eigen::Vector3d p = frame_pose(robot, k, frame).translation();
      c.position = {p.x() + testing::draw(-0.3, 0.3), p.y() + testing::draw(-0.3, 0.3),
                    planar ? 0.0 : p.z() + testing::draw(-0.3, 0.3)};
      c.rpy = {testing::draw(-0.5, 0.5), testing::draw(-0.5, 0.5), testing::draw(-3, 3)};
      if (planar) c.rpy = std::array<double, 3>{0.0, 0.0, testing::draw(-3, 3)};
      c.gain = testing::draw(0.2, 2.0);
      c.rows.clear();
      TaskMode mode = kind == 0 ? TaskMode::kEquality : TaskMode::kSoft;
      if (kind == 2) {
        mode = TaskMode::kInequality;
        c.rows = {planar ? "y" : "z"};
        const double at = planar ? p.y() : p.z();
        c.position.reset();
        c.rpy.reset();
        c.reference = "start";
        c.lower = std::vector<double>{at + testing::draw(-0.2, 0.2)};
      } else {
        for (const auto& r : all_rows) {
          if (*rc::gen::inRange(0, 2) == 1) c.rows.push_back(r);
        }
        if (c.rows.empty()) c.rows.push_back("x");
      }
      tasks.push_back(frame_task(robot, "t" + std::to_string(tasks.size()), c, mode, l, testing::draw(0.5, 2.0)));
      by_level[static_cast<std::size_t>(l)].push_back(tasks.size() - 1);
    }
  }
  std::vector<std::unique_ptr<Objective>> objectives;
  objectives.push_back(min_norm(robot, levels));  // the last level: the smallest velocity among the optima
  std::vector<std::unique_ptr<Constraint>> constraints;
  constraints.push_back(std::make_unique<JointVelocityLimits>(JointVelocityLimits::Config{}, robot));
  Rig rig(robot, std::move(objectives), std::move(constraints), std::move(tasks), 1e-8, 1e-9);
  // Well-conditioned rows only: where the rows of a level with those above it have a singular value between 1e-9 and
  // 1e-3 of the largest, both solvers' answers move by their tolerances over that value (checked elsewhere: the
  // conflict test below has exactly dependent rows).
  const Eigen::VectorXd x = rig.step(theta);
  {
    Eigen::MatrixXd stacked(0, n);
    for (const auto& level : by_level) {
      for (std::size_t t : level) {
        const Eigen::MatrixXd& J = rig.terms(t).J;
        stacked.conservativeResize(stacked.rows() + J.rows(), n);
        stacked.bottomRows(J.rows()) = J;
      }
      if (stacked.rows() == 0) continue;
      // The squared singular values: the eigenvalues of J'J, in increasing order.
      const Eigen::VectorXd ev =
          Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(stacked.transpose() * stacked, Eigen::EigenvaluesOnly)
              .eigenvalues();
      const double top = ev(ev.size() - 1);
      for (Eigen::Index i = 0; i < ev.size(); ++i) RC_PRE(ev(i) < 1e-14 * top || ev(i) > 1e-6 * top);
    }
  }
  // The reference: the same rows, bounds, levels, and the velocity norm last.
  testing::ReferenceProblem p;
  p.lo = rig.ctrl->qp().lo;
  p.hi = rig.ctrl->qp().hi;
  p.A.resize(0, n);
  p.b.resize(0);
  for (const auto& level : by_level) {
    testing::ReferenceLevel r;
    stack(rig, level, r, n);
    p.levels.push_back(r);
  }
  p.levels.push_back(
      {Eigen::MatrixXd::Identity(n, n), Eigen::VectorXd::Zero(n), Eigen::MatrixXd(0, n), Eigen::VectorXd(0)});
  testing::ReferenceSolution ref;
  try {
    ref = testing::solve_lexicographic(p, Eigen::VectorXd::Zero(n));
  } catch (const std::runtime_error& e) {
    RC_DISCARD(std::string("the reference could not solve it: ") + e.what());  // rare: SLSQP's iteration limit
  }
  if (rig.out.levels[0].status == SolverStatus::kInfeasible) {
    // Level 0's tasks are hard: the step fails (for the failure policy) exactly where they cannot be met.
    RC_ASSERT(ref.residual[0] > 1e-12);
    return;
  }
  // A level that fails keeps the answer of the levels above it (rare here: an engine stopped at a degenerate vertex
  // of the held rows and the bounds); then only the levels above it are compared.
  std::size_t compared = p.levels.size();
  for (std::size_t l = 0; l < rig.out.levels.size(); ++l) {
    const LevelInfo& level = rig.out.levels[l];
    if (level.status == SolverStatus::kSolved || level.status == SolverStatus::kRelaxed) continue;
    // A level below one that decided every joint velocity has nothing to do (and says so).
    if (level.status == SolverStatus::kNotRun && level.diagnosis.find("nothing left to decide") != std::string::npos) {
      continue;
    }
    RC_ASSERT(level.status != SolverStatus::kNotRun);  // skipped only below a failed level, which comes first
    RC_ASSERT(level.diagnosis.find("the step keeps the answer of the levels above") != std::string::npos);
    compared = l;
    break;
  }
  RC_CLASSIFY(compared < p.levels.size(), "a lower level failed and kept the answer above it");
  // Compared lexicographically: at the first level where the two differ (by more than 1e-7 relative, 1e-10 absolute),
  // redres's value must be the lower one (below it, a better higher level may cost a lower one).
  bool same = true;
  for (std::size_t l = 0; l < compared && same; ++l) {
    const double mine = level_value(p.levels[l], x), theirs = ref.residual[l];
    if (std::abs(mine - theirs) <= 1e-7 * theirs + 1e-10) continue;
    same = false;
    if (!(mine < theirs)) {
      std::ostringstream m;
      m << "level " << l << " mine " << mine << " reference " << theirs << "\nx " << x.transpose() << "\nreference "
        << ref.x.transpose() << "\n";
      for (const LevelInfo& level : rig.out.levels) {
        m << "priority " << level.priority << " " << to_string(level.status) << " " << level.diagnosis << "\n";
      }
      for (std::size_t q = 0; q < p.levels.size(); ++q) {
        m << "level " << q << " mine " << level_value(p.levels[q], x) << " reference " << ref.residual[q] << " rows "
          << p.levels[q].J.rows() << " + " << p.levels[q].G.rows() << "\n";
      }
      RC_FAIL(m.str());
    }
  }
  RC_CLASSIFY(same, "the reference reaches the same optimum at every level");
  RC_CLASSIFY(!same, "SLSQP stops short at a level (redres's optimum is lower)");
  if (compared < p.levels.size()) return;
  // Where every task level agrees, the answers agree: the last level, |x|^2, is strongly convex, so for its optimum x*
  // and any point y of the same set |y - x*|^2 <= |y|^2 - |x*|^2. redres's x is the optimum when the reference's point
  // lies that close to it, to 1e-5 in x (the engines' tolerance, 1e-9 on the scaled QPs, over the rows' conditioning).
  const double mine_last = x.squaredNorm(), theirs_last = ref.x.squaredNorm();
  const bool agree = (x - ref.x).squaredNorm() <= std::max(0.0, theirs_last - mine_last) + 1e-10;
  if (same && !agree) {
    std::ostringstream m;
    m.precision(12);
    m << "x " << x.transpose() << "\nreference " << ref.x.transpose() << "\n";
    for (const LevelInfo& level : rig.out.levels) {
      m << "priority " << level.priority << " " << to_string(level.status) << " " << level.diagnosis << "\n";
    }
    for (std::size_t l = 0; l < p.levels.size(); ++l) {
      m << "level " << l << " mine " << level_value(p.levels[l], x) << " reference " << ref.residual[l] << " rows "
        << p.levels[l].J.rows() << " + " << p.levels[l].G.rows() << "\n";
    }
    m << "bounds " << p.lo.transpose() << " / " << p.hi.transpose();
    RC_FAIL(m.str());
  }
  // The last level's KKT conditions at x, with every higher level's optimum held: x minimises |x|^2 / 2 subject to
  // the held rows (every equality and soft row: E x = E x), the inequality rows at or past their bounds (held where
  // they ended), and the bounds: x + E'l + G_a'm + nu = 0.
  Eigen::MatrixXd E(0, n), G(0, n);
  for (const auto& level : p.levels) {
    if (level.J.cols() == n && &level != &p.levels.back()) {
      E.conservativeResize(E.rows() + level.J.rows(), n);
      E.bottomRows(level.J.rows()) = level.J;
    }
    for (Eigen::Index r = 0; r < level.G.rows(); ++r) {
      if (level.G.row(r).dot(x) >= level.h(r) - 1e-8) {
        G.conservativeResize(G.rows() + 1, n);
        G.bottomRows(1) = level.G.row(r);
      }
    }
  }
  std::vector<int> at_bound;
  for (int j = 0; j < n; ++j) {
    if (x(j) <= p.lo(j) + 1e-9 || x(j) >= p.hi(j) - 1e-9) at_bound.push_back(j);
  }
  const Eigen::Index m = E.rows() + G.rows() + static_cast<Eigen::Index>(at_bound.size());
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, m);
  if (E.rows() > 0) M.leftCols(E.rows()) = E.transpose();
  if (G.rows() > 0) M.middleCols(E.rows(), G.rows()) = G.transpose();
  for (std::size_t i = 0; i < at_bound.size(); ++i)
    M(at_bound[i], E.rows() + G.rows() + static_cast<Eigen::Index>(i)) = 1.0;
  // Stationarity: x lies in the span of the active constraints' normals (the multipliers' signs are not unique where
  // held rows and bounds overlap; the comparison with the reference above covers the inequalities' side).
  if (m == 0) {
    RC_ASSERT(x.norm() < 1e-6);  // nothing held, nothing active: the smallest velocity is 0
  } else {
    const Eigen::VectorXd mult = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(M).solve(-x);
    RC_ASSERT((x + M * mult).norm() < 1e-6);
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Two tasks that cannot both be met.

TEST(Tasks, TheHigherOfTwoConflictingTasksIsMetAndSwappingThePrioritiesSwapsTheOutcome) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  const Eigen::VectorXd theta = robot.home() + Eigen::VectorXd::LinSpaced(robot.dof(), 0.3, -0.3);
  // The tool's full pose (6 rows) and the elbow's position (3 rows): 9 rows on 7 joints.
  FrameTaskConfig tool;
  tool.rows = {"x", "y", "z", "wx", "wy", "wz"};
  tool.reference = "fixed";
  tool.position = {0.45, 0.1, 0.4};
  tool.rpy = {3.0, 0.2, -0.5};
  FrameTaskConfig elbow;
  elbow.frame = "panda_joint4";
  elbow.point = {0.05, 0.05, 0.05};  // off the frame's origin, which lies on joint 3's axis (rank 2 there)
  elbow.reference = "fixed";
  elbow.position = {-0.2, 0.25, 0.5};
  Eigen::VectorXd first_tool_miss(2), first_elbow_miss(2);
  for (int order = 0; order < 2; ++order) {
    std::vector<std::unique_ptr<Task>> tasks;
    tasks.push_back(frame_task(robot, "tool", tool, TaskMode::kEquality, order == 0 ? 0 : 1));
    tasks.push_back(frame_task(robot, "elbow", elbow, TaskMode::kEquality, order == 0 ? 1 : 0));
    std::vector<std::unique_ptr<Objective>> objectives;
    objectives.push_back(min_norm(robot, 2));
    Rig rig(robot, std::move(objectives), {}, std::move(tasks), 1e-12);
    const Eigen::VectorXd x = rig.step(theta);
    const TaskTerms& t = rig.terms(0);
    const TaskTerms& e = rig.terms(1);
    const double tool_miss = (t.J * x - t.d).norm(), elbow_miss = (e.J * x - e.d).norm();
    // The higher task is met; the lower one cannot be (its level is solved in least squares: `relaxed`) and is met
    // as well as the higher one allows: its residual is the least-squares one in the higher task's null space.
    const TaskTerms& high = order == 0 ? t : e;
    const TaskTerms& low = order == 0 ? e : t;
    EXPECT_LT(order == 0 ? tool_miss : elbow_miss, 1e-9) << "order " << order;
    EXPECT_EQ(rig.out.levels[1].status, SolverStatus::kRelaxed)
        << rig.out.levels[1].diagnosis << " / " << rig.out.info.diagnosis;
    std::vector<testing::ReferenceLevel> levels{{high.J, high.d, Eigen::MatrixXd(0, 7), Eigen::VectorXd(0)},
                                                {low.J, low.d, Eigen::MatrixXd(0, 7), Eigen::VectorXd(0)}};
    const Eigen::VectorXd ns = testing::null_space_cascade(levels, 7);
    EXPECT_NEAR((low.J * x - low.d).norm(), (low.J * ns - low.d).norm(), 1e-7) << "order " << order;
    EXPECT_GT((low.J * x - low.d).norm(), 1e-3) << "the tasks conflict";
    // And x is the null-space cascade's (no bound here, the velocity norm last).
    EXPECT_LT((x - ns).norm(), 1e-7) << "order " << order;
    first_tool_miss(order) = tool_miss;
    first_elbow_miss(order) = elbow_miss;
  }
  // Swapping swaps the outcome: the tool is met first and missed second, the elbow the other way round.
  EXPECT_LT(first_tool_miss(0), 1e-9);
  EXPECT_GT(first_tool_miss(1), 1e-3);
  EXPECT_GT(first_elbow_miss(0), 1e-3);
  EXPECT_LT(first_elbow_miss(1), 1e-9);
}

TEST(Tasks, ASoftTaskWithAVeryLargeWeightApproachesTheHardOne) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  const Eigen::VectorXd theta = robot.home() + Eigen::VectorXd::LinSpaced(robot.dof(), 0.1, -0.2);
  FrameTaskConfig c;
  c.reference = "fixed";
  c.position = {0.4, 0.1, 0.5};
  const auto solve = [&](TaskMode mode, double weight) {
    std::vector<std::unique_ptr<Task>> tasks;
    tasks.push_back(frame_task(robot, "tool", c, mode, 0, weight));
    std::vector<std::unique_ptr<Objective>> objectives;
    objectives.push_back(min_norm(robot, 0));
    Rig rig(robot, std::move(objectives), {}, std::move(tasks), Scheme::kDefaultRegularization, 1e-10);
    EXPECT_TRUE(rig.out.levels.empty()) << "one level: one QP";
    const Eigen::VectorXd x = rig.step(theta);
    EXPECT_EQ(rig.out.info.status, SolverStatus::kSolved) << rig.out.info.diagnosis;
    return x;
  };
  const Eigen::VectorXd hard = solve(TaskMode::kEquality, 1.0);
  double previous = 1e9;
  for (const double w : {1e1, 1e2, 1e3, 1e4}) {
    const double gap = (solve(TaskMode::kSoft, w) - hard).norm();
    EXPECT_LT(gap, previous) << "weight " << w;
    EXPECT_LT(gap, 10.0 / w) << "weight " << w;  // the least squares' bias is O(1/w)
    previous = gap;
  }
}

TEST(Tasks, DampingBoundsTheVelocityNearASingularityAndVanishesAwayFromIt) {
  const RobotModel robot = load_robot(source_path("robots/planar_4link.toml"));
  const auto solve = [&](const Eigen::VectorXd& theta, double damping, const Eigen::Vector2d& target) {
    FrameTaskConfig c;
    c.reference = "fixed";
    c.position = {target.x(), target.y(), 0.0};
    c.damping = damping;
    c.damping_threshold = 0.05;
    std::vector<std::unique_ptr<Task>> tasks;
    tasks.push_back(frame_task(robot, "tool", c, TaskMode::kSoft, 0));
    std::vector<std::unique_ptr<Objective>> objectives;
    objectives.push_back(min_norm(robot, 0));
    objectives.back()->set_weight(1e-8);
    Rig rig(robot, std::move(objectives), {}, std::move(tasks), Scheme::kDefaultRegularization, 1e-10);
    const Eigen::VectorXd x = rig.step(theta);
    EXPECT_EQ(rig.out.info.status, SolverStatus::kSolved) << rig.out.info.diagnosis;
    return std::make_pair(x, rig.terms(0));
  };
  // Nearly stretched: the rows lose rank along the arm. The target lies 5 cm along the weak direction.
  Eigen::VectorXd theta(4);
  theta << 0.3, 0.004, 0.002, 0.001;
  KinematicsData k(robot);
  compute_kinematics(robot, theta, k, KinematicsLevel::kJacobian);
  const Eigen::MatrixXd J = k.J.topRows(2);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeFullU);
  ASSERT_LT(svd.singularValues()(1), 0.01);
  const Eigen::Vector2d weak = svd.matrixU().col(1);
  const Eigen::Vector2d target = k.f.head(2) + 0.05 * weak;
  const auto [plain, plain_terms] = solve(theta, 0.0, target);
  const auto [damped, damped_terms] = solve(theta, 0.1, target);
  EXPECT_EQ(plain_terms.damping, 0.0);
  EXPECT_GT(damped_terms.damping, 0.9 * 0.01);  // lambda^2 near its largest, 0.1^2
  EXPECT_NEAR(damped_terms.sigma_min, svd.singularValues()(1), 1e-9);
  // Undamped, the joints race to make up the lost rank; damped, |x| <= |d| / (2 lambda) (damped least squares).
  EXPECT_GT(plain.norm(), 10.0 * damped.norm());
  EXPECT_LE(damped.norm(), damped_terms.d.norm() / (2.0 * std::sqrt(damped_terms.damping)) * 1.001);
  // Away from the singularity the damping is 0 and the answer is the undamped one, bit for bit.
  Eigen::VectorXd bent(4);
  bent << 0.3, 0.8, -0.6, 0.4;
  const Eigen::Vector2d near = target;
  const auto [a, a_terms] = solve(bent, 0.0, near);
  const auto [b, b_terms] = solve(bent, 0.1, near);
  EXPECT_EQ(b_terms.damping, 0.0);
  EXPECT_EQ((a - b).norm(), 0.0);
}

// ---------------------------------------------------------------------------------------------------------------
// One level; a failed lower level.

TEST(Tasks, OneLevelIsOneQpWithTheTasksRowsAfterTheConstraints) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  FrameTaskConfig c;
  c.reference = "fixed";
  c.position = {0.4, 0.1, 0.5};
  std::vector<std::unique_ptr<Task>> tasks;
  tasks.push_back(frame_task(robot, "tool", c, TaskMode::kEquality, 0));
  FrameTaskConfig e;
  e.frame = "panda_joint4";
  e.rows = {"z"};
  e.lower = std::vector<double>{0.7};
  tasks.push_back(frame_task(robot, "elbow", e, TaskMode::kInequality, 0));
  std::vector<std::unique_ptr<Objective>> objectives;
  objectives.push_back(min_norm(robot, 0));
  Rig rig(robot, std::move(objectives), {}, std::move(tasks));
  ASSERT_FALSE(rig.scheme->cascaded());
  EXPECT_EQ(rig.ctrl->qp().m_eq(), 3);
  EXPECT_EQ(rig.ctrl->qp().m_in(), 1);
  const Eigen::VectorXd x = rig.step(robot.home());
  ASSERT_EQ(rig.out.info.status, SolverStatus::kSolved) << rig.out.info.diagnosis;
  EXPECT_LT((rig.terms(0).J * x - rig.terms(0).d).norm(), 1e-9);
  // The elbow (0.615 m at home) is below 0.7 m: its row asks it up, at gain 1: J_z x >= 0.7 - z.
  EXPECT_GE(rig.terms(1).J.row(0).dot(x), rig.terms(1).lo(0) - 1e-9);
  EXPECT_NEAR(rig.terms(1).error(0), 0.7 - 0.614782052, 1e-8);
}

// The controller runs a one-level scheme as a list of one level (control/cascade.hpp); the QP it solves is the one
// Scheme::build() writes, entry for entry, with tasks in all three modes (the one writer of task rows) beside
// constraints and an objective.
TEST(Tasks, TheControllersOneLevelIsTheSchemesOneQpEntryForEntry) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  std::vector<std::unique_ptr<Task>> tasks;
  FrameTaskConfig tool;
  tool.reference = "fixed";
  tool.position = {0.4, 0.1, 0.5};
  tasks.push_back(frame_task(robot, "tool", tool, TaskMode::kEquality, 0));
  FrameTaskConfig elbow;
  elbow.frame = "panda_joint4";
  elbow.rows = {"z"};
  elbow.lower = std::vector<double>{0.7};
  elbow.upper = std::vector<double>{0.9};
  tasks.push_back(frame_task(robot, "elbow", elbow, TaskMode::kInequality, 0));
  FrameTaskConfig wrist;
  wrist.frame = "panda_joint6";
  wrist.rows = {"x", "y"};
  wrist.damping = 0.3;
  wrist.damping_threshold = 10.0;  // damped at every state
  tasks.push_back(frame_task(robot, "wrist", wrist, TaskMode::kSoft, 0, 0.5));
  std::vector<std::unique_ptr<Objective>> objectives;
  objectives.push_back(min_norm(robot, 0));
  std::vector<std::unique_ptr<Constraint>> constraints;
  constraints.push_back(std::make_unique<JointVelocityLimits>(JointVelocityLimits::Config{}, robot));
  Rig rig(robot, std::move(objectives), std::move(constraints), std::move(tasks));
  ASSERT_FALSE(rig.scheme->cascaded());
  Eigen::VectorXd theta = robot.home();
  theta(1) += 0.2;
  theta(3) -= 0.1;
  (void)rig.step(theta);
  ASSERT_EQ(rig.out.info.status, SolverStatus::kSolved) << rig.out.info.diagnosis;
  EXPECT_GT(rig.terms(2).damping, 0.0);

  // The same scheme's one QP, built directly at the same state.
  SchemeData data = rig.scheme->make_data();
  rig.scheme->start(data);
  QpProblem qp;
  rig.scheme->setup(qp, data);
  KinematicsData kin(robot);
  compute_kinematics(robot, theta, kin, rig.scheme->kinematics_level());
  const Eigen::VectorXd r = Eigen::VectorXd::Zero(robot.reference_dim());
  Context ctx;
  ctx.robot = &robot;
  ctx.kinematics = &kin;
  ctx.T = 10.0;
  ctx.tau = 0.01;
  ctx.r_d = &r;
  ctx.r_d_dot = &r;
  rig.scheme->build(ctx, qp, data);

  const QpProblem& solved = rig.ctrl->qp();
  ASSERT_EQ(solved.n(), qp.n());
  ASSERT_EQ(solved.m_eq(), qp.m_eq());
  ASSERT_EQ(solved.m_in(), qp.m_in());
  EXPECT_EQ(solved.W, qp.W);
  EXPECT_EQ(solved.zeta, qp.zeta);
  EXPECT_EQ(solved.J, qp.J);
  EXPECT_EQ(solved.d, qp.d);
  EXPECT_EQ(solved.A, qp.A);
  EXPECT_EQ(solved.b, qp.b);
  EXPECT_EQ(solved.lo, qp.lo);
  EXPECT_EQ(solved.hi, qp.hi);
  EXPECT_EQ(solved.w_diagonal, qp.w_diagonal);
  EXPECT_EQ(solved.eq_source, qp.eq_source);
  EXPECT_EQ(solved.in_source, qp.in_source);
  EXPECT_EQ(solved.lo_source, qp.lo_source);
  EXPECT_EQ(solved.source_names, qp.source_names);
  EXPECT_FALSE(qp.w_diagonal);  // the soft task's least squares filled W off its diagonal
  EXPECT_EQ(qp.m_eq(), 3);      // the tool's rows
  EXPECT_EQ(qp.m_in(), 2);      // the elbow's two bounds
}

TEST(Tasks, APostureThatCannotBeMetIsMetAsWellAsTheLimitsAllowAndTheStepDoesNotFail) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  FrameTaskConfig c;
  c.reference = "fixed";
  c.position = {0.4, 0.1, 0.5};
  std::vector<std::unique_ptr<Task>> tasks;
  tasks.push_back(frame_task(robot, "tool", c, TaskMode::kEquality, 0));
  // Level 1: a posture the velocity limits cannot reach in one step, as an equality: its least-squares retry meets
  // it as well as the limits allow (status `relaxed`).
  PostureConfig posture;
  posture.target = PerJoint{2.5, 1.5, -2.5, -0.2, 2.5, 3.5, -2.5};
  posture.gain = 10.0;
  auto p = std::make_unique<Posture>(posture, robot);
  p->set_name("posture");
  p->set_priority(1);
  tasks.push_back(std::move(p));
  std::vector<std::unique_ptr<Objective>> objectives;
  objectives.push_back(min_norm(robot, 2));
  std::vector<std::unique_ptr<Constraint>> constraints;
  constraints.push_back(std::make_unique<JointVelocityLimits>(JointVelocityLimits::Config{}, robot));
  Rig rig(robot, std::move(objectives), std::move(constraints), std::move(tasks));
  const Eigen::VectorXd x = rig.step(robot.home());
  ASSERT_EQ(rig.out.info.status, SolverStatus::kSolved) << rig.out.info.diagnosis;
  ASSERT_EQ(rig.out.levels.size(), 3U);
  EXPECT_EQ(rig.out.levels[0].status, SolverStatus::kSolved);
  EXPECT_EQ(rig.out.levels[1].status, SolverStatus::kRelaxed) << rig.out.levels[1].diagnosis;
  EXPECT_NE(rig.out.levels[1].diagnosis.find("least squares"), std::string::npos) << rig.out.levels[1].diagnosis;
  EXPECT_LT((rig.terms(0).J * x - rig.terms(0).d).norm(), 1e-9);  // the tool is still met
  // The velocity limits hold.
  EXPECT_TRUE((x.array() <= rig.ctrl->qp().hi.array() + 1e-9).all());
  EXPECT_TRUE((x.array() >= rig.ctrl->qp().lo.array() - 1e-9).all());
  // The posture's 7 rows, held, decide every joint: the level below is skipped, and says why.
  EXPECT_EQ(rig.out.levels[2].status, SolverStatus::kNotRun) << rig.out.levels[2].diagnosis;
  EXPECT_NE(rig.out.levels[2].diagnosis.find("nothing left to decide"), std::string::npos)
      << rig.out.levels[2].diagnosis;
}

}  // namespace
}  // namespace redres

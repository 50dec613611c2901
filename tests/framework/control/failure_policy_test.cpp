// Failed steps: the status and the diagnosis come from one decision (the exact fit of the rows inside the bounds,
// certified here by its KKT conditions and by NLopt's L-BFGS-B), a singular configuration says so, and the
// [solver] on_infeasible policies: hold never integrates a failed step, stop ends there, relax yields inside every
// limit and reports how far the rows are missed.

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <regex>
#include <string>

#include <gtest/gtest.h>
#include <nlopt.h>
#include <rapidcheck/gtest.h>

#include "cli_util.hpp"
#include "qp_util.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/qp/lvi.hpp"
#include "redres/run/run_summary.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"
#include "scenario_text.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

// |J x - d|^2 + |(A x - b)+|^2.
double fit_value(const QpProblem& qp, const Eigen::VectorXd& x) {
  return (qp.J * x - qp.d).squaredNorm() + (qp.m_in() > 0 ? (qp.A * x - qp.b).cwiseMax(0.0).squaredNorm() : 0.0);
}

// The same minimised by NLopt's L-BFGS-B (bounds as NLopt takes them), an independent solver.
double lbfgs_fit_value(const QpProblem& qp) {
  const int n = qp.n();
  nlopt_opt opt = nlopt_create(NLOPT_LD_LBFGS, static_cast<unsigned>(n));
  std::vector<double> lo(qp.lo.data(), qp.lo.data() + n), hi(qp.hi.data(), qp.hi.data() + n);
  nlopt_set_lower_bounds(opt, lo.data());
  nlopt_set_upper_bounds(opt, hi.data());
  nlopt_set_min_objective(
      opt,
      [](unsigned m, const double* x, double* grad, void* data) {
        const QpProblem& q = *static_cast<const QpProblem*>(data);
        const Eigen::Map<const Eigen::VectorXd> xv(x, m);
        const Eigen::VectorXd re = q.J * xv - q.d;
        const Eigen::VectorXd ri = q.m_in() > 0 ? Eigen::VectorXd((q.A * xv - q.b).cwiseMax(0.0)) : Eigen::VectorXd();
        if (grad != nullptr) {
          Eigen::Map<Eigen::VectorXd> g(grad, m);
          g = 2.0 * q.J.transpose() * re;
          if (q.m_in() > 0) g += 2.0 * q.A.transpose() * ri;
        }
        return re.squaredNorm() + ri.squaredNorm();
      },
      const_cast<QpProblem*>(&qp));
  nlopt_set_ftol_abs(opt, 1e-30);
  nlopt_set_xtol_rel(opt, 1e-15);
  nlopt_set_maxeval(opt, 20000);
  std::vector<double> x(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = std::clamp(0.0, qp.lo(i), qp.hi(i));
  double f = 0.0;
  nlopt_optimize(opt, x.data(), &f);
  nlopt_destroy(opt);
  return fit_value(qp, Eigen::Map<const Eigen::VectorXd>(x.data(), n));
}

// A QP whose rows are often hard: rank-deficient (a zero row, a repeated row), nearly singular, or asking more
// than the bounds allow.
QpProblem hard_qp(std::mt19937& rng, int n, int m_e, int m_i, int kind) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  QpProblem qp;
  qp.resize(n, m_e, m_i);
  for (int i = 0; i < n; ++i) {
    qp.W(i, i) = 0.5 + 0.75 * (u(rng) + 1.0);
    qp.zeta(i) = u(rng);
    const double centre = 0.3 * u(rng), half = 0.05 + std::abs(u(rng));
    qp.lo(i) = centre - half;
    qp.hi(i) = centre + half;
    if (i % 4 == 3) qp.hi(i) = kNoBound;
  }
  for (int r = 0; r < m_e; ++r) {
    for (int i = 0; i < n; ++i) qp.J(r, i) = u(rng);
    qp.d(r) = u(rng) * (kind == 3 ? 10.0 : 0.5);
  }
  if (kind == 0 && m_e > 0) qp.J.row(0).setZero();
  if (kind == 1 && m_e > 1) qp.J.row(1) = qp.J.row(0);
  if (kind == 2 && m_e > 1) qp.J.row(1) = qp.J.row(0) + 1e-7 * qp.J.row(1);
  for (int r = 0; r < m_i; ++r) {
    for (int i = 0; i < n; ++i) qp.A(r, i) = u(rng);
    qp.b(r) = 0.2 * u(rng);
  }
  for (auto* v : {&qp.lo_source, &qp.hi_source}) std::fill(v->begin(), v->end(), 0);
  std::fill(qp.eq_source.begin(), qp.eq_source.end(), 0);
  std::fill(qp.in_source.begin(), qp.in_source.end(), 0);
  qp.source_names = {"test"};
  return qp;
}

// Every "residual X > tolerance Y" in a text has X > Y.
void expect_comparisons_hold(const std::string& text) {
  static const std::regex claim(R"(residual ([0-9.eE+-]+) > tolerance ([0-9.eE+-]+))");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), claim); it != std::sregex_iterator(); ++it) {
    EXPECT_GT(std::stod((*it)[1]), std::stod((*it)[2])) << text;
  }
}

RC_GTEST_PROP(RowFit, EqualityRowsFitMeetsItsKktConditionsAndBeatsLbfgs, ()) {
  const int n = *rc::gen::inRange(1, 12);
  const int m_e = *rc::gen::inRange(1, 5);
  const int kind = *rc::gen::inRange(0, 5);
  std::mt19937 rng(*rc::gen::arbitrary<std::uint32_t>());
  const QpProblem qp = hard_qp(rng, n, m_e, 0, kind);
  const RowFit fit = best_row_fit(qp);
  // Inside the box, and a KKT point of the convex problem min |J x - d|^2 over the box (hence its minimum).
  RC_ASSERT(((fit.x - qp.lo).array() >= 0.0).all() && ((qp.hi - fit.x).array() >= 0.0).all());
  const Eigen::VectorXd g = qp.J.transpose() * (qp.J * fit.x - qp.d);
  const double scale = 1.0 + qp.J.cwiseAbs().maxCoeff() * (qp.d.cwiseAbs().maxCoeff() + 1.0);
  for (int i = 0; i < n; ++i) {
    const bool at_lo = fit.x(i) <= qp.lo(i), at_hi = fit.x(i) >= qp.hi(i);
    if (!at_lo && !at_hi) RC_ASSERT(std::abs(g(i)) <= 1e-9 * scale);
    if (at_lo) RC_ASSERT(g(i) >= -1e-9 * scale);
    if (at_hi) RC_ASSERT(g(i) <= 1e-9 * scale);
  }
  RC_ASSERT(fit_value(qp, fit.x) <= lbfgs_fit_value(qp) + 1e-12);
  RC_ASSERT(std::abs(fit.equality_miss - (qp.J * fit.x - qp.d).cwiseAbs().maxCoeff()) <= 1e-15);
}

RC_GTEST_PROP(RowFit, WithInequalityRowsIsNoWorseThanLbfgs, ()) {
  const int n = *rc::gen::inRange(2, 10);
  const int m_e = *rc::gen::inRange(0, 3);
  const int m_i = *rc::gen::inRange(1, 5);
  std::mt19937 rng(*rc::gen::arbitrary<std::uint32_t>());
  const QpProblem qp = hard_qp(rng, n, m_e, m_i, *rc::gen::inRange(0, 5));
  const RowFit fit = best_row_fit(qp);
  RC_ASSERT(((fit.x - qp.lo).array() >= 0.0).all() && ((qp.hi - fit.x).array() >= 0.0).all());
  const double ours = fit_value(qp, fit.x), theirs = lbfgs_fit_value(qp);
  RC_ASSERT(ours <= theirs * (1.0 + 1e-6) + 1e-12);
}

// The engines' verdicts: `infeasible` only when the certified fit misses the rows; a failure on a QP whose rows can
// be met is never called infeasible; no text claims a residual above its tolerance that is not; and rank-deficient
// rows are named as a singular configuration.
RC_GTEST_PROP(FailureDiagnosis, StatusAndTextComeFromOneDecision, ()) {
  const int n = *rc::gen::inRange(2, 9);
  const int m_e = *rc::gen::inRange(1, std::min(4, n));
  const int m_i = *rc::gen::inRange(0, 3);
  const int kind = *rc::gen::inRange(0, 5);
  std::mt19937 rng(*rc::gen::arbitrary<std::uint32_t>());
  const QpProblem qp = hard_qp(rng, n, m_e, m_i, kind);
  const RowFit fit = best_row_fit(qp);
  const double tolerance = 1e-6;
  const bool unmeetable = std::max(fit.equality_miss, fit.inequality_excess) > 10.0 * tolerance;
  for (const char* engine : {"projection", "newton", "nlopt"}) {
    SolverSettings settings;
    settings.max_iterations = std::string(engine) == "projection" ? 3000 : 500;
    const auto e = make_engine(engine, settings);
    SolverResult r;
    e->setup(n, m_e, m_i, r);
    e->solve(qp, r);
    const std::string& text = r.info.diagnosis;
    expect_comparisons_hold(text);
    if (r.info.status == SolverStatus::kSolved) {
      RC_ASSERT(!unmeetable);
      continue;
    }
    RC_ASSERT((r.info.status == SolverStatus::kInfeasible) == unmeetable);
    RC_ASSERT(!text.empty());
    if (unmeetable) RC_ASSERT(text.find("cannot be met") != std::string::npos);
    if (!unmeetable) RC_ASSERT(text.find("can be met") != std::string::npos);
    if ((kind == 0 || kind == 1) && m_e > 1) RC_ASSERT(text.find("rank") != std::string::npos);
  }
}

RC_GTEST_PROP(FailureDiagnosis, FeasibleQpsAreNeverCalledInfeasible, ()) {
  const int n = *rc::gen::inRange(2, 10);
  const int m_e = *rc::gen::inRange(0, std::min(4, n));
  const int m_i = *rc::gen::inRange(0, 3);
  std::mt19937 rng(*rc::gen::arbitrary<std::uint32_t>());
  const testing::RandomQp rq = testing::random_qp(rng, n, m_e, m_i);
  for (const char* engine : {"projection", "newton", "nlopt"}) {
    SolverSettings settings;
    settings.max_iterations = 50;  // the projection engine often stops short: a failure, but not "infeasible"
    const auto e = make_engine(engine, settings);
    SolverResult r;
    e->setup(n, m_e, m_i, r);
    e->solve(rq.qp, r);
    RC_ASSERT(r.info.status != SolverStatus::kInfeasible);
    expect_comparisons_hold(r.info.diagnosis);
  }
}

// Scenario files for the runs below, in a scratch directory; the robot is the repository's planar 4R arm.
std::filesystem::path write_scenario(const std::string& test, const std::string& body) {
  const auto file = scratch_dir(test) / "scenario.toml";
  std::ofstream(file) << "name = \"" << test << "\"\n" << robot_line("planar_4link.toml") << body;
  return file;
}

// The issue's reproducer: the 4R arm starting fully stretched. Step 1 sits at the singularity.
const std::string kStretched =
    "duration = 2.0\nstep = 0.01\ntheta0 = [0, 0, 0, 0]\n" + circle_tracking("0.06", "engine = \"newton\"\n");

TEST(FailureDiagnosis, AStretchedArmIsASingularConfigurationNotAnInfeasibleStep) {
  const auto file = write_scenario("stretched", kStretched);
  for (const char* engine : {"newton", "nlopt", "projection"}) {
    Scenario s =
        load_scenario(file, {"solver.engine=\"" + std::string(engine) + "\"", "solver.on_infeasible=\"hold\""});
    const RunResult run = simulate(s);
    ASSERT_GT(run.failures, 0) << engine;
    const std::string& first = run.first_failure;
    EXPECT_EQ(first.find("infeasible"), std::string::npos) << engine << ": " << first;
    EXPECT_NE(first.find("the rows can be met inside the bounds"), std::string::npos) << engine << ": " << first;
    EXPECT_NE(first.find("singular"), std::string::npos) << engine << ": " << first;
    expect_comparisons_hold(first);
  }
}

// Whether row k of the run moved theta to row k + 1.
double theta_step(const Trajectory& tr, std::size_t k, int n) {
  double d = 0.0;
  for (int j = 1; j <= n; ++j) {
    const std::string J = std::to_string(j);
    d = std::max(d, std::abs(tr.at(k + 1, "theta_" + J) - tr.at(k, "theta_" + J)));
  }
  return d;
}

TEST(OnInfeasible, HoldNeverIntegratesAFailedStep) {
  // The projection engine capped at 40 iterations fails often on this circle; the runs go on to T.
  const auto file = write_scenario("hold", kStretched + "max_iterations = 40\n");
  for (const char* policy : {"hold", "continue"}) {
    Scenario s = load_scenario(file, {"theta0=[0.3, 0.6, 0.6, 0.4]", "solver.engine=\"projection\"",
                                      "solver.on_infeasible=\"" + std::string(policy) + "\""});
    EXPECT_EQ(s.on_infeasible, FailurePolicy::kHold);
    const RunResult run = simulate(s);
    const Trajectory& tr = run.trajectory;
    ASSERT_EQ(tr.size(), 201u);
    int failed = 0, held = 0;
    for (std::size_t k = 0; k + 1 < tr.size(); ++k) {
      if (tr.at(k, "solver_status") == 0.0) continue;
      ++failed;
      for (int j = 1; j <= 4; ++j) EXPECT_EQ(tr.at(k, "theta_dot_" + std::to_string(j)), 0.0) << "row " << k;
      EXPECT_EQ(theta_step(tr, k, 4), 0.0) << "row " << k;
      ++held;
    }
    EXPECT_GT(failed, 10);
    EXPECT_EQ(run.held_steps, held);
    EXPECT_EQ(run.failures, failed + (tr.at(200, "solver_status") != 0.0 ? 1 : 0));
    const RunSummary sum = summarise(s, run);
    EXPECT_EQ(sum.solver.on_infeasible, "hold");
    EXPECT_EQ(sum.status, "complete");
  }
}

TEST(OnInfeasible, AManyJointArmWithFailedStepsStaysNearItsCircle) {
  // 1000 joints of 1 mm: the projection engine capped at 30 iterations fails steps; before, each failed step
  // integrated its unconverged iterate and the arm ended metres away from a 5 cm circle.
  const auto dir = scratch_dir("many_joints");
  std::ofstream robot(dir / "robot.toml");
  robot << "name = \"chain1000\"\nkind = \"planar\"\ntask = \"position\"\n";
  for (int j = 0; j < 1000; ++j) {
    robot << "[[joints]]\nname = \"j" << j << "\"\nlength = 0.001\nlimits = [-3.0, 3.0]\n"
          << "velocity_limit = { type = \"constant\", lower = -1.0, upper = 1.0 }\n";
  }
  robot.close();
  std::ofstream(dir / "scenario.toml") << "name = \"many\"\nrobot = \"robot.toml\"\nduration = 0.2\nstep = 0.01\n"
                                       << "theta0 = [" <<
      [] {
        std::string s = "0.5";
        for (int j = 1; j < 1000; ++j) s += ", 0.002";
        return s;
      }() << "]\n" << circle_tracking("0.05", "engine = \"projection\"\nmax_iterations = 30\n");
  Scenario s = load_scenario(dir / "scenario.toml");
  const RunResult run = simulate(s);
  EXPECT_GT(run.failures, 5);
  const RunSummary sum = summarise(s, run);
  EXPECT_LT(sum.max_position_error, 0.11) << run.failures << " failures: " << run.first_failure;
}

TEST(OnInfeasible, StopEndsTheRunAtTheFirstFailedStep) {
  const auto file = write_scenario("stop", kStretched);
  Scenario s = load_scenario(file, {"solver.on_infeasible=\"stop\""});
  const RunResult run = simulate(s);
  EXPECT_TRUE(run.stopped);
  EXPECT_EQ(run.failures, 1);
  const Trajectory& tr = run.trajectory;
  EXPECT_NE(tr.at(tr.size() - 1, "solver_status"), 0.0);
  for (std::size_t k = 0; k + 1 < tr.size(); ++k) EXPECT_EQ(tr.at(k, "solver_status"), 0.0);
  EXPECT_EQ(summarise(s, run).status, "stopped");
}

// Each row's theta_dot lies inside that row's merged bounds.
void expect_inside_bounds(const Trajectory& tr, int n) {
  for (std::size_t k = 0; k < tr.size(); ++k) {
    for (int j = 1; j <= n; ++j) {
      const std::string J = std::to_string(j);
      EXPECT_GE(tr.at(k, "theta_dot_" + J), tr.at(k, "lo_" + J) - 1e-9) << "row " << k << " joint " << j;
      EXPECT_LE(tr.at(k, "theta_dot_" + J), tr.at(k, "hi_" + J) + 1e-9) << "row " << k << " joint " << j;
    }
  }
}

TEST(OnInfeasible, RelaxGetsPastASingularStartInsideEveryLimit) {
  const auto file = write_scenario("relax_singular", kStretched);
  Scenario s = load_scenario(file, {"solver.on_infeasible=\"relax\""});
  const RunResult run = simulate(s);
  EXPECT_EQ(run.failures, 0) << run.first_failure;
  EXPECT_GE(run.relaxed_steps, 1);
  EXPECT_NE(run.first_relaxed.find("rows relaxed"), std::string::npos) << run.first_relaxed;
  expect_inside_bounds(run.trajectory, 4);
  const RunSummary sum = summarise(s, run);
  EXPECT_EQ(sum.solver.relaxed_steps, run.relaxed_steps);
  EXPECT_LT(sum.max_position_error, 5e-3);  // past the singularity the task is tracked again
  // The same start held: the arm never leaves the singularity and ends far from the circle.
  Scenario held = load_scenario(file, {"solver.on_infeasible=\"hold\""});
  const RunSummary hs = summarise(held, simulate(held));
  EXPECT_GT(hs.max_position_error, 0.05);
}

TEST(OnInfeasible, AControllerFromTheScenarioRunsWhatSimulateRuns) {
  // Controller::from_scenario, driven by simulate()'s Euler loop, gives its theta bit for bit, relaxed steps
  // included (a closed loop that missed set_relaxation would hold at the singular start instead).
  const auto file = write_scenario("from_scenario", kStretched);
  Scenario s = load_scenario(file, {"solver.on_infeasible=\"relax\""});
  const RunResult run = simulate(s);
  ASSERT_GE(run.relaxed_steps, 1);
  Scenario again = load_scenario(file, {"solver.on_infeasible=\"relax\""});
  const std::unique_ptr<Controller> ctrl = Controller::from_scenario(again);
  StepOutput out = ctrl->make_output();
  Eigen::VectorXd theta = again.theta0;
  const Trajectory& tr = run.trajectory;
  int relaxed = 0;
  for (int k = 0; k <= again.steps(); ++k) {
    for (int j = 1; j <= 4; ++j) {
      ASSERT_EQ(theta(j - 1), tr.at(static_cast<std::size_t>(k), "theta_" + std::to_string(j))) << "row " << k;
    }
    ctrl->step(theta, k == again.steps() ? again.duration : k * again.tau, out);
    ASSERT_EQ(static_cast<double>(static_cast<int>(out.info.status)),
              tr.at(static_cast<std::size_t>(k), "solver_status"))
        << "row " << k;
    relaxed += out.info.status == SolverStatus::kRelaxed ? 1 : 0;
    if (out.info.status == SolverStatus::kSolved || out.info.status == SolverStatus::kRelaxed) {
      theta += again.tau * out.theta_dot;
    }
  }
  EXPECT_EQ(relaxed, run.relaxed_steps);
}

TEST(OnInfeasible, RelaxOnATooFastCircleYieldsInsideTheLimitsAndReportsTheMiss) {
  // 6 cm in 0.2 s is beyond what the velocity limits allow: every step fails under hold; under relax each step
  // moves as far along as the limits allow, and the rows' miss is reported.
  const std::string body = kStretched + "on_infeasible = \"relax\"\n";
  const auto file = write_scenario("relax_fast", body);
  Scenario s = load_scenario(file, {"theta0=[0.3, 0.6, 0.6, 0.4]", "duration=0.2", "path.radius=0.06"});
  const RunResult run = simulate(s);
  EXPECT_EQ(run.failures, 0) << run.first_failure;
  EXPECT_GT(run.relaxed_steps, 3);
  EXPECT_GT(run.max_relaxed_task_error, 0.1);  // m/s of the task velocity left out
  expect_inside_bounds(run.trajectory, 4);
  // Relaxed steps move the arm: theta changes on them.
  const Trajectory& tr = run.trajectory;
  bool moved = false;
  for (std::size_t k = 0; k + 1 < tr.size(); ++k) {
    if (tr.at(k, "solver_status") == static_cast<double>(SolverStatus::kRelaxed)) moved |= theta_step(tr, k, 4) > 0;
  }
  EXPECT_TRUE(moved);
}

TEST(OnInfeasible, PolicyKeysAreChecked) {
  const auto file = write_scenario("policy_keys", kStretched);
  const auto message = [&](const std::vector<std::string>& set) {
    try {
      (void)load_scenario(file, set);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message({"solver.on_infeasible=\"abort\""})
                .find("key 'on_infeasible': expected one of 'hold', 'stop', 'relax', 'continue', 'brake', got 'abort'"),
            std::string::npos);
  EXPECT_NE(message({"solver.on_infeasible=\"relax\"", "solver.relax_weight=0.5"})
                .find("key 'relax_weight': expected a weight in [1, 1e8], got 0.5"),
            std::string::npos);
  EXPECT_NE(message({"solver.on_infeasible=\"hold\"", "solver.relax_weight=100"})
                .find("is used only with on_infeasible = \"relax\""),
            std::string::npos);
  EXPECT_EQ(load_scenario(file, {"solver.relax_weight=100"}).relax_weight, 100.0);  // the default policy relaxes
  Scenario s = load_scenario(file, {"solver.on_infeasible=\"relax\"", "solver.relax_weight=100"});
  EXPECT_EQ(s.relax_weight, 100.0);
}

// Runs the CLI with stdout and stderr into separate files; returns the exit code.
int run_cli(const std::string& args, const std::filesystem::path& out, const std::filesystem::path& err) {
  const std::string cmd =
      "'" + std::string(REDRES_CLI) + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(OnInfeasibleCli, TheDiagnosisGoesToStderrWithQuietAndTheExitCodeFollowsThePolicy) {
  const auto file = write_scenario("policy_cli", kStretched);
  const auto dir = file.parent_path();
  const std::string base = "run '" + file.string() + "' --out '" + (dir / "out").string() + "' --quiet";
  for (const char* policy : {"hold", "stop"}) {
    // The stretched start is singular for the task: refused before the run (exit 2), with a way out.
    int code = run_cli(base + " --set solver.on_infeasible=" + policy, dir / "stdout", dir / "stderr");
    std::string err = read_text(dir / "stderr");
    EXPECT_EQ(code, 2) << policy << ": " << err;
    EXPECT_NE(err.find("is singular for the task"), std::string::npos) << err;
    EXPECT_NE(err.find("relax"), std::string::npos) << err;
    // Bent, it is not singular (the check passes), but a circle in 0.1 s is beyond its velocity limits: exit 1.
    code = run_cli(
        base + " --set solver.on_infeasible=" + policy + " --set 'theta0=[0, 0.5, 0.5, 0.5]' --set duration=0.1",
        dir / "stdout", dir / "stderr");
    err = read_text(dir / "stderr");
    EXPECT_EQ(code, 1) << policy << ": " << err;
    EXPECT_EQ(read_text(dir / "stdout"), "") << policy;
    EXPECT_NE(err.find("failed step"), std::string::npos) << err;
    EXPECT_NE(err.find("first failure: t = 0.02 s: infeasible"), std::string::npos) << err;
    EXPECT_NE(err.find("on_infeasible = \"" + std::string(policy) + "\""), std::string::npos) << err;
  }
  const int code = run_cli(base + " --set solver.on_infeasible=relax", dir / "stdout", dir / "stderr");
  EXPECT_EQ(code, 0) << read_text(dir / "stderr");
  EXPECT_EQ(read_text(dir / "stderr"), "");
  EXPECT_EQ(read_text(dir / "stdout"), "");
}

// Under relax, a robot without acceleration limits holds where the elastic QP fails too: it cannot brake (nothing
// bounds the deceleration), and a zero command is not reported as a braked step.
TEST(OnInfeasible, RelaxHoldsWhereTheElasticQpFailsOnARobotWithoutAccelerationLimits) {
  Scenario s = load_scenario(source_path("configs/paper_r_tvcmm.toml"),
                             {"duration=0.2", "solver.engine=\"projection\"", "solver.max_iterations=1",
                              "solver.tolerance=1e-14", "solver.on_infeasible=\"relax\""});
  ASSERT_FALSE(s.robot->has_acceleration_limits());
  const RunResult run = simulate(s);
  EXPECT_GT(run.failures, 0);
  EXPECT_EQ(run.braked_steps, 0);
  EXPECT_EQ(run.held_steps, run.failures - 1);  // every failed step but the last row's (not integrated) held
  const std::size_t c = run.trajectory.column("solver_status");
  for (std::size_t r = 0; r < run.trajectory.size(); ++r) {
    EXPECT_NE(run.trajectory(r, c), static_cast<double>(static_cast<int>(SolverStatus::kBraked))) << "row " << r;
  }
}

}  // namespace
}  // namespace redres

// Hostile input files: inputs that crashed the reader, grew without bound or blocked it are one file:line:col
// error and exit 2, from the command line and from the library; valid TOML with many dots and deep (but bounded)
// nesting still loads.

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "cli_util.hpp"
#include "common/input_file.hpp"
#include "redres/common/error.hpp"
#include "redres/config/toml_reader.hpp"
#include "redres/model/velocity_limit.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"
#include "scenario_text.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

std::string repeat(const std::string& s, int n, const std::string& sep) {
  std::string out;
  for (int i = 0; i < n; ++i) out += (i ? sep : "") + s;
  return out;
}

void write(const std::filesystem::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

// The first line of the CLI's output.
std::string first_line(const std::string& out) { return out.substr(0, out.find('\n')); }

const std::string kHead = "name = \"r\"\nkind = \"planar\"\n";

TEST(HostileInput, KeysAndNestingTooDeepForTheParserAreErrorsNotCrashes) {
  const auto dir = scratch_dir("hostile_deep");
  struct Case {
    const char* file;
    std::string text;
    const char* expect;
  };
  const Case cases[] = {
      {"dotted.toml", kHead + repeat("a", 40000, ".") + " = 1\n", "dotted.toml:3:"},
      {"header.toml", kHead + "[" + repeat("a", 40000, ".") + "]\n", "header.toml:3:"},
      {"quoted.toml", kHead + repeat("\"a\"", 20000, " . ") + " = 1\n", "quoted.toml:3:"},
      {"inline.toml", kHead + "x = " + repeat("{a = ", 20000, "") + "1" + repeat("}", 20000, "") + "\n",
       "inline.toml:3:"},
      {"arrays.toml", kHead + "x = " + repeat("[", 20000, "") + repeat("]", 20000, "") + "\n", "arrays.toml:3:"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    write(dir / c.file, c.text);
    const Cli r = redres("robot '" + (dir / c.file).string() + "'");
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(first_line(r.out).find(c.expect), std::string::npos) << r.out;
    EXPECT_TRUE(r.out.find("parts") != std::string::npos || r.out.find("nested") != std::string::npos) << r.out;
    EXPECT_THROW((void)parse_toml_file(dir / c.file), ConfigError);
  }
  std::filesystem::remove_all(dir);
}

TEST(HostileInput, TomlWithDotsInStringsCommentsAndNumbersStillParses) {
  const std::string many_dots = repeat("a", 200, ".");
  const std::string text = "s = \"" + many_dots + "\"\nl = '" + many_dots + "'\n# " + many_dots + "\nm = \"\"\"\n" +
                           many_dots + "\n\"\"\"\nn = '''" + many_dots + "'''\nq = \"\"\"x\"\"\"\"\n" + "v = [" +
                           repeat("1.5", 500, ", ") + "]\nt = 1979-05-27T07:32:00.999Z\n" + repeat("k", 60, ".") +
                           " = 1\n[" + repeat("h", 60, ".") + "]\nx = " + repeat("[", 60, "") + repeat("]", 60, "") +
                           "\n";
  const auto file = parse_toml_string(text, "ok.toml");
  EXPECT_EQ(file->root["s"].value_or(std::string()), many_dots);
  EXPECT_EQ(file->root["m"].value_or(std::string()), many_dots + "\n");
  EXPECT_EQ(file->root["q"].value_or(std::string()), "x\"");
  const toml::array* v = file->root["v"].as_array();
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(v->size(), 500u);
}

TEST(HostileInput, InputsThatAreNotBoundedRegularFilesAreRefusedBeforeReading) {
  const auto dir = scratch_dir("hostile_files");
  const std::string fifo = (dir / "fifo.toml").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string big = (dir / "big.toml").string();
  {
    std::ofstream(big) << kHead;
    std::filesystem::resize_file(big, kMaxInputFileBytes + 1);  // sparse: nothing is written
  }
  struct Case {
    std::string path;
    const char* expect;
  };
  const Case cases[] = {
      {"/dev/zero", "/dev/zero: TOML file is a character device, expected a regular file"},
      {dir.string(), "TOML file is a directory, expected a regular file"},
      {fifo, "TOML file is a FIFO (named pipe), expected a regular file"},
      {big, "more than the 16777216 bytes an input file may have"},
      {(dir / "missing.toml").string(), "missing.toml: TOML file does not exist"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.path);
    // The CLI would hang on the FIFO or grow without bound on /dev/zero: `timeout` turns either into a failure.
    const Cli r = redres_env("timeout 20 ", "robot '" + c.path + "'");
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(first_line(r.out).find(c.expect), std::string::npos) << r.out;
    EXPECT_THROW((void)read_input_file(c.path, "TOML file"), ConfigError);
  }
  // A table law naming /dev/zero as its CSV file.
  write(dir / "law.toml", kHead +
                              "[[joints]]\nname = \"j1\"\nlength = 0.3\nlimits = [-1.0, 1.0]\n"
                              "[joints.velocity_limit]\ntype = \"table\"\nfile = \"/dev/zero\"\n");
  const Cli r = redres_env("timeout 20 ", "robot '" + (dir / "law.toml").string() + "'");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("/dev/zero: CSV file is a character device"), std::string::npos) << r.out;
  std::filesystem::remove_all(dir);
}

// A step count that overflowed an int, or a table of gigabytes made before the loop, is an error at the key.
TEST(HostileInput, StepCountsAndTheTableAreBoundedAtLoad) {
  const auto scenario = source_path("configs/paper_r_fast.toml");
  const auto message = [&](const std::vector<std::string>& overrides) {
    try {
      (void)load_scenario(scenario, overrides);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("(loaded)");
  };
  std::string m = message({"duration=2147483647.0", "step=1.0"});
  EXPECT_NE(m.find("--set step:1:5: scenario: key 'step': expected at most 10000000 steps"), std::string::npos) << m;
  m = message({"duration=1e300", "step=1e-300"});
  EXPECT_NE(m.find("expected at most 10000000 steps"), std::string::npos) << m;
  m = message({"duration=1e7", "step=1.0"});
  EXPECT_NE(m.find("key 'step': expected a run whose recorded table fits in 2 GiB, got 10000001 rows"),
            std::string::npos)
      << m;
  // The largest run that fits still loads, and nothing is allocated for it until it runs.
  EXPECT_EQ(message({"duration=4e6", "step=1.0"}), "(loaded)");
  // A scenario put together in code is checked where the count is taken.
  Scenario s = load_scenario(scenario);
  s.duration = 1e12;
  EXPECT_THROW((void)s.steps(), std::invalid_argument);
}

// Values that passed the type checks but overflowed the step (inf in trajectory.csv, null in summary.json) are
// refused at load, at their key, with the range: a unit's physical range, or the key's own sane range.
TEST(HostileInput, ValuesOutsidePhysicalOrSaneRangesAreRefusedAtTheirKey) {
  const auto scenario = source_path("configs/paper_r_fast.toml");
  struct Case {
    std::string set;
    std::string expect;
  };
  const Case cases[] = {
      {"path.height=1e300", "key 'height': expected |x| <= 1000 m (a physical range), got 1e+300"},
      {"constraints.0.gain=1e308", "key 'gain': expected |x| <= 1e+06 1/s (a physical range), got 1e+308"},
      {"constraints.1.kappa=1e300", "key 'kappa': expected |x| <= 1e+06 1/s (a physical range)"},
      {"objectives.0.weight=1e308", "key 'weight': expected in [0, 1e+06], got 1e+308"},
      {"objectives.1.p=1e308", "key 'p': expected in [-1e+06, 1e+06], got 1e+308"},
      {"solver.tolerance=1e-300", "key 'tolerance': expected in [1e-14, 1], got 1e-300"},
      {"solver.varpi=1e-300", "key 'varpi': expected in [1, 1e+12], got 1e-300"},
  };
  for (const Case& c : cases) {
    if (c.expect.empty()) continue;
    SCOPED_TRACE(c.set);
    try {
      (void)load_scenario(scenario, {c.set});
      ADD_FAILURE() << "loaded";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("--set " + c.set.substr(0, c.set.find('=')) + ":1:", 0), 0u) << e.what();
    }
  }
  const Cli origin = redres("validate configs/planar_4link_circle.toml --set 'path.origin=[1e300, 0]'");
  EXPECT_EQ(origin.code, 2) << origin.out;
  EXPECT_NE(origin.out.find("key 'origin': expected |x| <= 1000 m (a physical range), got [1e+300, 0.0]"),
            std::string::npos)
      << origin.out;
  const Cli radius = redres("validate configs/planar_4link_circle.toml --set path.radius=1e200");
  EXPECT_EQ(radius.code, 2) << radius.out;
  EXPECT_NE(radius.out.find("key 'radius': expected |x| <= 1000 m"), std::string::npos) << radius.out;
  // A link of 1e308 m in a robot file.
  const auto dir = scratch_dir("hostile_ranges");
  write(dir / "long.toml", kHead + "[[joints]]\nname = \"j1\"\nlength = 1e308\nlimits = [-1.0, 1.0]\n");
  const Cli robot = redres("robot '" + (dir / "long.toml").string() + "'");
  EXPECT_EQ(robot.code, 2) << robot.out;
  EXPECT_NE(first_line(robot.out).find("long.toml:5:10:"), std::string::npos) << robot.out;
  EXPECT_NE(robot.out.find("key 'length': expected |x| <= 1000 m (a physical range), got 1e+308"), std::string::npos)
      << robot.out;
  std::filesystem::remove_all(dir);
}

// A schedule formula of t that is not finite at some step time of the run is refused at load, at its key, with the
// first such time; before, the run stopped mid-way (or, later, failed every step with t < 1 s).
TEST(HostileInput, AScheduleFormulaIsCheckedAtEveryStepTimeAtLoad) {
  const auto dir = scratch_dir("hostile_schedule");
  const std::string text = shipped_scenario_text("paper_r_fast.toml");
  for (const char* formula : {"sqrt(t-1)", "1/(t-1.2)", "log(2.4 - t)"}) {
    SCOPED_TRACE(formula);
    std::string scenario = text;
    const std::string schedule = "schedule = \"sine\"\n";
    ASSERT_NE(scenario.find(schedule), std::string::npos);
    scenario.replace(scenario.find(schedule), schedule.size(),
                     "schedule = \"expression\"\nformula = \"" + std::string(formula) + "\"\n");
    // The formula's line in the file.
    const std::size_t formula_pos = scenario.find("formula = ");
    const auto line =
        1 + std::count(scenario.begin(), scenario.begin() + static_cast<std::ptrdiff_t>(formula_pos), '\n');
    write(dir / "s.toml", scenario);
    const Cli r = redres("validate '" + (dir / "s.toml").string() + "'");
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_EQ(first_line(r.out).rfind((dir / "s.toml").string() + ":" + std::to_string(line) + ":", 0), 0u) << r.out;
    EXPECT_NE(r.out.find("key 'formula': expected p(t) finite at every step time of the run, got"), std::string::npos)
        << r.out;
  }
  // Finite at every step time: accepted, although not finite between them (1/(t - 0.0005) at tau = 1 ms).
  EXPECT_NO_THROW((void)load_scenario(source_path("configs/paper_r_fast.toml"),
                                      {"objectives.1.schedule=expression", "objectives.1.formula=1/(t-0.0005)"}));
}

// A velocity-limit formula of theta that is NaN in a window narrower than the load-time samples: the step that meets
// it is a failed step (invalid_problem) whose diagnosis names the joint, its law and where the law was configured;
// it moves nothing, and the run goes on to the end with every recorded value finite.
TEST(HostileInput, ANonFiniteVelocityLimitMidRunIsAFailedStepNotTheEndOfTheRun) {
  const auto dir = scratch_dir("hostile_nan_law");
  // Where joint 1 goes in the run, and a value it takes mid-run whose window misses every load-time sample.
  Scenario plain = load_scenario(source_path("configs/paper_r_fast.toml"));
  const RunResult base = simulate(plain);
  const double lo = plain.robot->lower_limits()(0), hi = plain.robot->upper_limits()(0);
  const double h = (hi - lo) / (kVelocityLawSamples - 1), half = 4e-4;
  std::size_t row = base.trajectory.size() / 2;
  for (; row < base.trajectory.size(); ++row) {
    const double th = base.trajectory.at(row, "theta_1");
    const double below = std::floor((th - half - lo) / h), above = std::floor((th + half - lo) / h);
    if (below == above) break;  // no sample in [th - half, th + half]
  }
  ASSERT_LT(row, base.trajectory.size());
  const double centre = base.trajectory.at(row, "theta_1");
  std::string robot = read_text(source_path("robots/paper_pushrod_6dof.toml"));
  const std::string law = "type = \"constant\"\nlower = -3.272492347489368  # -25 pi / 24 rad/s\n";
  ASSERT_NE(robot.find(law), std::string::npos);
  std::ostringstream expr;
  expr.precision(17);
  expr << "type = \"expression\"\nlower = \"-3.272492347489368 + 0*sqrt(abs(theta - " << centre << ") - " << half
       << ")\"\n";
  robot.replace(robot.find(law), law.size(), expr.str());
  robot.replace(robot.find("upper = 3.272492347489368"), std::string("upper = 3.272492347489368").size(),
                "upper = \"3.272492347489368\"");
  write(dir / "robot.toml", robot);
  std::string scenario = read_text(source_path("configs/paper_r_fast.toml"));
  const std::string robot_line = "robot = \"../robots/paper_pushrod_6dof.toml\"";
  scenario.replace(scenario.find(robot_line), robot_line.size(), "robot = \"robot.toml\"");
  write(dir / "s.toml", scenario);

  Scenario s = load_scenario(dir / "s.toml");
  const RunResult run = simulate(s);
  ASSERT_EQ(run.trajectory.size(), base.trajectory.size());
  // The first row whose theta_1 lies in the window (at `row` at the latest): the run is the plain run up to there,
  // fails there, and is held from there on (the law stays NaN where the arm stands).
  const std::size_t status = run.trajectory.column("solver_status");
  std::size_t first = 0;
  while (first < run.trajectory.size() && run.trajectory(first, status) == 0.0) ++first;
  ASSERT_LE(first, row);
  EXPECT_LT(std::abs(run.trajectory.at(first, "theta_1") - centre), half);
  std::ostringstream when;
  when << "t = " << run.trajectory.at(first, "t")
       << " s: invalid_problem: joint 1 ('joint1') velocity limit expression(";
  EXPECT_EQ(run.first_failure.rfind(when.str(), 0), 0u) << run.first_failure;
  EXPECT_NE(run.first_failure.find("(" + (dir / "robot.toml").string() + ":"), std::string::npos) << run.first_failure;
  EXPECT_NE(run.first_failure.find("gave lower nan"), std::string::npos) << run.first_failure;
  for (std::size_t r = 0; r < run.trajectory.size(); ++r) {
    for (std::size_t c = 0; c < run.trajectory.width(); ++c) {
      const std::string& name = run.trajectory.columns()[c];
      if (name.rfind("lo_", 0) == 0 || name.rfind("hi_", 0) == 0 || name.rfind("vel_lo_", 0) == 0) continue;
      ASSERT_TRUE(std::isfinite(run.trajectory(r, c))) << name << " at row " << r;
    }
    const bool bad = run.trajectory(r, status) == static_cast<double>(static_cast<int>(SolverStatus::kInvalidProblem));
    EXPECT_EQ(bad, r >= first) << "row " << r;
    if (r <= first) {
      EXPECT_EQ(run.trajectory.at(r, "theta_1"), base.trajectory.at(r, "theta_1")) << "row " << r;
    }
    if (bad && r + 1 < run.trajectory.size()) {
      EXPECT_EQ(run.trajectory.at(r + 1, "theta_1"), run.trajectory.at(r, "theta_1"));
    }
  }
  EXPECT_EQ(run.held_steps, static_cast<int>(run.trajectory.size() - first) - 1);
  // The CLI writes the run and exits 1 (failed steps), with or without --quiet.
  for (const char* quiet : {"", " --quiet"}) {
    const auto out = dir / "out";
    const Cli r = redres("run '" + (dir / "s.toml").string() + "' --out '" + out.string() + "'" + quiet);
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_NE(r.out.find("first failure: " + when.str()), std::string::npos) << r.out;
    EXPECT_TRUE(std::filesystem::exists(out / "summary.json"));
    EXPECT_TRUE(std::filesystem::exists(out / "trajectory.csv"));
    std::filesystem::remove_all(out);
  }
}

// Each message is about what is wrong, where it is: the command line's own words are named as such.
TEST(HostileInput, CommandLineMistakesAreNamedAsTheyWereGiven) {
  struct Case {
    std::string args;
    std::string first_line;
  };
  const std::string v = "validate configs/paper_r_fast.toml ";
  const Case cases[] = {
      {"frobnicate", "redres: unknown command 'frobnicate'; the commands are robot, plugins, keys, run, validate"},
      {v + "--set duration=1e400", "--set duration=1e400: '1e400' is out of range for a number"},
      {v + "--set objectives.1xyz.p=1", "'1xyz' is not an index into the array 'objectives' (expected digits"},
      {v + "--set objectives.1e0.p=1", "'1e0' is not an index into the array 'objectives'"},
      {v + "--set 'duration=2.5 # two'", "expected one value after '=', got extra text in '2.5 # two'"},
      {v + "--set 'name=\"r\" x'", "'\"r\" x' is not a TOML value"},
      {v + "--set objectives.1.schedule=expression --set 'objectives.1.formula=t = 5'",
       "\"t = 5\" is not a valid formula: '=' assigns to a variable"},
      {v + "--set objectives.1.schedule=expression --set 'objectives.1.formula=1, 2'",
       "\"1, 2\" is not a valid formula: expected one expression, got 2"},
      {"robot robots/paper_pushrod_6dof.toml --theta 0.1,0.1", "--theta: expected 6 comma-separated values"},
      {"robot robots/paper_pushrod_6dof.toml --theta 9,0.1,0.1,0.1,0.1,0.1",
       "--theta: joint 1 ('joint1') = 9 is outside its limits [-1.536, 1.431]"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const Cli r = redres(c.args);
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(first_line(r.out).find(c.first_line), std::string::npos) << r.out;
  }
  // What is right still is: a bare word, a quoted string with a code point past ASCII, comparisons in formulas.
  for (const std::string ok :
       {"--set 'name=bare words'", "--set 'name=\"\u03a9mega\"'",
        "--set objectives.1.schedule=expression --set 'objectives.1.formula=(t >= 1) * min(t, 2)'"}) {
    SCOPED_TRACE(ok);
    const Cli r = redres(v + ok);
    EXPECT_EQ(r.code, 0) << r.out;
  }
}

}  // namespace
}  // namespace redres

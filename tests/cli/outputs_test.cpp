// What the commands leave in their output directories: stale files of an earlier run are removed (and a user's
// own files are not), --out is checked before the run, `compare` keeps same-stem scenarios apart, checks every
// scenario before the first run, quotes its CSV and reports write errors, and SIGINT ends `run`, `compare` and
// `sweep` cleanly with exit code 130.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_util.hpp"
#include "redres/run/run_output.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"
#include "scenario_text.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

std::set<std::string> names_in(const std::filesystem::path& dir) {
  std::set<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// A short planar run (2 s of the 4R arm's circle, 200 steps), written into `dir` as scenario.toml.
std::filesystem::path short_scenario(const std::filesystem::path& dir, const std::string& name = "short",
                                     const std::string& file = "scenario.toml") {
  std::filesystem::create_directories(dir);
  const auto path = dir / file;
  std::string quoted;  // the name as a TOML basic string's content
  for (const char c : name) quoted += c == '"' ? std::string("\\\"") : std::string(1, c);
  std::ofstream(path) << "name = \"" << quoted << "\"\n"
                      << robot_line("planar_4link.toml") << "duration = 2.0\nstep = 0.01\n"
                      << circle_tracking("0.06", "engine = \"newton\"\n");
  return path;
}

TEST(RunOutputs, AFileAnEarlierRunWroteAndThisOneDoesNotIsRemovedAndAUsersFileStays) {
  const auto dir = scratch("stale_outputs");
  Scenario s = load_scenario(short_scenario(dir / "in"));
  const RunResult run = simulate(s);
  const RunSummary summary = summarise(s, run);
  const auto out = dir / "out";
  const std::vector<std::string> written = write_run(*s.robot, run, summary, out);
  EXPECT_EQ(written, (std::vector<std::string>{"trajectory.csv", "frames.csv", "summary.json"}));
  // A figure step adds its files; the user adds one of their own.
  std::ofstream(out / "tracking.png") << "figure";
  add_to_output_manifest(out, {"tracking.png"});
  std::ofstream(out / "notes.txt") << "mine";
  EXPECT_EQ(read_output_manifest(out),
            (std::vector<std::string>{"trajectory.csv", "frames.csv", "summary.json", "tracking.png"}));
  // The next run writes only the summary: the tables and the figure are stale, the notes are not redres's.
  RecordOptions none;
  none.none = true;
  (void)write_run(*s.robot, run, summary, out, none);
  EXPECT_EQ(names_in(out), (std::set<std::string>{".redres-outputs", "summary.json", "notes.txt"}));
  EXPECT_EQ(read_text(out / "notes.txt"), "mine");
  EXPECT_EQ(read_output_manifest(out), std::vector<std::string>{"summary.json"});
}

TEST(RunOutputs, AManifestNeverNamesAnythingOutsideItsDirectory) {
  const auto dir = scratch("manifest_names");
  std::filesystem::create_directories(dir / "out");
  std::ofstream(dir / "victim.txt") << "keep";
  std::ofstream(dir / "out" / ".redres-outputs")
      << "# hand-edited\n../victim.txt\n/etc/passwd\n.hidden\nsummary.json\n";
  EXPECT_EQ(read_output_manifest(dir / "out"), std::vector<std::string>{"summary.json"});
  Scenario s = load_scenario(short_scenario(dir / "in"));
  const RunResult run = simulate(s);
  (void)write_run(*s.robot, run, summarise(s, run), dir / "out");
  EXPECT_EQ(read_text(dir / "victim.txt"), "keep");
}

TEST(RunOutputsCli, FiguresOfAnEarlierPlotsRunAreRemovedByARunWithoutPlots) {
  const auto dir = scratch("stale_figures");
  const auto file = short_scenario(dir);
  const auto out = dir / "out";
  // Debian's python3 first (the one scripts/install_deps.sh gives matplotlib), whatever else is on PATH.
  const Cli plotted =
      redres_env("PATH=/usr/bin:$PATH ", "run '" + file.string() + "' --out '" + out.string() + "' --plots --quiet");
  if (plotted.code == 2 && plotted.out.find("matplotlib") != std::string::npos) {
    GTEST_SKIP() << "no matplotlib for the python3 on PATH: " << plotted.out;
  }
  ASSERT_EQ(plotted.code, 0) << plotted.out;
  std::vector<std::string> figures;
  for (const auto& n : names_in(out)) {
    if (n.size() > 4 && n.substr(n.size() - 4) == ".png") figures.push_back(n);
  }
  ASSERT_FALSE(figures.empty());
  const std::vector<std::string> manifest = read_output_manifest(out);
  for (const auto& f : figures) EXPECT_NE(std::find(manifest.begin(), manifest.end(), f), manifest.end()) << f;
  std::ofstream(out / "my_plot.png") << "the user's";
  const Cli again = redres("run '" + file.string() + "' --out '" + out.string() + "' --quiet");
  ASSERT_EQ(again.code, 0) << again.out;
  for (const auto& f : figures) EXPECT_FALSE(std::filesystem::exists(out / f)) << f;
  EXPECT_EQ(read_text(out / "my_plot.png"), "the user's");
  EXPECT_TRUE(std::filesystem::exists(out / "trajectory.csv"));
}

TEST(RunOutputsCli, OutIsCheckedBeforeTheRunStarts) {
  const auto dir = scratch("out_checked");
  const auto file = short_scenario(dir);
  std::ofstream(dir / "a_file") << "x";
  const Cli r = redres("run '" + file.string() + "' --out '" + (dir / "a_file").string() + "' --quiet");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--out " + (dir / "a_file").string() + ": exists and is not a directory"), std::string::npos)
      << r.out;
  EXPECT_EQ(read_text(dir / "a_file"), "x");
  const Cli p = redres("run '" + file.string() + "' --out /proc/version/out --quiet");
  EXPECT_EQ(p.code, 2) << p.out;
  EXPECT_NE(p.out.find("--out /proc/version/out: cannot create the directory"), std::string::npos) << p.out;
  // Neither ran: the failure is not preceded by a summary or a run's files.
  EXPECT_EQ(r.out.find("steps of"), std::string::npos);
}

TEST(CompareCli, SameStemsGetTheirOwnDirectoriesAndNamesAreQuotedInTheCsv) {
  const auto dir = scratch("compare_stems");
  const auto a = short_scenario(dir / "a", "circle, newton", "x.toml");
  const auto b = short_scenario(dir / "b", "circle \"b\"", "x.toml");
  const auto out = dir / "out";
  const Cli r =
      redres("compare '" + a.string() + "' '" + b.string() + "' --out '" + out.string() + "' --no-plots --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(std::filesystem::exists(out / "x" / "summary.json"));
  EXPECT_TRUE(std::filesystem::exists(out / "x-2" / "summary.json"));
  EXPECT_EQ(read_summary(out / "x")["name"], "circle, newton");
  EXPECT_EQ(read_summary(out / "x-2")["name"], "circle \"b\"");
  const std::string csv = read_text(out / "comparison.csv");
  // The name, then the label (no `label` in the files: the name), quoted the same way.
  EXPECT_NE(csv.find("\n\"circle, newton\",\"circle, newton\",newton,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\n\"circle \"\"b\"\"\",\"circle \"\"b\"\"\",newton,"), std::string::npos) << csv;
}

TEST(CompareCli, ABadLaterScenarioIsReportedBeforeAnyRun) {
  const auto dir = scratch("compare_bad_later");
  const auto good = short_scenario(dir, "good", "good.toml");
  std::ofstream(dir / "bad.toml") << "name = \"bad\"\nduration = -1\n";
  const auto out = dir / "out";
  const Cli r = redres("compare '" + good.string() + "' '" + (dir / "bad.toml").string() + "' --out '" + out.string() +
                       "' --no-plots --quiet");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(r.out.rfind((dir / "bad.toml").string() + ":", 0), 0u) << r.out;
  EXPECT_FALSE(std::filesystem::exists(out)) << "the good scenario ran before the bad one was read";
}

TEST(CompareCli, AWriteErrorIsAnError) {
  const auto dir = scratch("compare_write_error");
  const auto file = short_scenario(dir);
  const auto out = dir / "out";
  std::filesystem::create_directories(out / "comparison.csv");  // a directory where the file goes
  const Cli r = redres("compare '" + file.string() + "' --out '" + out.string() + "' --no-plots --quiet");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("comparison.csv"), std::string::npos) << r.out;
}

// Starts the CLI with `args` (stdout and stderr into `log`), sends SIGINT after `delay`, and returns its exit code.
int interrupt_after(const std::vector<std::string>& args, std::chrono::milliseconds delay,
                    const std::filesystem::path& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::FILE* f = std::freopen(log.c_str(), "w", stdout);
    if (f == nullptr || dup2(fileno(stdout), 2) < 0) _exit(127);
    std::vector<char*> argv;
    std::string cli = REDRES_CLI;
    argv.push_back(cli.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(cli.c_str(), argv.data());
    _exit(127);
  }
  std::this_thread::sleep_for(delay);
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// Settings that make the paper's R long enough to be interrupted: a 0.1 ms step (400,000 steps) with the nlopt
// engine (tens of microseconds per step).
std::string long_run_set() { return "step=0.0001"; }

TEST(SignalsCli, SigintEndsRunCompareAndSweepWithExitCode130) {
  const auto dir = scratch_dir("sigint");
  const std::string paper = source_path("configs/paper_r_tvcmm.toml").string();
  {
    const int code = interrupt_after({"run", paper, "--out", (dir / "run").string(), "--quiet", "--set", long_run_set(),
                                      "--set", "solver.engine=nlopt"},
                                     std::chrono::milliseconds(1500), dir / "run.log");
    EXPECT_EQ(code, 130) << read_text(dir / "run.log");
    EXPECT_EQ(read_summary(dir / "run")["status"], "interrupted");
  }
  {
    const int code = interrupt_after({"compare", paper, paper, "--out", (dir / "compare").string(), "--quiet",
                                      "--no-plots", "--set", long_run_set(), "--set", "solver.engine=nlopt"},
                                     std::chrono::milliseconds(1500), dir / "compare.log");
    EXPECT_EQ(code, 130) << read_text(dir / "compare.log");
    EXPECT_EQ(read_summary(dir / "compare" / "paper_r_tvcmm")["status"], "interrupted");
    EXPECT_FALSE(std::filesystem::exists(dir / "compare" / "paper_r_tvcmm-2")) << "the second run started";
    EXPECT_TRUE(std::filesystem::exists(dir / "compare" / "comparison.csv"));
  }
  {
    std::ofstream(dir / "sweep.toml") << "name = \"long\"\nscenario = \"" << paper
                                      << "\"\nset = [\"step=0.0001\", \"solver.engine=nlopt\"]\n"
                                      << "[[vary]]\nkey = \"objectives.1.p\"\nvalues = [0.0, 1.0, 2.0, 4.0]\n";
    const int code = interrupt_after(
        {"sweep", (dir / "sweep.toml").string(), "--out", (dir / "sweep").string(), "--quiet", "--jobs", "1"},
        std::chrono::milliseconds(1500), dir / "sweep.log");
    EXPECT_EQ(code, 130) << read_text(dir / "sweep.log");
    const auto meta = nlohmann::json::parse(read_text(dir / "sweep" / "sweep.json"));
    EXPECT_EQ(meta["interrupted"], true);
    EXPECT_LT(meta["rows"].get<int>(), 4);
    EXPECT_NE(read_text(dir / "sweep" / "sweep.csv").find("interrupted"), std::string::npos);
  }
}

}  // namespace
}  // namespace redres

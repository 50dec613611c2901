// Outputs that cannot be turned against the user: a symbolic link where redres writes is refused, never followed
// or replaced; a planted, hand-written or stale manifest deletes nothing redres did not write; a sweep whose write
// fails (a full disk, here a file-size limit) keeps its previous sweep.csv and sweep.json whole; staged files are
// created exclusively and leave nothing behind.

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "cli_util.hpp"
#include "redres/common/output_file.hpp"
#include "redres/run/run_output.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

// The names in `dir` that start with a dot, the manifest aside (staging files left behind).
int temporaries_in(const std::filesystem::path& dir) {
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name[0] == '.' && name != kOutputManifest) ++n;
  }
  return n;
}

std::string fast_run_args(const std::filesystem::path& out) {
  return "run configs/paper_r_fast.toml --quiet --out '" + out.string() + "'";
}

TEST(OutputSafety, ASymbolicLinkWhereARunWritesIsRefusedBeforeTheRunAndItsTargetIsUntouched) {
  const auto dir = scratch("out_symlink");
  std::filesystem::create_directories(dir / "out");
  std::ofstream(dir / "victim.txt") << "keep";
  for (const char* name : {"trajectory.csv", "summary.json", ".redres-outputs"}) {
    std::filesystem::remove(dir / "out" / name);
    std::filesystem::create_symlink(dir / "victim.txt", dir / "out" / name);
    const Cli r = redres(fast_run_args(dir / "out"));
    EXPECT_EQ(r.code, 2) << name << ": " << r.out;
    EXPECT_NE(r.out.find(std::string(name) + " is a symbolic link"), std::string::npos) << r.out;
    EXPECT_EQ(read_text(dir / "victim.txt"), "keep") << name;
    EXPECT_TRUE(std::filesystem::is_symlink(dir / "out" / name)) << name << ": the link itself stays";
    std::filesystem::remove(dir / "out" / name);
  }
  // Without links the same run writes regular files.
  const Cli ok = redres(fast_run_args(dir / "out"));
  ASSERT_EQ(ok.code, 0) << ok.out;
  for (const char* name : {"trajectory.csv", "frames.csv", "summary.json", ".redres-outputs"}) {
    EXPECT_FALSE(std::filesystem::is_symlink(dir / "out" / name)) << name;
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "out" / name)) << name;
  }
  EXPECT_EQ(temporaries_in(dir / "out"), 0);
  std::filesystem::remove_all(dir);
}

// A sweep's table names are checked before its first variation runs: a link there costs nothing but the message
// (the sweep is never run only to be refused at its end).
TEST(OutputSafety, ASymbolicLinkWhereASweepWritesIsRefusedBeforeItRuns) {
  const auto dir = scratch("out_sweep_symlink");
  std::filesystem::create_directories(dir / "out");
  std::ofstream(dir / "victim.txt") << "keep";
  for (const char* name : {"sweep.csv", "sweep.json"}) {
    std::filesystem::create_symlink(dir / "victim.txt", dir / "out" / name);
    const Cli r = redres("sweep tests/data/sweeps/small.toml --quiet --out '" + (dir / "out").string() + "'");
    EXPECT_EQ(r.code, 2) << name << ": " << r.out;
    EXPECT_NE(r.out.find(std::string(name) + " is a symbolic link"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "runs")) << "no variation ran";
    EXPECT_EQ(read_text(dir / "victim.txt"), "keep") << name;
    std::filesystem::remove(dir / "out" / name);
  }
  std::filesystem::remove_all(dir);
}

TEST(OutputSafety, StagedFilesAreCreatedExclusivelyAndNeverThroughALink) {
  const auto dir = scratch_dir("staged_file");
  std::ofstream(dir / "victim.txt") << "keep";
  {
    StagedFile a(dir / "x.csv"), b(dir / "x.csv");  // two at once get two temporaries
    a.write("a\n");
    b.write("b\n");
    EXPECT_EQ(temporaries_in(dir), 2);
    a.install();
    EXPECT_EQ(read_text(dir / "x.csv"), "a\n");
  }  // b is destroyed without install: its temporary goes, x.csv stays a's
  EXPECT_EQ(temporaries_in(dir), 0);
  EXPECT_EQ(read_text(dir / "x.csv"), "a\n");
  // A link at the final name: refused at construction, and again at install when planted after construction.
  std::filesystem::create_symlink(dir / "victim.txt", dir / "link.csv");
  EXPECT_THROW(StagedFile(dir / "link.csv"), std::runtime_error);
  StagedFile late(dir / "late.csv");
  late.write("late\n");
  std::filesystem::create_symlink(dir / "victim.txt", dir / "late.csv");
  EXPECT_THROW(late.install(), std::runtime_error);
  EXPECT_EQ(read_text(dir / "victim.txt"), "keep");
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "late.csv"));
  EXPECT_EQ(temporaries_in(dir), 0);
  // The file's mode follows the umask like any other output (not mkstemp's 0600).
  const mode_t old = ::umask(022);
  write_text_file(dir / "mode.txt", "m");
  ::umask(old);
  EXPECT_EQ(std::filesystem::status(dir / "mode.txt").permissions() & std::filesystem::perms::all,
            std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                std::filesystem::perms::group_read | std::filesystem::perms::others_read);
  std::filesystem::remove_all(dir);
}

TEST(OutputSafety, APlantedOrHandWrittenManifestDeletesNothing) {
  const auto dir = scratch("out_manifest");
  std::filesystem::create_directories(dir / "out");
  std::ofstream(dir / "out" / "notes.txt") << "mine";
  std::ofstream(dir / "out" / "data.csv") << "mine too";
  const auto st = stamp_of(dir / "out" / "data.csv");
  // Names without stamps, and a stamp that does not match the file: neither is recognisably redres's.
  std::ofstream(dir / "out" / ".redres-outputs")
      << "# planted\nnotes.txt\ndata.csv\t" << st.size + 1 << "\t" << st.mtime_ns << "\t" << st.inode << "\n";
  const Cli r = redres(fast_run_args(dir / "out"));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(read_text(dir / "out" / "notes.txt"), "mine");
  EXPECT_EQ(read_text(dir / "out" / "data.csv"), "mine too");
  std::filesystem::remove_all(dir);
}

// A manifest that carries the file's own stamp, as anyone who can stat it could write, deletes it only when the
// manifest is this user's own and no one else can write it: one others may write (or, run as root, one another
// user owns, as in a sticky shared directory) is not trusted, and a file another user owns is never removed.
TEST(OutputSafety, AManifestOthersCouldHaveWrittenDeletesNothing) {
  const auto dir = scratch("out_manifest_owner");
  const auto out = dir / "out";
  std::filesystem::create_directories(out);
  std::ofstream(out / "precious.txt") << "mine";
  const auto plant = [&] {
    const auto st = stamp_of(out / "precious.txt");
    std::filesystem::remove(out / ".redres-outputs");
    std::ofstream(out / ".redres-outputs")
        << "precious.txt\t" << st.size << "\t" << st.mtime_ns << "\t" << st.inode << "\n";
  };
  plant();
  ASSERT_EQ(::chmod((out / ".redres-outputs").c_str(), 0666), 0);
  Cli r = redres(fast_run_args(out));
  EXPECT_EQ(read_text(out / "precious.txt"), "mine") << r.out;
  if (::geteuid() == 0) {
    plant();
    ASSERT_EQ(::chown((out / ".redres-outputs").c_str(), 65534, 65534), 0);
    r = redres(fast_run_args(out));
    EXPECT_EQ(read_text(out / "precious.txt"), "mine") << r.out;
    ASSERT_EQ(::chown((out / "precious.txt").c_str(), 65534, 65534), 0);
    plant();  // this user's manifest, but the file is another user's
    r = redres(fast_run_args(out));
    EXPECT_EQ(read_text(out / "precious.txt"), "mine") << r.out;
    ASSERT_EQ(::chown((out / "precious.txt").c_str(), 0, 0), 0);
  }
  // The same manifest, this user's alone, over this user's file: it names the file as redres's, and the file goes
  // (what the stamp is for: a stale output of an earlier run).
  plant();
  r = redres(fast_run_args(out));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_FALSE(std::filesystem::exists(out / "precious.txt"));
  std::filesystem::remove_all(dir);
}

TEST(OutputSafety, AFileEditedOrReplacedSinceARunWroteItIsNotStale) {
  const auto dir = scratch("out_stale");
  Scenario s = load_scenario(source_path("configs/paper_r_fast.toml"));
  const RunResult run = simulate(s);
  const RunSummary summary = summarise(s, run);
  const auto out = dir / "out";
  (void)write_run(*s.robot, run, summary, out);
  // The user appends to trajectory.csv and replaces frames.csv by a file of their own; the next run records none.
  std::ofstream(out / "trajectory.csv", std::ios::app) << "# my note\n";
  std::filesystem::remove(out / "frames.csv");
  std::ofstream(out / "frames.csv") << "mine";
  RecordOptions none;
  none.none = true;
  (void)write_run(*s.robot, run, summary, out, none);
  EXPECT_NE(read_text(out / "trajectory.csv").find("# my note"), std::string::npos);
  EXPECT_EQ(read_text(out / "frames.csv"), "mine");
  // Unedited, the same tables are stale and go.
  (void)write_run(*s.robot, run, summary, out);
  (void)write_run(*s.robot, run, summary, out, none);
  EXPECT_FALSE(std::filesystem::exists(out / "trajectory.csv"));
  EXPECT_FALSE(std::filesystem::exists(out / "frames.csv"));
  EXPECT_TRUE(std::filesystem::exists(out / "summary.json"));
  std::filesystem::remove_all(dir);
}

TEST(OutputSafety, ASweepWhoseWriteFailsKeepsThePreviousTableAndDescriptionWhole) {
  const auto dir = scratch("sweep_full");
  const std::string sweep = data_path("sweeps/small.toml").string();
  const auto out = dir / "out";
  const Cli first = redres("sweep '" + sweep + "' --jobs 2 --quiet --out '" + out.string() + "'");
  ASSERT_LE(first.code, 1) << first.out;
  const std::string csv = read_text(out / "sweep.csv"), json = read_text(out / "sweep.json");
  ASSERT_GT(csv.size(), 1024U);
  // A full disk, as a file-size limit of 1 KiB (SIGXFSZ ignored, so that the write fails with EFBIG).
  const Cli full =
      redres_env("trap '' XFSZ; ulimit -f 1; ", "sweep '" + sweep + "' --jobs 2 --quiet --out '" + out.string() + "'");
  EXPECT_EQ(full.code, 2) << full.out;
  EXPECT_NE(full.out.find("cannot write " + (out / "sweep.csv").string()), std::string::npos) << full.out;
  EXPECT_EQ(read_text(out / "sweep.csv"), csv);
  EXPECT_EQ(read_text(out / "sweep.json"), json);
  EXPECT_EQ(temporaries_in(out), 0);
  // A link at sweep.csv is refused, its target untouched.
  std::ofstream(dir / "victim.txt") << "keep";
  std::filesystem::remove(out / "sweep.csv");
  std::filesystem::create_symlink(dir / "victim.txt", out / "sweep.csv");
  const Cli link = redres("sweep '" + sweep + "' --jobs 2 --quiet --out '" + out.string() + "'");
  EXPECT_EQ(link.code, 2) << link.out;
  EXPECT_NE(link.out.find("is a symbolic link"), std::string::npos) << link.out;
  EXPECT_EQ(read_text(dir / "victim.txt"), "keep");
  std::filesystem::remove_all(dir);
}

TEST(OutputSafety, AFigureNameThatIsASymbolicLinkIsRefusedByThePlotter) {
  const auto dir = scratch("out_figure_link");
  std::filesystem::create_directories(dir / "out");
  std::ofstream(dir / "victim.txt") << "keep";
  std::filesystem::create_symlink(dir / "victim.txt", dir / "out" / "fig3_profiles.png");
  const Cli r = redres_env("PATH=/usr/bin:$PATH ", fast_run_args(dir / "out") + " --plots");
  if (r.code == 2 && r.out.find("matplotlib") != std::string::npos &&
      r.out.find("not installed") != std::string::npos) {
    GTEST_SKIP() << "no matplotlib for the python3 on PATH: " << r.out;
  }
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("fig3_profiles.png: it is a symbolic link"), std::string::npos) << r.out;
  EXPECT_EQ(read_text(dir / "victim.txt"), "keep");
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "out" / "fig3_profiles.png"));
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "out" / "summary.json")) << "the run itself is kept";
  std::filesystem::remove_all(dir);
}

TEST(OutputSafety, PrivateDirectoriesAreNewAndOnlyTheirOwnersCanEnterThem) {
  const auto a = make_private_directory("redres-test-"), b = make_private_directory("redres-test-");
  EXPECT_NE(a, b);
  EXPECT_EQ(std::filesystem::status(a).permissions() & std::filesystem::perms::all, std::filesystem::perms::owner_all);
  std::filesystem::remove(a);
  std::filesystem::remove(b);
}

}  // namespace
}  // namespace redres

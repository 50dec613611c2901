// A corpus of bad scenario files (tests/data/scenario_corpus, described in its README.md): each file states on its
// first line where and how it must be refused (`# expect: LINE:COL: TEXT`). `redres validate` must exit with 2 and
// report it there. `redres run` must do the same, and leave an existing output directory exactly as it was and a
// missing one missing.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "cli_util.hpp"

namespace redres {
namespace {

namespace fs = std::filesystem;

struct Expectation {
  fs::path file;
  std::string where;  // "LINE:COL"
  std::string says;   // what the message after "FILE:LINE:COL: " contains; " ... " stands for any text
  bool parsed = false;
};

// Every *.toml file in the corpus, sorted, with the expectation on its first line.
std::vector<Expectation> corpus() {
  std::vector<Expectation> out;
  for (const auto& e : fs::directory_iterator(data_path("scenario_corpus"))) {
    if (e.path().extension() != ".toml") continue;
    Expectation x;
    x.file = e.path();
    std::ifstream in(e.path());
    std::string line;
    std::getline(in, line);
    static const std::regex kExpect(R"(^# expect: (\d+:\d+): (.+)$)");
    std::smatch m;
    if (std::regex_match(line, m, kExpect)) {
      x.where = m[1];
      x.says = m[2];
      x.parsed = true;
    }
    out.push_back(x);
  }
  std::sort(out.begin(), out.end(), [](const Expectation& a, const Expectation& b) { return a.file < b.file; });
  return out;
}

struct Outcome {
  int code = -1;
  std::string err;  // stderr alone
};

// redres() merges stderr into stdout (it appends `2>&1`). This sends stderr to `err_file` before that, and
// `exit $?` keeps the CLI's exit code (the appended `2>&1` then applies to `exit`).
Outcome run_cli(const std::string& args, const fs::path& err_file) {
  const Cli r = redres(args + " 2>'" + err_file.string() + "'; exit $?");
  return {r.code, read_text(err_file)};
}

std::string first_line(const std::string& s) { return s.substr(0, s.find('\n')); }

// Whether `text` from `from` on holds the parts of `says` between its " ... " in order.
bool says_in_order(const std::string& text, std::size_t from, const std::string& says) {
  static const std::string kGap = " ... ";
  std::size_t part = 0;
  while (true) {
    const std::size_t gap = says.find(kGap, part);
    const std::string piece = says.substr(part, gap == std::string::npos ? std::string::npos : gap - part);
    const std::size_t at = text.find(piece, from);
    if (at == std::string::npos) return false;
    if (gap == std::string::npos) return true;
    from = at + piece.size();
    part = gap + kGap.size();
  }
}

// Everything in a directory tree: each entry's kind, bytes and modification time, the root's time included.
using Snapshot = std::map<std::string, std::string>;

Snapshot snapshot(const fs::path& root) {
  Snapshot s;
  const auto stamp = [](const fs::path& p) {
    return std::to_string(fs::last_write_time(p).time_since_epoch().count());
  };
  s["."] = "dir @" + stamp(root);
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    const std::string rel = fs::relative(e.path(), root).string();
    if (e.is_symlink()) {
      s[rel] = "link -> " + fs::read_symlink(e.path()).string();
    } else if (e.is_directory()) {
      s[rel] = "dir @" + stamp(e.path());
    } else {
      s[rel] = "file @" + stamp(e.path()) + ": " + read_text(e.path());
    }
  }
  return s;
}

std::string describe_difference(const Snapshot& before, const Snapshot& after) {
  std::string d;
  for (const auto& [name, what] : before) {
    const auto it = after.find(name);
    if (it == after.end()) {
      d += " removed '" + name + "';";
    } else if (it->second != what) {
      d += " changed '" + name + "';";
    }
  }
  for (const auto& [name, what] : after) {
    if (before.count(name) == 0) d += " added '" + name + "';";
  }
  return d;
}

// An output directory from an earlier run, with a user's file and a sub-directory beside it, all dated an hour ago
// so that a rewrite with the same bytes still shows.
void prepare_existing(const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir / "notes");
  const std::pair<const char*, const char*> files[] = {
      {"summary.json", "{\"name\": \"earlier run\", \"status\": \"complete\"}\n"},
      {"trajectory.csv", "t,theta_1\n0,0.3\n0.01,0.31\n"},
      {"my_analysis.txt", "the user's own notes, not redres's\n"},
      {"notes/plot.py", "print('mine')\n"},
  };
  const auto old = fs::file_time_type::clock::now() - std::chrono::hours(1);
  for (const auto& [name, text] : files) {
    std::ofstream(dir / name, std::ios::binary) << text;
    fs::last_write_time(dir / name, old);
  }
  fs::last_write_time(dir / "notes", old);
  fs::last_write_time(dir, old);
}

struct Result {
  Outcome validate, run_existing, run_missing;
  Snapshot before, after;
  bool missing_created = false;
};

// validate, run into an existing directory, run into a missing one: for one corpus file, in `work`.
Result check(const Expectation& x, const fs::path& work) {
  Result r;
  const std::string file = "'" + x.file.string() + "'";
  const fs::path err = work / "stderr.txt";
  r.validate = run_cli("validate " + file, err);
  const fs::path existing = work / "existing";
  prepare_existing(existing);
  r.before = snapshot(existing);
  r.run_existing = run_cli("run " + file + " --out '" + existing.string() + "'", err);
  r.after = snapshot(existing);
  const fs::path missing = work / "missing";
  fs::remove_all(missing);
  r.run_missing = run_cli("run " + file + " --out '" + missing.string() + "'", err);
  r.missing_created = fs::exists(fs::symlink_status(missing));
  return r;
}

TEST(ScenarioCorpus, HoldsAtLeastFortyBadFilesEachWithItsExpectation) {
  const std::vector<Expectation> c = corpus();
  EXPECT_GE(c.size(), 40u);
  for (const Expectation& x : c) {
    EXPECT_TRUE(x.parsed) << x.file << ": the first line must be '# expect: LINE:COL: TEXT'";
  }
}

TEST(ScenarioCorpus, EveryBadFileIsRefusedAtItsLineAndLeavesTheOutputDirectoryAsItWas) {
  const std::vector<Expectation> c = corpus();
  ASSERT_FALSE(c.empty());
  // The CLI calls run in parallel (three per file), each worker in its own scratch directory; the checks are
  // made here, on the main thread.
  const unsigned workers = std::clamp(std::thread::hardware_concurrency() * 2, 2u, 8u);
  std::vector<Result> results(c.size());
  std::vector<fs::path> work(workers);
  std::atomic<std::size_t> next{0};
  std::vector<std::thread> pool;
  for (unsigned w = 0; w < workers; ++w) {
    work[w] = scratch_dir("scenario_corpus_" + std::to_string(w));
    pool.emplace_back([&, w] {
      for (std::size_t i = next++; i < c.size(); i = next++) results[i] = check(c[i], work[w]);
    });
  }
  for (std::thread& t : pool) t.join();
  for (const fs::path& w : work) fs::remove_all(w);

  for (std::size_t i = 0; i < c.size(); ++i) {
    const Expectation& x = c[i];
    const Result& r = results[i];
    SCOPED_TRACE(x.file.filename().string());
    if (!x.parsed) continue;  // reported by the test above
    const std::string prefix = x.file.string() + ":" + x.where + ": ";
    const std::string line = first_line(r.validate.err);
    EXPECT_EQ(r.validate.code, 2) << r.validate.err;
    EXPECT_EQ(line.rfind(prefix, 0), 0u) << "expected it to start with '" << prefix << "', got: " << line;
    EXPECT_TRUE(says_in_order(line, std::min(prefix.size(), line.size()), x.says))
        << "expected '" << x.says << "' in: " << line;

    EXPECT_EQ(r.run_existing.code, 2) << r.run_existing.err;
    EXPECT_EQ(first_line(r.run_existing.err), line);
    EXPECT_TRUE(r.after == r.before) << "the output directory changed:" << describe_difference(r.before, r.after);

    EXPECT_EQ(r.run_missing.code, 2) << r.run_missing.err;
    EXPECT_EQ(first_line(r.run_missing.err), line);
    EXPECT_FALSE(r.missing_created) << "run created the output directory although the scenario is bad";
  }
}

}  // namespace
}  // namespace redres

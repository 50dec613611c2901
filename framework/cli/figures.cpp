// The figures and the animation of `redres run` and `redres compare` (figures.hpp).
#include "figures.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string_view>

#include "redres/run/run_output.hpp"

extern char** environ;  // the environment plot_run.py inherits (POSIX leaves the declaration to the program)

namespace redres::cli {

namespace {

// plot_run.py: $REDRES_TOOLS_DIR/plot_run.py when set, else <dir of this executable>/REDRES_TOOLS_RELDIR, which is
// where `cmake --install` puts it (<prefix>/bin -> <prefix>/share/redres/tools) and where the build tree keeps a
// copy (build/<preset>/bin -> build/<preset>/share/redres/tools). One relative rule serves both, so an installed
// binary never depends on the source tree it was built from.
std::filesystem::path plot_script() {
  if (const char* env = std::getenv("REDRES_TOOLS_DIR"); env != nullptr && *env != '\0') {
    return std::filesystem::path(env) / "plot_run.py";
  }
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) {
    throw std::runtime_error("cannot locate plot_run.py: /proc/self/exe: " + ec.message() +
                             " (set REDRES_TOOLS_DIR to the directory that holds plot_run.py)");
  }
  return (exe.parent_path() / REDRES_TOOLS_RELDIR / "plot_run.py").lexically_normal();
}

// The first executable `program` in a directory of PATH, as a shell would find it, so that the figures use the
// interpreter the user chose (a virtualenv's, pyenv's or Debian's), never one fixed at build time. Empty if none.
std::filesystem::path find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return {};
  std::string_view rest = path;
  for (;;) {
    const std::size_t colon = rest.find(':');
    std::string dir(rest.substr(0, colon));
    if (dir.empty()) dir = ".";  // POSIX: an empty PATH entry is the working directory
    const std::filesystem::path candidate = std::filesystem::path(dir) / program;
    std::error_code ec;
    if (std::filesystem::is_regular_file(candidate, ec) && access(candidate.c_str(), X_OK) == 0) return candidate;
    if (colon == std::string_view::npos) return {};
    rest.remove_prefix(colon + 1);
  }
}

}  // namespace

Plotter find_plotter(std::string request) {
  Plotter p{find_on_path("python3"), plot_script(), std::move(request)};
  if (p.python.empty()) {
    throw std::runtime_error(p.request + ": python3 not found on PATH; the figures need python3 with matplotlib and " +
                             "numpy (apt-get install python3 python3-matplotlib python3-numpy)");
  }
  if (!std::filesystem::is_regular_file(p.script)) {
    const char* env = std::getenv("REDRES_TOOLS_DIR");
    const std::string hint = env != nullptr && *env != '\0' ? " (REDRES_TOOLS_DIR names a directory without it)"
                                                            : "; redres installs it at " REDRES_TOOLS_RELDIR
                                                              " relative to its executable, or "
                                                              "set REDRES_TOOLS_DIR to the directory that holds it";
    throw std::runtime_error(p.request + ": " + p.script.string() + " not found" + hint);
  }
  return p;
}

namespace {
// Exit code of plot_run.py when matplotlib or numpy cannot be imported (see there).
constexpr int kPlotMissingLibrary = 3;
}  // namespace

void render_plots(const Plotter& p, std::vector<std::string> args, bool quiet, const std::string& outputs) {
  if (quiet) args.emplace_back("--quiet");
  args.insert(args.begin(), {p.python.string(), p.script.string()});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::cout.flush();
  // posix_spawn rather than system(): no shell, so paths need no quoting.
  pid_t pid = 0;
  if (const int err = posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ); err != 0) {
    throw std::runtime_error(p.request + ": cannot start " + p.python.string() + ": " + std::strerror(err));
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error(p.request + ": waiting for plot_run.py: " + std::strerror(errno));
  }
  const std::string kept = "; " + outputs + " were written";
  if (WIFEXITED(status) && WEXITSTATUS(status) == kPlotMissingLibrary) {
    throw std::runtime_error(p.request + ": matplotlib is not installed for " + p.python.string() +
                             ", the python3 on PATH: apt-get install python3-matplotlib python3-numpy (Debian's " +
                             "python3) or pip install matplotlib numpy, or put a python3 that has them first on PATH" +
                             kept);
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const std::string how = WIFEXITED(status) ? "exited with code " + std::to_string(WEXITSTATUS(status))
                                              : "was killed by signal " + std::to_string(WTERMSIG(status));
    throw std::runtime_error(p.request + ": plotting failed: " + p.python.string() + " " + p.script.string() + " " +
                             how + kept);
  }
}

std::filesystem::path render_animation(const Plotter& p, const std::filesystem::path& dir, bool quiet,
                                       const std::string& outputs) {
  const std::filesystem::path files[] = {dir / "animation.mp4", dir / "animation.gif"};
  FileStamp before[2];
  for (int i = 0; i < 2; ++i) {
    (void)remove_earlier_output(dir, files[i].filename().string());  // only an animation an earlier run made
    before[i] = stamp_of(files[i]);
  }
  render_plots(p, {"--animate", dir.string()}, quiet, outputs);
  for (int i = 0; i < 2; ++i) {
    const FileStamp now = stamp_of(files[i]);
    if (now.exists && now.size > 0 && !(now == before[i])) return files[i];
  }
  throw std::runtime_error(p.request + ": plot_run.py --animate wrote neither animation.mp4 nor animation.gif in " +
                           dir.string() + "; " + outputs + " were written");
}

Listing list_files(const std::filesystem::path& dir) {
  Listing files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    if (!e.is_regular_file(ec)) continue;
    files.emplace_back(e.path().filename().string(), e.last_write_time(ec), e.file_size(ec));
  }
  return files;
}

void record_new_files(const std::filesystem::path& dir, const Listing& before) {
  std::vector<std::string> added;
  for (const auto& file : list_files(dir)) {
    if (std::find(before.begin(), before.end(), file) == before.end()) added.push_back(std::get<0>(file));
  }
  add_to_output_manifest(dir, added);
}

}  // namespace redres::cli

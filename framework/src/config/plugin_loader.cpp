#include "redres/config/plugin_loader.hpp"

#include <cxxabi.h>
#include <dlfcn.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <set>
#include <typeinfo>

#include "config/registration_scope.hpp"
#include "redres/common/error.hpp"
#include "redres/config/registry.hpp"

namespace redres {

namespace {

std::vector<std::filesystem::path>& loaded() {
  static std::vector<std::filesystem::path> libs;
  return libs;
}

std::vector<std::filesystem::path> plugin_path_dirs() {
  std::vector<std::filesystem::path> out;
  const char* env = std::getenv("REDRES_PLUGIN_PATH");
  if (env == nullptr) return out;
  std::string rest = env;
  std::size_t start = 0;
  while (start <= rest.size()) {
    const std::size_t colon = rest.find(':', start);
    const std::string dir = rest.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    if (!dir.empty()) out.emplace_back(dir);
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  return out;
}

[[noreturn]] void fail(const SourceLocation& where, const std::filesystem::path& library, const std::string& why) {
  const std::string msg = "plugin library " + library.string() + ": " + why;
  if (where.file.empty()) throw ConfigError({library.string(), 0, 0}, why);
  throw ConfigError(where, msg);
}

// Sets the registration scope for as long as it lives, and restores the previous one however the load ends.
class ScopeGuard {
 public:
  explicit ScopeGuard(RegistrationScope& scope) : previous_(current_registration_scope()) {
    current_registration_scope() = &scope;
  }
  ~ScopeGuard() { current_registration_scope() = previous_; }
  ScopeGuard(const ScopeGuard&) = delete;
  ScopeGuard& operator=(const ScopeGuard&) = delete;

 private:
  RegistrationScope* previous_;
};

// --- the probe: a library's static initialisers run first in a child process -------------------------------------
//
// What a library's initialisers do while dlopen runs them cannot be undone in this process: an exception cannot
// pass through the dynamic loader (the C++ runtime terminates), exit() ends the process with the library's code, a
// crash is a crash. So each library is loaded first in a forked child, which reports how the load ended through a
// pipe; the library is loaded here only when the child's load ended well.

int g_probe_fd = -1;  // the child's end of the pipe

void probe_write(const char* text) {
  if (g_probe_fd < 0) return;
  std::size_t left = std::strlen(text);
  while (left > 0) {
    const ssize_t n = ::write(g_probe_fd, text, left);
    if (n <= 0) return;
    text += n;
    left -= static_cast<std::size_t>(n);
  }
}

// "threw <type>: <what>" of the exception being handled.
std::string thrown(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& x) {
    int status = 0;
    char* name = abi::__cxa_demangle(typeid(x).name(), nullptr, nullptr, &status);
    std::string what = std::string("threw ") + (name != nullptr ? name : typeid(x).name()) + ": " + x.what();
    std::free(name);
    return what;
  } catch (...) {
    return "threw an exception that is not a std::exception";
  }
}

// dlopen(library, RTLD_NOW | RTLD_LOCAL): RTLD_NOW, so that an unresolved symbol is reported here, not at the first
// call in the middle of a run. dlopen is declared not to throw, so a compiler may drop the handler of a try around
// it (clang does), and a library's initialiser's exception would pass it by; called through a volatile pointer of a
// type that may throw, the callers' handlers stay.
void* open_library(const std::filesystem::path& library) {
  using OpenFn = void* (*)(const char*, int);
  static OpenFn volatile dlopen_fn = &::dlopen;
  return dlopen_fn(library.c_str(), RTLD_NOW | RTLD_LOCAL);
}

// An exception that the dynamic loader cannot pass on ends in std::terminate.
[[noreturn]] void probe_terminate() {
  const std::exception_ptr e = std::current_exception();
  probe_write(("T" + (e ? thrown(e) : std::string("ended in std::terminate"))).c_str());
  ::_exit(3);
}

void probe_atexit() {
  probe_write("X");
  ::_exit(4);
}

struct Probe {
  bool ok = true;   // the library may be loaded here
  std::string why;  // else: what its initialisers did
};

constexpr auto kProbeTimeout = std::chrono::seconds(60);

Probe probe_library(const std::filesystem::path& library) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) return {};  // cannot probe: load as before
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return {};
  }
  if (pid == 0) {  // the child: load, report, end without running this process's exit handlers
    ::close(fds[0]);
    g_probe_fd = fds[1];
    std::set_terminate(probe_terminate);
    std::atexit(probe_atexit);
    RegistrationScope scope{library.string(), {}, 0};
    current_registration_scope() = &scope;
    try {
      void* handle = open_library(library);
      probe_write(handle != nullptr ? "K" : "D");
    } catch (...) {  // an exception that came through dlopen
      probe_write(("T" + thrown(std::current_exception())).c_str());
      ::_exit(3);
    }
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string report;
  const auto deadline = std::chrono::steady_clock::now() + kProbeTimeout;
  bool timed_out = false;
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int r = ::poll(&p, 1, static_cast<int>(std::min<long long>(left, 1000)));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) continue;
    char buffer[512];
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // the child closed the pipe: it ended
    if (report.size() < 4096) report.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  if (timed_out) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out) {
    return {false, "its static initialisers did not finish within " + std::to_string(kProbeTimeout.count()) +
                       " s (loaded first in a separate process, which was stopped)"};
  }
  if (!report.empty() && (report[0] == 'K' || report[0] == 'D')) return {};  // loaded, or dlopen's own error
  if (!report.empty() && report[0] == 'T') {
    return {false, "its static initialisers " + report.substr(1) + "; nothing of it was loaded"};
  }
  if (!report.empty() && report[0] == 'X') {
    return {false, "its static initialisers called exit() while loading; nothing of it was loaded"};
  }
  if (WIFSIGNALED(status)) {
    return {false, "its static initialisers crashed (signal " + std::to_string(WTERMSIG(status)) + ", " +
                       strsignal(WTERMSIG(status)) + "); nothing of it was loaded"};
  }
  if (WIFEXITED(status)) {
    return {false, "its static initialisers ended the process (_exit(" + std::to_string(WEXITSTATUS(status)) +
                       ")); nothing of it was loaded"};
  }
  return {};
}

// A file at `library` that dlopen may open, or why not: "no such file" only when there is none.
std::string unreadable(const std::filesystem::path& library) {
  struct stat st {};
  if (::stat(library.c_str(), &st) != 0) {
    const int err = errno;
    if (err == ENOENT || err == ENOTDIR) {
      return "no such file (a path relative to the file that names it, or a name found in REDRES_PLUGIN_PATH)";
    }
    return std::string("cannot be read: ") + std::strerror(err);
  }
  if (!S_ISREG(st.st_mode)) return S_ISDIR(st.st_mode) ? "is a directory, not a library" : "is not a regular file";
  if (::access(library.c_str(), R_OK) != 0) return std::string("cannot be read: ") + std::strerror(errno);
  return "";
}

// A REDRES_PLUGIN_PATH directory that others could write libraries into: said once per directory.
void warn_if_open(const std::filesystem::path& dir) {
  static std::set<std::string> warned;
  std::string why;
  struct stat st {};
  if (dir.is_relative()) {
    why = "is relative: libraries are loaded from whatever directory redres runs in";
  } else if (::stat(dir.c_str(), &st) == 0 && (st.st_mode & S_IWOTH) != 0) {
    why = "is writable by every user: anyone can put a library there that redres then runs";
  } else {
    // A directory others may rename away (a parent every user can write, without the sticky bit) is as open.
    for (std::filesystem::path p = dir.parent_path(); !p.empty(); p = p.parent_path()) {
      struct stat up {};
      if (::stat(p.c_str(), &up) == 0 && (up.st_mode & S_IWOTH) != 0 && (up.st_mode & S_ISVTX) == 0) {
        why = "is inside '" + printable(p.string()) +
              "', which every user can write to (without the sticky bit): anyone can put another directory in its "
              "place";
        break;
      }
      if (p == p.root_path()) break;
    }
  }
  if (why.empty() || !warned.insert(dir.string()).second) return;
  std::cerr << "redres: warning: REDRES_PLUGIN_PATH directory '" << printable(dir.string()) << "' " << why << "\n";
}

}  // namespace

const std::vector<std::filesystem::path>& loaded_plugin_libraries() { return loaded(); }

std::filesystem::path resolve_plugin_library(const std::string& name, const std::filesystem::path& base_dir) {
  const std::filesystem::path p = name;
  if (p.is_absolute()) return p;
  const std::filesystem::path local = base_dir / p;
  std::error_code ec;  // a directory that cannot be searched holds nothing here; load_plugin_library says why
  if (name.find('/') != std::string::npos || std::filesystem::exists(local, ec)) return local;
  for (const auto& dir : plugin_path_dirs()) {
    if (std::filesystem::exists(dir / p, ec)) {
      warn_if_open(dir);
      return dir / p;
    }
  }
  return local;
}

void load_plugin_library(const std::filesystem::path& library, const SourceLocation& where) {
  if (const std::string why = unreadable(library); !why.empty()) fail(where, library, why);
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::canonical(library, ec);
  if (ec) fail(where, library, "cannot be resolved: " + ec.message());
  if (std::find(loaded().begin(), loaded().end(), canonical) != loaded().end()) return;

  // A library every user may write is code anyone can change: said once per library.
  static std::set<std::string> open_files;
  struct stat st {};
  if (::stat(canonical.c_str(), &st) == 0 && (st.st_mode & S_IWOTH) != 0 && open_files.insert(canonical).second) {
    std::cerr << "redres: warning: plugin library '" << printable(canonical.string())
              << "' is writable by every user: anyone can change the code redres runs\n";
  }
  const Probe probe = probe_library(canonical);
  if (!probe.ok) fail(where, library, probe.why);

  RegistrationScope scope{canonical.string(), {}, 0};
  void* handle = nullptr;
  {
    const ScopeGuard guard(scope);
    try {
      handle = open_library(canonical);
    } catch (...) {  // the probe's load went well, this one did not: the library's initialisers differ each time
      for (RegistryBase* r : RegistryBase::all()) r->remove_origin(canonical.string());
      fail(where, library, "its static initialisers " + thrown(std::current_exception()));
    }
  }
  if (handle == nullptr) {
    const char* err = dlerror();
    fail(where, library, std::string("cannot be loaded: ") + (err != nullptr ? err : "unknown dlopen error"));
  }
  std::string why;
  if (!scope.errors.empty()) {
    for (const auto& e : scope.errors) why += (why.empty() ? "" : "; ") + e;
  } else if (scope.added == 0) {
    why = "registered no plugin (does it call a registry's add() or add_plugin() from a namespace-scope object?)";
  }
  if (!why.empty()) {
    for (RegistryBase* r : RegistryBase::all()) r->remove_origin(canonical.string());
    // The library stays mapped: its static objects may still be referenced by the C++ runtime's exit handlers.
    fail(where, library, why);
  }
  loaded().push_back(canonical);
}

int load_plugin_path() {
  int n = 0;
  for (const auto& dir : plugin_path_dirs()) {
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) {
      throw ConfigError({"REDRES_PLUGIN_PATH", 0, 0}, "'" + dir.string() + "' is not a directory");
    }
    warn_if_open(dir);
    std::vector<std::filesystem::path> libs;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
      if (e.is_regular_file() && e.path().extension() == ".so") libs.push_back(e.path());
    }
    std::sort(libs.begin(), libs.end());
    for (const auto& lib : libs) {
      load_plugin_library(lib, {"REDRES_PLUGIN_PATH", 0, 0});
      ++n;
    }
  }
  return n;
}

void load_plugins_from(const TableReader& root) {
  if (!root.has("plugins")) return;
  const std::vector<std::string> names = root.strings("plugins");
  const toml::array* arr = root.raw().get("plugins")->as_array();
  for (std::size_t k = 0; k < names.size(); ++k) {
    const std::filesystem::path lib = resolve_plugin_library(names[k], root.file().path.parent_path());
    load_plugin_library(lib, location_of(root.file(), *arr->get(k)));
  }
}

}  // namespace redres

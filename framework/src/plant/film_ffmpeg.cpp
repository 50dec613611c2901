// A film's MP4: frames piped to ffmpeg (film_encoder.hpp).

#if REDRES_HAVE_MUJOCO

#include <fcntl.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <system_error>

#include "plant/film_encoder.hpp"

extern char** environ;

namespace redres::plant_detail {

namespace {

// The end of a file's text, at most `bytes` of it, from an open descriptor.
std::string tail_of(int fd, long bytes) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return "";
  const long start = std::max(0L, static_cast<long>(st.st_size) - bytes);
  std::string text(static_cast<std::size_t>(st.st_size - start), '\0');
  const ssize_t got = ::pread(fd, text.data(), text.size(), start);
  text.resize(got > 0 ? static_cast<std::size_t>(got) : 0);
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  return text;
}

// ffmpeg, reading raw RGB frames from a socket on its standard input and writing the MP4 itself (`-n`: it never
// overwrites). A socket rather than a pipe: send(MSG_NOSIGNAL) reports an ffmpeg that died as an error instead of
// raising SIGPIPE in the caller's process. Its messages go to an unlinked temporary file, read back on failure.
class FfmpegEncoder final : public Encoder {
 public:
  FfmpegEncoder(const std::filesystem::path& ffmpeg, const std::filesystem::path& output, int width, int height,
                double fps)
      : output_(output) {
    std::string errors = (std::filesystem::temp_directory_path() / "redres_ffmpeg_XXXXXX").string();
    errors_ = ::mkostemp(errors.data(), O_CLOEXEC);
    if (errors_ < 0)
      throw std::runtime_error("film: cannot create a temporary file for ffmpeg's messages: " +
                               std::string(std::strerror(errno)));
    ::unlink(errors.c_str());
    int sockets[2];
    if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sockets) != 0) {
      const int error = errno;
      ::close(errors_);
      throw std::runtime_error("film: cannot make a socket for ffmpeg: " + std::string(std::strerror(error)));
    }
    input_ = sockets[0];
    char size[64], rate[64];
    std::snprintf(size, sizeof size, "%dx%d", width, height);
    std::snprintf(rate, sizeof rate, "%.10g", fps);
    // "file:" and an absolute path: a name that starts with '-' or holds a ':' is still a file name to ffmpeg.
    const std::string target = "file:" + std::filesystem::absolute(output).string();
    std::vector<std::string> args = {
        ffmpeg.string(), "-hide_banner", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt",
        "rgb24",         "-s",           size,        "-r",    rate, "-i",       "-",
        "-pix_fmt",      "yuv420p",      "-n",        target};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, sockets[1], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions, errors_, STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, errors_, STDERR_FILENO);
    const int spawned = ::posix_spawn(&pid_, ffmpeg.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(sockets[1]);
    if (spawned != 0) {
      pid_ = -1;
      close_all();
      throw std::runtime_error("film: cannot start " + ffmpeg.string() + ": " + std::strerror(spawned));
    }
  }
  FfmpegEncoder(const FfmpegEncoder&) = delete;
  FfmpegEncoder& operator=(const FfmpegEncoder&) = delete;

  // A film that failed half way: ffmpeg is stopped and its partial MP4 removed.
  ~FfmpegEncoder() override {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      wait();
      std::error_code ignored;
      if (std::filesystem::is_regular_file(std::filesystem::symlink_status(output_, ignored)))
        std::filesystem::remove(output_, ignored);
    }
    close_all();
  }

  void add(const std::vector<unsigned char>& rgb) override {
    const unsigned char* p = rgb.data();
    std::size_t left = rgb.size();
    while (left > 0 && !broken_) {
      const ssize_t sent = ::send(input_, p, left, MSG_NOSIGNAL);
      if (sent < 0) {
        if (errno == EINTR) continue;
        broken_ = true;  // ffmpeg stopped reading: finish() reports its exit status
        break;
      }
      p += sent;
      left -= static_cast<std::size_t>(sent);
    }
    if (broken_) finish();
  }

  void finish() override {
    if (input_ >= 0) ::close(input_);
    input_ = -1;
    const int status = wait();
    pid_ = -1;
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && !broken_) {
      close_all();
      return;
    }
    std::string how = WIFEXITED(status)     ? "exited with status " + std::to_string(WEXITSTATUS(status))
                      : WIFSIGNALED(status) ? "was killed by signal " + std::to_string(WTERMSIG(status))
                                            : "failed";
    if (broken_ && WIFEXITED(status) && WEXITSTATUS(status) == 0) how = "stopped reading the frames";
    const std::string messages = tail_of(errors_, 2000);
    close_all();
    std::error_code ignored;
    const bool made = std::filesystem::is_regular_file(std::filesystem::symlink_status(output_, ignored));
    if (made) std::filesystem::remove(output_, ignored);
    throw std::runtime_error("film: ffmpeg " + how + " writing " + output_.string() +
                             (messages.empty() ? std::string(" (no messages)") : ":\n" + messages));
  }

 private:
  int wait() {
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
  }
  void close_all() noexcept {
    if (input_ >= 0) ::close(input_);
    if (errors_ >= 0) ::close(errors_);
    input_ = errors_ = -1;
  }

  std::filesystem::path output_;
  pid_t pid_ = -1;
  int input_ = -1;
  int errors_ = -1;
  bool broken_ = false;
};

}  // namespace

std::filesystem::path find_on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return {};
  const std::string_view all(path);
  std::size_t begin = 0;
  while (begin <= all.size()) {
    const std::size_t end = std::min(all.find(':', begin), all.size());
    const std::string directory(all.substr(begin, end - begin));
    const std::filesystem::path candidate = std::filesystem::path(directory.empty() ? "." : directory) / name;
    struct stat st {};
    if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(candidate.c_str(), X_OK) == 0)
      return candidate;
    begin = end + 1;
  }
  return {};
}

std::unique_ptr<Encoder> make_ffmpeg_encoder(const std::filesystem::path& ffmpeg, const std::filesystem::path& output,
                                             int width, int height, double fps) {
  return std::make_unique<FfmpegEncoder>(ffmpeg, output, width, height, fps);
}

}  // namespace redres::plant_detail

#endif  // REDRES_HAVE_MUJOCO

#include "common/input_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "redres/common/error.hpp"

namespace redres {

const char* file_kind(mode_t mode) {
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

namespace {

// Closes the descriptor on every path out.
struct Descriptor {
  int fd = -1;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::string read_input_file(const std::filesystem::path& path, const char* what, std::uintmax_t max_bytes) {
  const SourceLocation where{path.string(), 0, 0};
  const auto fail = [&](const std::string& message) { throw ConfigError(where, std::string(what) + " " + message); };
  // O_NONBLOCK: opening a FIFO for reading must not wait for a writer; it is rejected below by its type.
  Descriptor d;
  d.fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (d.fd < 0) {
    const int e = errno;
    if (e == ENOENT) fail("does not exist");
    fail(std::string("cannot be opened: ") + std::strerror(e));
  }
  struct stat st {};
  if (::fstat(d.fd, &st) != 0) fail(std::string("cannot be read: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) fail("is " + std::string(file_kind(st.st_mode)) + ", expected a regular file");
  const auto size = static_cast<std::uintmax_t>(st.st_size);
  if (size > max_bytes) {
    fail("is " + std::to_string(size) + " bytes, more than the " + std::to_string(max_bytes) +
         " bytes an input file may have");
  }
  // Read at most max_bytes + 1 bytes, whatever fstat said: a file that grows while it is read is caught too.
  std::string out(static_cast<std::size_t>(size), '\0');
  std::size_t got = 0;
  while (true) {
    if (got == out.size()) {
      if (out.size() > max_bytes) break;
      out.resize(std::min<std::uintmax_t>(max_bytes + 1, out.size() + 4096));
    }
    const ssize_t n = ::read(d.fd, out.data() + got, out.size() - got);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail(std::string("cannot be read: ") + std::strerror(errno));
    }
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  if (got > max_bytes) {
    fail("grew past the " + std::to_string(max_bytes) + " bytes an input file may have while it was read");
  }
  out.resize(got);
  return out;
}

}  // namespace redres

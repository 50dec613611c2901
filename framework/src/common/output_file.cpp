#include "redres/common/output_file.hpp"

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/input_file.hpp"

namespace redres {

namespace {

// A name no other process or thread picks: the pid, a per-process random word and a counter.
std::string fresh_suffix() {
  static const std::uint64_t word = [] {
    std::random_device rd;
    return (std::uint64_t{rd()} << 32) ^ rd();
  }();
  static std::atomic<std::uint64_t> counter{0};
  char text[64];
  std::snprintf(text, sizeof text, "%ld.%016llx.%llu", static_cast<long>(::getpid()),
                static_cast<unsigned long long>(word), static_cast<unsigned long long>(counter++));
  return text;
}

}  // namespace

void require_replaceable(const std::filesystem::path& file, const std::string& what) {
  struct stat st {};
  if (::lstat(file.c_str(), &st) != 0) return;  // missing: fine
  if (S_ISREG(st.st_mode)) return;
  throw std::runtime_error(what + " " + file.string() + " is " + file_kind(st.st_mode) +
                           "; redres writes only regular files and never replaces or follows anything else (remove "
                           "it, or choose another output directory)");
}

StagedFile::StagedFile(std::filesystem::path final_name) : final_(std::move(final_name)) {
  require_replaceable(final_, "cannot write");
  const std::filesystem::path dir = final_.has_parent_path() ? final_.parent_path() : std::filesystem::path(".");
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::filesystem::path temp = dir / ("." + final_.filename().string() + ".tmp." + fresh_suffix());
    // O_EXCL with O_CREAT fails on any existing name, a symbolic link included; O_NOFOLLOW says so twice.
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0) {
      if (errno == EEXIST) continue;
      throw std::runtime_error("cannot write " + final_.string() + ": " + std::strerror(errno));
    }
    file_ = ::fdopen(fd, "w");
    if (file_ == nullptr) {
      const int e = errno;
      ::close(fd);
      ::unlink(temp.c_str());
      throw std::runtime_error("cannot write " + final_.string() + ": " + std::strerror(e));
    }
    temp_ = std::move(temp);
    return;
  }
  throw std::runtime_error("cannot write " + final_.string() + ": no free temporary name beside it");
}

StagedFile::StagedFile(StagedFile&& other) noexcept
    : final_(std::move(other.final_)),
      temp_(std::move(other.temp_)),
      file_(std::exchange(other.file_, nullptr)),
      failed_(other.failed_),
      error_(other.error_),
      installed_(std::exchange(other.installed_, true)) {
  other.temp_.clear();
}

StagedFile::~StagedFile() {
  if (!installed_) discard();
}

void StagedFile::discard() noexcept {
  if (file_ != nullptr) std::fclose(file_);
  file_ = nullptr;
  if (!temp_.empty()) ::unlink(temp_.c_str());  // only the name this object created
  temp_.clear();
}

void StagedFile::write(std::string_view bytes) {
  if (file_ == nullptr || failed_) return;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    failed_ = true;
    error_ = errno;
  }
}

void StagedFile::fail(const std::string& why) {
  discard();
  throw std::runtime_error("cannot write " + final_.string() + ": " + why);
}

void StagedFile::finish() {
  if (file_ == nullptr) return;
  if (!failed_ && std::ferror(file_) != 0) {
    failed_ = true;
    error_ = errno;
  }
  if (!failed_ && std::fflush(file_) != 0) {
    failed_ = true;
    error_ = errno;
  }
  std::FILE* f = std::exchange(file_, nullptr);
  if (std::fclose(f) != 0 && !failed_) {
    failed_ = true;
    error_ = errno;
  }
  if (failed_) fail(error_ != 0 ? std::strerror(error_) : "write error");
}

void StagedFile::install() {
  finish();
  if (installed_) return;
  try {
    require_replaceable(final_, "cannot write");  // not turned into a link or a directory meanwhile
  } catch (const std::exception&) {
    discard();
    throw;
  }
  if (std::rename(temp_.c_str(), final_.c_str()) != 0) fail(std::strerror(errno));
  installed_ = true;
}

void write_text_file(const std::filesystem::path& file, std::string_view text) {
  StagedFile out(file);
  out.write(text);
  out.install();
}

FileStamp stamp_of(const std::filesystem::path& file) {
  struct stat st {};
  if (::lstat(file.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return {};
  FileStamp s;
  s.exists = true;
  s.size = static_cast<std::uintmax_t>(st.st_size);
  s.mtime_ns = static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
  s.inode = static_cast<std::uint64_t>(st.st_ino);
  return s;
}

bool owned_by_me_alone(const std::filesystem::path& file) {
  struct stat st {};
  return ::lstat(file.c_str(), &st) == 0 && st.st_uid == ::geteuid() && (st.st_mode & (S_IWGRP | S_IWOTH)) == 0;
}

bool remove_if_unchanged(const std::filesystem::path& file, const FileStamp& expected) {
  if (!expected.exists || !owned_by_me_alone(file)) return false;
  const FileStamp now = stamp_of(file);
  if (!(now == expected)) return false;
  return ::unlink(file.c_str()) == 0;
}

std::filesystem::path make_private_directory(const std::string& prefix) {
  std::error_code ec;
  const std::filesystem::path base = std::filesystem::temp_directory_path(ec);
  if (ec) throw std::runtime_error("cannot find the temporary directory: " + ec.message());
  std::string name = (base / (prefix + "XXXXXX")).string();
  std::vector<char> buffer(name.begin(), name.end());
  buffer.push_back('\0');
  if (::mkdtemp(buffer.data()) == nullptr) {
    throw std::runtime_error("cannot create a private directory " + name + ": " + std::strerror(errno));
  }
  return std::filesystem::path(buffer.data());
}

}  // namespace redres

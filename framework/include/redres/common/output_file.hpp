#pragma once
/// @file
/// Writing an output file so that it cannot be turned against the user. A StagedFile is created exclusively, under
/// a fresh random name beside its final name (mkostemp: O_CREAT | O_EXCL, so a file or symbolic link planted there
/// is never opened), written, checked, and renamed into place. Its final name must be missing or a regular file: a
/// symbolic link, a directory or a device there is refused with a message, never replaced or written through. A
/// failed write (a full disk) removes the temporary it created and leaves the old file as it was.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace redres {

/// One output file, staged beside its final name. Typical use: construct, write() or stream(), finish(), then
/// install(); several files can be finished first and installed after, so that a failure in any leaves all the old
/// files. Destroying a StagedFile that was not installed removes its temporary.
class StagedFile {
 public:
  /// Creates the temporary in final_name's directory (which must exist). std::runtime_error "cannot write FILE:
  /// ..." when it cannot, or when final_name exists and is not a regular file.
  explicit StagedFile(std::filesystem::path final_name);
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;
  StagedFile(StagedFile&& other) noexcept;
  StagedFile& operator=(StagedFile&&) = delete;
  ~StagedFile();

  /// The open stream (buffered); null after finish().
  [[nodiscard]] std::FILE* stream() const { return file_; }
  /// Appends bytes; a write error is remembered and reported by finish().
  void write(std::string_view bytes);
  /// Flushes and closes; std::runtime_error naming the final file (and errno's text) when any write failed.
  void finish();
  /// Renames the finished temporary onto the final name; std::runtime_error when the final name has meanwhile
  /// become something other than a regular file, or the rename fails.
  void install();

  [[nodiscard]] const std::filesystem::path& final_name() const { return final_; }

 private:
  [[noreturn]] void fail(const std::string& why);
  void discard() noexcept;  // closes the stream and removes the temporary, if any
  std::filesystem::path final_;
  std::filesystem::path temp_;
  std::FILE* file_ = nullptr;
  bool failed_ = false;
  int error_ = 0;
  bool installed_ = false;
};

/// Writes `text` to `file` through a StagedFile: a reader never sees half of it, and a failed write leaves the old
/// file. std::runtime_error naming the file on failure.
void write_text_file(const std::filesystem::path& file, std::string_view text);

/// Throws std::runtime_error "<what> FILE is a symbolic link ..." (or a directory, or another kind of file) when
/// `file` exists and is not a regular file: redres replaces only regular files.
void require_replaceable(const std::filesystem::path& file, const std::string& what);

/// What identifies a file redres wrote: its size, modification time and inode, as lstat gives them (a symbolic
/// link is never followed). `exists` is false when there is no regular file at `file`.
struct FileStamp {
  bool exists = false;
  std::uintmax_t size = 0;
  std::int64_t mtime_ns = 0;
  std::uint64_t inode = 0;
  friend bool operator==(const FileStamp&, const FileStamp&) = default;
};
[[nodiscard]] FileStamp stamp_of(const std::filesystem::path& file);

/// Whether `file` (not followed if a link) belongs to this process's user and neither its group nor others may
/// write it.
[[nodiscard]] bool owned_by_me_alone(const std::filesystem::path& file);

/// Removes `file` only when it is a regular file (not a symbolic link) of this user's, that only this user may
/// write, whose stamp is `expected`: a file that was replaced, edited or planted since redres wrote it stays.
/// Returns whether it was removed.
bool remove_if_unchanged(const std::filesystem::path& file, const FileStamp& expected);

/// A new directory only this user can enter (mode 0700), under the system's temporary directory, named
/// `<prefix>XXXXXX` with a random suffix (mkdtemp). std::runtime_error when it cannot be created.
[[nodiscard]] std::filesystem::path make_private_directory(const std::string& prefix);

}  // namespace redres

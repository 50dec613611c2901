#pragma once
/// @file
/// Reading an input file (a robot or scenario TOML file, a URDF file, a CSV table) whole, safely: it must be a
/// regular file no larger than a stated bound, and it is read with a bounded read. A directory, a FIFO, a device
/// (`/dev/zero`) or an oversized file is a ConfigError that says which, before anything is read, and a FIFO never
/// blocks the reader.

#include <sys/types.h>

#include <cstdint>
#include <filesystem>
#include <string>

namespace redres {

/// The largest input file read, in bytes (16 MiB). Robot and scenario files are a few kilobytes; the largest
/// tables and URDF files in common use are well below this.
inline constexpr std::uintmax_t kMaxInputFileBytes = std::uintmax_t{16} << 20;

/// What a file that is not a regular file is, for messages ("a directory", "a symbolic link", "a FIFO (named pipe)",
/// ...), from its `st_mode`.
[[nodiscard]] const char* file_kind(mode_t mode);

/// The contents of `path`, of at most `max_bytes` bytes. `what` names the kind of file in messages ("robot file",
/// "CSV file"). Throws ConfigError at `path` when it does not exist, cannot be read, is not a regular file, or is
/// larger than `max_bytes`.
[[nodiscard]] std::string read_input_file(const std::filesystem::path& path, const char* what,
                                          std::uintmax_t max_bytes = kMaxInputFileBytes);

}  // namespace redres

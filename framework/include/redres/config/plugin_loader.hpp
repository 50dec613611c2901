#pragma once
/// @file
/// Plugins from shared libraries, loaded at run time into the stock `redres` (and any program using the library).
/// A plugin library is an ordinary shared library built against the installed package (find_package(redres),
/// target redres::framework) whose .cpp files register plugins exactly as the built-in ones do; see
/// docs/writing_plugins.md and examples/custom_plugin/.
///
/// Where libraries come from:
/// - `plugins = ["build/libmy_plugins.so"]` in a scenario or robot file (relative to that file);
/// - `redres --plugin PATH` (repeatable);
/// - REDRES_PLUGIN_PATH: directories separated by ':'; every `*.so` in them is loaded by the CLI at start, and a
///   bare library name (no '/') that is not found relative to the naming file is looked up there.
///
/// A library that cannot be loaded, registers no plugin, or registers a name that exists already is a ConfigError
/// that names the library (and the file:line:col that named it); its registrations are undone.

#include <filesystem>
#include <string>
#include <vector>

#include "redres/common/error.hpp"
#include "redres/config/config.hpp"
#include "redres/config/toml_reader.hpp"

namespace redres {

/// Loads one plugin library (once per canonical path; later calls are no-ops). `where` is what named it.
void load_plugin_library(const std::filesystem::path& library, const SourceLocation& where = {});

/// Resolves a library named in a file or on the command line: a path with a '/' (relative to `base_dir`), else
/// `base_dir`/name if it exists, else the first REDRES_PLUGIN_PATH directory that holds it.
[[nodiscard]] std::filesystem::path resolve_plugin_library(const std::string& name,
                                                           const std::filesystem::path& base_dir);

/// Loads every `*.so` in the REDRES_PLUGIN_PATH directories (sorted by name); returns how many were loaded.
int load_plugin_path();

/// Reads the optional `plugins` key of a scenario or robot file (an array of library paths, relative to the file)
/// and loads them.
void load_plugins_from(const TableReader& root);

/// The `plugins` key of a file's schema (scenario, robot): an array of libraries, loaded (load_plugins_from) when
/// the key is read, before the keys after it that may name their plugins. `help` says what they may provide.
template <class C>
[[nodiscard]] Field<C> plugins_entry(std::string help) {
  return entry<C>("plugins", "array of strings", "", "[]", std::move(help),
                  [](const TableReader& r, C& /*c*/) { load_plugins_from(r); });
}

/// The libraries loaded so far (canonical paths), in load order.
[[nodiscard]] const std::vector<std::filesystem::path>& loaded_plugin_libraries();

}  // namespace redres

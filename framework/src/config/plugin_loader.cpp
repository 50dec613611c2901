#include "redres/config/plugin_loader.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>

#include "config/registration_scope.hpp"
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

}  // namespace

const std::vector<std::filesystem::path>& loaded_plugin_libraries() { return loaded(); }

std::filesystem::path resolve_plugin_library(const std::string& name, const std::filesystem::path& base_dir) {
  const std::filesystem::path p = name;
  if (p.is_absolute()) return p;
  const std::filesystem::path local = base_dir / p;
  if (name.find('/') != std::string::npos || std::filesystem::exists(local)) return local;
  for (const auto& dir : plugin_path_dirs()) {
    if (std::filesystem::exists(dir / p)) return dir / p;
  }
  return local;
}

void load_plugin_library(const std::filesystem::path& library, const SourceLocation& where) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(library, ec)) {
    fail(where, library,
         "no such file (a path relative to the file that names it, or a name found in "
         "REDRES_PLUGIN_PATH)");
  }
  const std::filesystem::path canonical = std::filesystem::canonical(library, ec);
  if (std::find(loaded().begin(), loaded().end(), canonical) != loaded().end()) return;

  RegistrationScope scope{canonical.string(), {}, 0};
  RegistrationScope* const previous = current_registration_scope();
  current_registration_scope() = &scope;
  // RTLD_NOW: an unresolved symbol is reported here, not at the first call in the middle of a run.
  void* handle = dlopen(canonical.c_str(), RTLD_NOW | RTLD_LOCAL);
  current_registration_scope() = previous;
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

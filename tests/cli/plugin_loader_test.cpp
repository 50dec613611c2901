// Plugin libraries in the stock CLI: named by a scenario (`plugins = [...]`, relative to the file), by --plugin,
// or found through REDRES_PLUGIN_PATH; a library that cannot be loaded, registers a name that exists, or registers
// nothing is exit 2 with the library (and the file:line:col that named it) in the message.

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "cli_util.hpp"
#include "scenario_text.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

const std::string kPlugin = REDRES_TEST_PLUGIN;

// A scenario in `dir` that uses the test plugin's objective and constraint; `plugins` is the TOML array text.
std::filesystem::path write_scenario(const std::filesystem::path& dir, const std::string& plugins) {
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "scenario.toml")
      << "plugins = " << plugins << "\n"
      << robot_line("paper_pushrod_6dof.toml")
      << "theta0 = [\"pi/4\", \"pi/12\", \"pi/12\", \"pi/12\", \"pi/36\", \"pi/36\"]\nduration = 2.0\nstep = 0.01\n"
      << "[path]\ntype = \"line\"\ndelta = [-0.02, 0.0]\n"
      << objective_entry("test_damping", "gain = 2.0\n") << constraint_entry("task_tracking")
      << constraint_entry("test_cap", "cap = 0.2\n") << "[solver]\nengine = \"newton\"\n";
  return dir / "scenario.toml";
}

TEST(PluginLoader, AScenarioNamesALibraryRelativeToItself) {
  const auto dir = scratch("plugin_relative");
  std::filesystem::create_directories(dir / "lib");
  std::filesystem::copy_file(kPlugin, dir / "lib" / "libmine.so");
  const auto file = write_scenario(dir, "[\"lib/libmine.so\"]");
  const Cli r = redres("run '" + file.string() + "' --out '" + (dir / "out").string() + "' --quiet");
  EXPECT_EQ(r.code, 0) << r.out;
  std::ifstream summary(dir / "out" / "summary.json");
  std::stringstream text;
  text << summary.rdbuf();
  EXPECT_NE(text.str().find("\"failures\": 0"), std::string::npos) << text.str();
  std::filesystem::remove_all(dir);
}

TEST(PluginLoader, PluginOptionAndSearchPathLoadLibrariesForEveryCommand) {
  const Cli listed = redres("--plugin '" + kPlugin + "' plugins");
  EXPECT_EQ(listed.code, 0) << listed.out;
  EXPECT_NE(listed.out.find("test_damping   (from "), std::string::npos) << listed.out;
  EXPECT_NE(listed.out.find("test_cap   (from "), std::string::npos) << listed.out;
  const Cli without = redres("plugins");
  EXPECT_EQ(without.out.find("test_damping"), std::string::npos);

  const auto dir = scratch("plugin_path");
  std::filesystem::create_directories(dir / "search");
  std::filesystem::copy_file(kPlugin, dir / "search" / "libmine.so");
  // A bare name in the scenario, found through REDRES_PLUGIN_PATH (which also loads it at start: loaded once).
  const auto file = write_scenario(dir, "[\"libmine.so\"]");
  const Cli r = redres("validate '" + file.string() + "'");
  EXPECT_EQ(r.code, 2) << "the bare name must not be found without the search path: " << r.out;
  const std::string env = "REDRES_PLUGIN_PATH='" + (dir / "search").string() + "' ";
  const Cli found = redres_env(env, "validate '" + file.string() + "'");
  EXPECT_EQ(found.code, 0) << found.out;
  const Cli check = redres_env(env, "plugins --check");
  EXPECT_EQ(check.code, 0) << check.out;
  EXPECT_NE(check.out.find("checks passed, 0 failed"), std::string::npos) << check.out;
  std::filesystem::remove_all(dir);
}

TEST(PluginLoader, BadLibrariesAreExitTwoNamingTheLibrary) {
  const Cli dup = redres("--plugin '" + std::string(REDRES_TEST_PLUGIN_DUPLICATE) + "' plugins");
  EXPECT_EQ(dup.code, 2);
  EXPECT_NE(dup.out.find(REDRES_TEST_PLUGIN_DUPLICATE), std::string::npos) << dup.out;
  EXPECT_NE(dup.out.find("duplicate objective type 'manipulability': already registered by built-in"),
            std::string::npos)
      << dup.out;

  const Cli empty = redres("--plugin '" + std::string(REDRES_TEST_PLUGIN_EMPTY) + "' plugins");
  EXPECT_EQ(empty.code, 2);
  EXPECT_NE(empty.out.find("registered no plugin"), std::string::npos) << empty.out;

  const auto dir = scratch("plugin_bad");
  // Not a shared library at all.
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "libjunk.so") << "not an ELF file\n";
  const Cli junk = redres("validate '" + write_scenario(dir, "[\"libjunk.so\"]").string() + "'");
  EXPECT_EQ(junk.code, 2);
  EXPECT_NE(junk.out.find("scenario.toml:1:12: plugin library"), std::string::npos) << junk.out;
  EXPECT_NE(junk.out.find("cannot be loaded"), std::string::npos) << junk.out;
  // Missing.
  const Cli missing = redres("validate '" + write_scenario(dir, "[\"nowhere/libnone.so\"]").string() + "'");
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.out.find("scenario.toml:1:12: plugin library"), std::string::npos) << missing.out;
  EXPECT_NE(missing.out.find("no such file"), std::string::npos) << missing.out;
  std::filesystem::remove_all(dir);
}

// Static initialisers that throw, or call exit(0), after registering a plugin: the library is refused naming it and
// the file:line:col that named it, nothing of it stays registered, and redres goes on (here, to say so, exit 2).
TEST(PluginLoader, InitialisersThatThrowOrExitAreRefusedAndLeaveNothingRegistered) {
  const auto dir = scratch("plugin_hostile");
  for (const auto& [library, says] :
       {std::pair<std::string, std::string>{REDRES_TEST_PLUGIN_THROW,
                                            "its static initialisers threw std::runtime_error: the plugin's "
                                            "configuration file is missing; nothing of it was loaded"},
        {REDRES_TEST_PLUGIN_EXIT, "its static initialisers called exit() while loading; nothing of it was loaded"}}) {
    SCOPED_TRACE(library);
    const Cli r = redres("validate '" + write_scenario(dir, "[\"" + library + "\"]").string() + "'");
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("scenario.toml:1:12: plugin library " + library + ": " + says), std::string::npos) << r.out;
    // Loaded by --plugin before a command that lists the plugins: refused before anything registers.
    const Cli listed = redres("--plugin '" + library + "' plugins");
    EXPECT_EQ(listed.code, 2) << listed.out;
    EXPECT_EQ(listed.out.find("test_registered_before_the_failure   (from"), std::string::npos) << listed.out;
  }
  std::filesystem::remove_all(dir);
}

// A file that exists but cannot be read, or a directory, is not reported as missing; an open directory on
// REDRES_PLUGIN_PATH is warned about.
TEST(PluginLoader, UnreadableLibrariesAndOpenSearchDirectoriesAreToldApart) {
  const auto dir = scratch("plugin_unreadable");
  std::filesystem::create_directories(dir / "libdir.so");
  const Cli directory = redres("validate '" + write_scenario(dir, "[\"libdir.so\"]").string() + "'");
  EXPECT_EQ(directory.code, 2);
  EXPECT_NE(directory.out.find("libdir.so: is a directory, not a library"), std::string::npos) << directory.out;
  std::filesystem::create_directories(dir / "open");
  std::filesystem::copy_file(kPlugin, dir / "open" / "libmine.so");
  std::filesystem::permissions(dir / "open", std::filesystem::perms::all);
  const Cli warned = redres_env("REDRES_PLUGIN_PATH='" + (dir / "open").string() + "' ", "plugins");
  EXPECT_EQ(warned.code, 0) << warned.out;
  EXPECT_NE(warned.out.find("redres: warning: REDRES_PLUGIN_PATH directory '" + (dir / "open").string() +
                            "' is writable by every user"),
            std::string::npos)
      << warned.out;
  const Cli relative = redres_env("cd '" + dir.string() + "' && REDRES_PLUGIN_PATH=open ", "plugins");
  EXPECT_NE(relative.out.find("REDRES_PLUGIN_PATH directory 'open' is relative"), std::string::npos) << relative.out;
  // A closed directory inside one every user can write (no sticky bit): others can put another in its place.
  std::filesystem::create_directories(dir / "shared" / "mine");
  std::filesystem::copy_file(kPlugin, dir / "shared" / "mine" / "libmine.so");
  std::filesystem::permissions(dir / "shared", std::filesystem::perms::all);
  std::filesystem::permissions(dir / "shared" / "mine",
                               std::filesystem::perms::owner_all | std::filesystem::perms::group_read |
                                   std::filesystem::perms::others_read | std::filesystem::perms::group_exec |
                                   std::filesystem::perms::others_exec);
  const Cli inside = redres_env("REDRES_PLUGIN_PATH='" + (dir / "shared" / "mine").string() + "' ", "plugins");
  EXPECT_EQ(inside.code, 0) << inside.out;
  EXPECT_NE(inside.out.find("' is inside '" + (dir / "shared").string() + "', which every user can write to"),
            std::string::npos)
      << inside.out;
  // A library file every user can write, named by a scenario: warned about, and still loaded.
  std::filesystem::create_directories(dir / "closed");
  std::filesystem::copy_file(kPlugin, dir / "closed" / "libopen.so");
  std::filesystem::permissions(dir / "closed" / "libopen.so",
                               std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                                   std::filesystem::perms::others_write | std::filesystem::perms::group_read |
                                   std::filesystem::perms::others_read);
  const Cli open_file = redres("validate '" + write_scenario(dir / "closed", "[\"libopen.so\"]").string() + "'");
  EXPECT_EQ(open_file.code, 0) << open_file.out;
  EXPECT_NE(open_file.out.find("libopen.so' is writable by every user: anyone can change the code redres runs"),
            std::string::npos)
      << open_file.out;
  std::filesystem::remove_all(dir);
}

TEST(PluginsListing, TheSolverTableListsTheRunPolicyKeysWithTheirDefaultsAndRules) {
  // on_infeasible and relax_weight are read through a schema, like the engines' keys, and listed with them.
  const Cli text = redres("plugins");
  ASSERT_EQ(text.code, 0) << text.out;
  EXPECT_NE(text.out.find("on_infeasible   = 'relax'"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("[one of 'hold', 'stop', 'relax', 'continue', 'brake']"), std::string::npos);
  EXPECT_NE(text.out.find("relax_weight    = 10000.0"), std::string::npos);
  EXPECT_NE(text.out.find("a weight in [1, 1e8]"), std::string::npos);
  const Cli json = redres("plugins --json");
  ASSERT_EQ(json.code, 0);
  EXPECT_NE(json.out.find("\"solver_policy_keys\""), std::string::npos);
  EXPECT_NE(json.out.find("\"relax_weight\""), std::string::npos);
}

}  // namespace
}  // namespace redres

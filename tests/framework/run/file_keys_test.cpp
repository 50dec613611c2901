// One reader for every file: the scenario, robot and sweep files are read through schemas, and the listing of their
// keys (`redres keys`, the docs' tables) comes from those schemas. These tests hold the listing to what the readers
// accept: the docs show the tables the schemas make, every key of every shipped file is listed, and every key a
// reader knows (the "known keys" of an unknown-key error) is a listed one.

#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <unistd.h>

#include <gtest/gtest.h>
#include <toml++/toml.h>

#include "mujoco_configs.hpp"
#include "redres/common/error.hpp"
#include "redres/config/toml_reader.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/run/file_keys.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/sweep.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

namespace fs = std::filesystem;

// The listed keys of one table of one file.
std::set<std::string> listed(const std::string& file, const std::string& table) {
  std::set<std::string> out;
  for (const KeyTable& t : file_key_tables()) {
    if (t.file != file || t.table != table) continue;
    for (const KeyInfo& k : t.keys) out.insert(k.name);
  }
  return out;
}

// The TOML files under a directory of the repository (not recursive).
std::vector<fs::path> toml_files(const std::string& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(source_path(dir))) {
    if (e.path().extension() == ".toml") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The keys named in the "known keys: a, b, c" tail of an unknown-key message.
std::set<std::string> known_keys(const std::string& message) {
  const std::size_t at = message.find("known keys: ");
  EXPECT_NE(at, std::string::npos) << message;
  std::set<std::string> out;
  std::stringstream s(message.substr(at + 12));
  std::string key;
  while (std::getline(s, key, ',')) {
    key.erase(0, key.find_first_not_of(' '));
    out.insert(key);
  }
  return out;
}

// The message of `load()`, which must throw a ConfigError.
template <class Load>
std::string message_of(Load load) {
  try {
    load();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(FileKeys, TheDocsShowTheTablesTheSchemasMake) {
  for (const auto& [file, page] : {std::pair{"scenario", "docs/scenario_format.md"},
                                   std::pair{"robot", "docs/robot_format.md"}, std::pair{"sweep", "docs/sweeps.md"}}) {
    const std::string tables = file_keys_markdown(file);
    EXPECT_NE(read_text(source_path(page)).find(tables), std::string::npos)
        << page << " lacks the key tables of the " << file << " file (redres keys " << file
        << " --markdown prints them):\n"
        << tables;
  }
  EXPECT_THROW((void)file_keys_markdown("mesh"), std::invalid_argument);
}

TEST(FileKeys, EveryTableListsItsKeysWithTypeAndMeaning) {
  std::set<std::string> tables;
  for (const KeyTable& t : file_key_tables()) {
    EXPECT_TRUE(tables.insert(t.file + " " + t.table).second) << "table listed twice: " << t.file << " " << t.table;
    EXPECT_FALSE(t.keys.empty()) << t.file << " " << t.table;
    std::set<std::string> names;
    for (const KeyInfo& k : t.keys) {
      EXPECT_TRUE(names.insert(k.name).second) << t.file << " " << t.table << ": '" << k.name << "' twice";
      EXPECT_FALSE(k.type.empty()) << t.file << " " << t.table << ": '" << k.name << "' has no type";
      EXPECT_FALSE(k.help.empty()) << t.file << " " << t.table << ": '" << k.name << "' has no meaning";
      if (k.presence == Presence::kOptional) {
        EXPECT_FALSE(k.default_text.empty()) << t.file << " " << t.table << ": '" << k.name << "' has no default";
      }
    }
  }
  EXPECT_EQ(listed("scenario", "").count("duration"), 1U);
  EXPECT_EQ(listed("robot", "[[joints]]").count("velocity_limit"), 1U);
  EXPECT_EQ(listed("sweep", "[theta0]").count("margin"), 1U);
}

TEST(FileKeys, EveryKeyOfTheShippedFilesIsListed) {
  const std::set<std::string> scenario = listed("scenario", ""), robot = listed("robot", ""),
                              joints = listed("robot", "[[joints]]"), sweep = listed("sweep", "");
  int files = 0;
  for (const fs::path& f : toml_files("configs")) {
    for (const auto& [key, value] : toml::parse_file(f.string())) {
      EXPECT_EQ(scenario.count(std::string(key.str())), 1U) << f << ": key '" << key.str() << "' is not listed";
    }
    ++files;
  }
  for (const fs::path& f : toml_files("configs/sweeps")) {
    for (const auto& [key, value] : toml::parse_file(f.string())) {
      EXPECT_EQ(sweep.count(std::string(key.str())), 1U) << f << ": key '" << key.str() << "' is not listed";
    }
    ++files;
  }
  for (const fs::path& f : toml_files("robots")) {
    const toml::table doc = toml::parse_file(f.string());
    for (const auto& [key, value] : doc) {
      EXPECT_EQ(robot.count(std::string(key.str())), 1U) << f << ": key '" << key.str() << "' is not listed";
    }
    if (const toml::array* js = doc["joints"].as_array()) {
      for (const toml::node& j : *js) {
        for (const auto& [key, value] : *j.as_table()) {
          EXPECT_EQ(joints.count(std::string(key.str())), 1U) << f << ": joint key '" << key.str() << "' is not listed";
        }
      }
    }
    ++files;
  }
  EXPECT_GE(files, 20);
}

TEST(FileKeys, EveryKeyAReaderKnowsIsListed) {
  // An unknown key's message names the keys the reader asked for: each must be a listed key of that table.
  const auto check = [](const fs::path& file, const std::set<std::string>& keys, const std::string& message) {
    ASSERT_NE(message.find("unknown key 'zz_unknown'"), std::string::npos) << file << ": " << message;
    for (const std::string& k : known_keys(message)) {
      EXPECT_EQ(keys.count(k), 1U) << file << ": the reader knows '" << k << "', which is not listed";
    }
  };
  for (const fs::path& f : toml_files("configs")) {
    if (mujoco_config_without_mujoco(f)) continue;
    check(f, listed("scenario", ""), message_of([&] { (void)load_scenario(f, {"zz_unknown=1"}); }));
  }
  for (const fs::path& f : toml_files("robots")) {
    check(f, listed("robot", ""), message_of([&] {
            const std::shared_ptr<TomlFile> doc = parse_toml_file(f);
            doc->root.insert("zz_unknown", 1);
            (void)load_robot(TableReader::root(doc, "robot"));
          }));
  }
  // A sweep file has no --set: a copy in a scratch directory, its base scenario named by its absolute path.
  const fs::path sweep = source_path("configs/sweeps/paper_r_psi_p.toml");
  toml::table doc = toml::parse_file(sweep.string());
  doc.insert_or_assign("scenario", fs::absolute(sweep.parent_path() / *doc["scenario"].value<std::string>()).string());
  doc.insert("zz_unknown", 1);
  const fs::path dir = fs::temp_directory_path() / ("redres_file_keys_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  {
    std::ofstream out(dir / "sweep.toml");
    out << doc << "\n";
  }
  check(sweep, listed("sweep", ""), message_of([&] { (void)load_sweep(dir / "sweep.toml"); }));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace redres

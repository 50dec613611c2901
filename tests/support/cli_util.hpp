#pragma once
// Running the `redres` executable from the tests (REDRES_CLI is its path in the build tree).

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "test_util.hpp"

namespace redres {

struct Cli {
  int code = -1;
  std::string out;
};

// Runs the CLI from the source tree with stderr merged into the captured output; `env` is prefixed to the command
// (e.g. "REDRES_PLUGIN_PATH='/x' ").
inline Cli redres_env(const std::string& env, const std::string& args) {
  const std::string cmd =
      "cd '" + std::string(REDRES_SOURCE_DIR) + "' && " + env + "'" + REDRES_CLI + "' " + args + " 2>&1";
  Cli r;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p) != nullptr) r.out += buf;
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// The same without extra environment.
inline Cli redres(const std::string& args) { return redres_env("", args); }

// The summary.json that a run wrote into `dir`.
inline nlohmann::json read_summary(const std::filesystem::path& dir) {
  return nlohmann::json::parse(read_text(dir / "summary.json"));
}

}  // namespace redres

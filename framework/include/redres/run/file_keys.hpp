#pragma once
/// @file
/// Every key of every input file (scenario, robot, sweep), table by table, from the schemas their readers read them
/// with: what `redres keys` prints and what docs/scenario_format.md, docs/robot_format.md and docs/sweeps.md show
/// (file_keys_markdown(), checked by a test). The plugins' own tables are `redres plugins`'.

#include <string>
#include <string_view>
#include <vector>

#include "redres/config/config.hpp"

namespace redres {

/// The tables of the scenario, robot and sweep files, in that order.
[[nodiscard]] std::vector<KeyTable> file_key_tables();

/// How a key must be given, as listed: "required", "group <name>" or "= <default>".
[[nodiscard]] std::string presence_text(const KeyInfo& key);

/// The Markdown tables of one file's keys ("scenario", "robot" or "sweep"), one per table, each under a bold
/// heading. Throws std::invalid_argument for another file name.
[[nodiscard]] std::string file_keys_markdown(std::string_view file);

}  // namespace redres

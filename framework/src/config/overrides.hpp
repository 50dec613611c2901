#pragma once
/// @file
/// Command-line overrides of a parsed TOML document: "key.path=value" (`--set`). The value is TOML (numbers,
/// booleans, arrays, quoted strings); a bare word is a string. Array entries are addressed by 0-based index
/// ("objectives.1.p=1"). Overrides edit the parsed tree in place, so the file's other values keep their source
/// positions, and an overridden value reports "--set key" as its location.

#include <string>
#include <vector>

#include <toml++/toml.h>

namespace redres {

/// Applies one override; a malformed one is a ConfigError located at "--set <text>".
void apply_override(toml::table& root, const std::string& text);

/// Applies every override in order.
void apply_overrides(toml::table& root, const std::vector<std::string>& overrides);

}  // namespace redres

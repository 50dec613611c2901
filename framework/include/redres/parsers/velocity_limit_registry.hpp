#pragma once
/// @file
/// The registry of velocity-limit laws: how a robot file's `[joints.velocity_limit]` table names a law. The model
/// (model/velocity_limit.hpp) knows only the law's interface; the robot-file parsers look laws up here.

#include <memory>

#include "redres/config/registry.hpp"
#include "redres/config/toml_reader.hpp"
#include "redres/model/velocity_limit.hpp"

namespace redres {

/// The registry of velocity-limit laws.
using VelocityLimitRegistry = Registry<VelocityLimitLaw>;

/// The process-wide registry of velocity-limit laws (function-local static).
VelocityLimitRegistry& velocity_limit_registry();

/// Builds a law from a [joints.velocity_limit] table (`type` and the law's keys); strict (unknown keys rejected).
[[nodiscard]] std::unique_ptr<VelocityLimitLaw> make_velocity_limit(const TableReader& table);

}  // namespace redres

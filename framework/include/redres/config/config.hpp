#pragma once
/// @file
/// Typed plugin configurations. Every plugin kind (objective, constraint, velocity-limit law, path, engine) has a
/// plain `Config` struct whose default member initialisers are its defaults, and one field list (its Schema):
/// the TOML key, the member, the unit, a help line, whether it is required, and a validity rule. From that one
/// list the framework derives
///   - the strict TOML reading (unknown keys listed, every error at file:line:col),
///   - the write-back that makes a configuration survive a round trip,
///   - the listing in `redres plugins` (key, default, unit, required / optional / group, rule, help),
///   - the validation of a Config built in C++ (std::invalid_argument naming the key).
/// A default is therefore written once: in the struct.
///
///   struct MyConfig {
///     double gain = 2.0;                       // default
///     static const Schema<MyConfig>& schema(); // defined in the plugin's .cpp:
///   };
///   const Schema<MyConfig>& MyConfig::schema() {
///     static const Schema<MyConfig> s{{field("gain", &MyConfig::gain, "1/s", "feedback gain", greater(0.0))}};
///     return s;
///   }
///
/// Supported member types: double (a number or a constant formula such as "pi/2"), int, bool, std::string,
/// std::filesystem::path (relative to the file that names it), enums with an `enum_names()` overload found by
/// argument-dependent lookup, std::vector of double, int or std::string, std::array<double, N>, PerJoint (one
/// number or one per joint), std::optional of these, a struct S with its own schema (a sub-table), and
/// std::vector<S> (an array of inline tables). A key whose reading needs more than its own value is an entry().
///
/// The parts, each a header of its own: field_types.hpp (FieldError, PerJoint, KeyInfo, KeyTable, Rule), value_io.hpp
/// (the value codecs), schema.hpp (Field, Schema, field(), entry(), physical_bound()), rules.hpp (greater(), ...),
/// schema_io.hpp (check_config(), read_config(), write_config(), describe_keys(), require_valid()) and configured.hpp
/// (Configured). This header includes them all.

#include "redres/config/configured.hpp"
#include "redres/config/field_types.hpp"
#include "redres/config/rules.hpp"
#include "redres/config/schema.hpp"
#include "redres/config/schema_io.hpp"
#include "redres/config/value_io.hpp"

#pragma once
/// @file
/// What the framework derives from a Config's schema (config.hpp): the checks of a Config (check_config(),
/// require_valid()), the strict reading of a TOML table (read_config()), the write-back (write_config()) and the
/// listing of its keys (describe_keys()).

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "redres/config/field_types.hpp"
#include "redres/config/schema.hpp"
#include "redres/config/toml_reader.hpp"

namespace redres {

/// Checks a Config: required keys given, every field's rule, then the cross-field rules. Throws FieldError.
template <class C>
void check_config(const C& c, const Schema<C>& schema) {
  for (const auto& f : schema.fields) {
    if (f.presence == Presence::kRequired && !f.given(c)) throw FieldError(f.name, "is required but was not given");
    if (f.check) {
      if (auto why = f.check(c)) throw FieldError(f.name, *why);
    }
  }
  if (schema.validate) schema.validate(c);
}

/// Throws a FieldError from check_config() as a ConfigError at the key's location in `r`.
[[noreturn]] void rethrow_at(const TableReader& r, const FieldError& e);

/// Reads a Config from a table (starting from the defaults in `c`), marking every schema key as known; checks it.
/// Does not call finish(): the caller may read more keys from the same table first.
/// The keys are read in the schema's order, and each is checked as soon as it is read, so that a later key's reader
/// (an entry()) sees checked values.
template <class C>
void read_config(const TableReader& r, const Schema<C>& schema, C& c) {
  for (const auto& f : schema.fields) {
    if (f.always || r.has(f.name)) {
      f.read(r, c);
    } else if (f.presence == Presence::kRequired) {
      r.fail("missing required key '" + f.name + "'" + (f.help.empty() ? "" : " (" + f.help + ")"));
    }
    if (f.check) {
      if (auto why = f.check(c)) rethrow_at(r, FieldError(f.name, *why));
    }
  }
  try {
    if (schema.validate) schema.validate(c);
  } catch (const FieldError& e) {
    rethrow_at(r, e);
  }
}

/// Writes every field of a Config into `out`.
template <class C>
void write_config(const C& c, const Schema<C>& schema, toml::table& out) {
  for (const auto& f : schema.fields) f.write(c, out);
}

/// The keys of a schema, with defaults taken from a default-constructed Config.
template <class C>
std::vector<KeyInfo> describe_keys(const Schema<C>& schema, const C& defaults = C{}) {
  std::vector<KeyInfo> out;
  for (const auto& f : schema.fields) {
    KeyInfo k;
    k.name = f.name;
    k.unit = f.unit;
    k.help = f.help;
    k.rule = f.rule;
    k.type = f.type;
    k.presence = f.presence;
    k.group = f.group;
    if (f.presence == Presence::kOptional && !f.default_text.empty()) {
      k.default_text = f.default_text;
    } else if (f.presence == Presence::kOptional) {
      toml::table t;
      f.write(defaults, t);
      if (const toml::node* n = t.get(f.name)) {
        k.default_text = node_text(*n);
      } else {
        k.default_text = "(none)";
      }
    }
    out.push_back(std::move(k));
  }
  return out;
}

/// Throws std::invalid_argument("<who>: key 'k': ...") when a Config built in C++ breaks its schema.
template <class C>
void require_valid(const C& c, const Schema<C>& schema, const std::string& who) {
  try {
    check_config(c, schema);
  } catch (const FieldError& e) {
    throw FieldError(e.key(), e.message(), who);
  }
}

}  // namespace redres

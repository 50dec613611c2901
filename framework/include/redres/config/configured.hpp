#pragma once
/// @file
/// The base of a plugin with a typed Config (config.hpp): Configured<Base, C> keeps the checked Config and writes it
/// back.

#include <string>
#include <utility>

#include "redres/config/schema_io.hpp"

namespace redres {

/// The base of a plugin with Config C: keeps the (checked) Config and writes it back. Use as
///   class MyObjective final : public Configured<Objective, MyConfig> { ... };
/// where the constructor passes the plugin's type name and config: Configured(kType, config).
template <class Base, class C>
class Configured : public Base {
 public:
  using Config = C;
  /// The configuration this instance was built with.
  [[nodiscard]] const Config& settings() const noexcept { return config_; }

 protected:
  Configured(std::string type, const Config& config) : Base(std::move(type)), config_(config) {
    require_valid(config_, Config::schema(), this->type());
  }
  Config config_;

 private:
  void write_config(toml::table& out) const final { redres::write_config(config_, Config::schema(), out); }
};

}  // namespace redres

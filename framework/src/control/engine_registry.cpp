#include "redres/control/engine_registry.hpp"

#include <string>

namespace redres {

namespace {
// `engine` itself, so that the listing and the reading share one definition.
struct EngineChoice {
  std::string engine = "projection";
  static const Schema<EngineChoice>& schema() {
    static const Schema<EngineChoice> s{{field("engine", &EngineChoice::engine, "", "the LVI engine (see below)")}};
    return s;
  }
};
}  // namespace

EngineRegistry& engine_registry() {
  static EngineRegistry registry("LVI engine");
  return registry;
}

const std::vector<KeyInfo>& solver_common_keys() {
  static const std::vector<KeyInfo> keys = [] {
    std::vector<KeyInfo> k = describe_keys(EngineChoice::schema());
    for (auto& x : describe_keys(SolverSettings::schema())) k.push_back(std::move(x));
    return k;
  }();
  return keys;
}

EngineSpec read_engine_spec(const TableReader& solver) {
  EngineChoice choice;
  read_config(solver, EngineChoice::schema(), choice);
  const EngineRegistry& reg = engine_registry();
  const auto* entry = reg.find(choice.engine);
  if (entry == nullptr) {
    std::string names;
    for (const auto* e : reg.entries()) names += (names.empty() ? "'" : ", '") + e->type + "'";
    solver.fail("engine", "expected one of " + names + ", got '" + choice.engine + "'");
  }
  EngineSpec spec;
  spec.type = choice.engine;
  read_config(solver, SolverSettings::schema(), spec.settings);
  spec.config = entry->read(solver);
  solver.finish();
  try {
    (void)entry->make(spec.config, spec.settings);  // what make() will build, checked here, at the file's place
  } catch (const FieldError& e) {
    rethrow_at(solver, e);
  }
  return spec;
}

std::unique_ptr<LviEngine> make_engine(const TableReader& solver) { return read_engine_spec(solver).make(); }

std::unique_ptr<LviEngine> EngineSpec::make() const {
  if (!config.has_value()) return make_engine(type, settings);  // the type's default Config
  return engine_registry().create(type, config, settings);
}

std::unique_ptr<LviEngine> make_engine(const std::string& name, const SolverSettings& settings) {
  const auto* e = engine_registry().find(name);
  if (e == nullptr) {
    throw std::invalid_argument("make_engine: unknown engine '" + name +
                                "'; known engines: " + engine_registry().names_like(name));
  }
  require_valid(settings, SolverSettings::schema(), "make_engine(" + name + ")");
  return e->make(e->defaults, settings);
}

}  // namespace redres

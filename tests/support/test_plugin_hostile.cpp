// A plugin library whose static initialisers misbehave after registering one plugin, built twice: with
// REDRES_TEST_HOSTILE_THROW it throws, with REDRES_TEST_HOSTILE_EXIT it calls exit(0). Loading either must fail
// with an error that names the library, leave nothing of it registered, and keep the process (tests/cli/).

#include <cstdlib>
#include <stdexcept>

#include <redres/control/plugin.hpp>

namespace {

struct NoConfig {
  static const redres::Schema<NoConfig>& schema() {
    static const redres::Schema<NoConfig> s{};
    return s;
  }
};

class Registered final : public redres::Configured<redres::Objective, NoConfig> {
 public:
  static constexpr const char* kType = "test_registered_before_the_failure";
  Registered(const Config& c, const redres::RobotModel& /*robot*/) : Configured(kType, c) {}

 private:
  void add_to(const redres::Context& /*ctx*/, redres::QpBuilder& /*b*/, redres::PluginData* /*data*/) const override {}
};

const bool kRegistered =
    redres::objective_registry().add_plugin<Registered>("test: registered, then the library fails");

struct Misbehave {
  Misbehave() {
#if defined(REDRES_TEST_HOSTILE_THROW)
    throw std::runtime_error("the plugin's configuration file is missing");
#elif defined(REDRES_TEST_HOSTILE_EXIT)
    std::exit(0);
#endif
  }
} const kMisbehave;

}  // namespace

// A plugin library that registers a name the built-ins already have: loading it must fail with a clear error that
// names the library, and leave the built-in plugin in place.

#include <redres/control/plugin.hpp>

namespace {

struct NoConfig {
  static const redres::Schema<NoConfig>& schema() {
    static const redres::Schema<NoConfig> s{};
    return s;
  }
};

class Impostor final : public redres::Configured<redres::Objective, NoConfig> {
 public:
  static constexpr const char* kType = "manipulability";
  Impostor(const Config& c, const redres::RobotModel& /*robot*/) : Configured(kType, c) {}

 private:
  void add_to(const redres::Context& /*ctx*/, redres::QpBuilder& /*b*/, redres::PluginData* /*data*/) const override {}
};

struct Fine final : public redres::Configured<redres::Objective, NoConfig> {
  static constexpr const char* kType = "test_fine_but_in_a_bad_library";
  Fine(const Config& c, const redres::RobotModel& /*robot*/) : Configured(kType, c) {}

 private:
  void add_to(const redres::Context& /*ctx*/, redres::QpBuilder& /*b*/, redres::PluginData* /*data*/) const override {}
};

const bool kFine = redres::objective_registry().add_plugin<Fine>("registered before the duplicate; undone with it");
const bool kImpostor = redres::objective_registry().add_plugin<Impostor>("a duplicate of a built-in");

}  // namespace

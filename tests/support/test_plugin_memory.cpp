// A plugin library for the sweep's out-of-memory test (tests/cli/sweep_limits_test.cpp): its objective
// `test_out_of_memory` adds nothing to the QP, but its first N contributions in the process throw std::bad_alloc,
// N from the environment variable REDRES_TEST_OUT_OF_MEMORY (0 when unset): a variation that runs out of memory,
// as under an address-space limit, made deterministic.

#include <atomic>
#include <cstdlib>
#include <new>

#include <redres/control/plugin.hpp>

namespace {

std::atomic<long> failures_left{[] {
  const char* n = std::getenv("REDRES_TEST_OUT_OF_MEMORY");
  return n == nullptr ? 0L : std::atol(n);
}()};

struct NoConfig {
  static const redres::Schema<NoConfig>& schema() {
    static const redres::Schema<NoConfig> s{{}};
    return s;
  }
};

class TestOutOfMemory final : public redres::Configured<redres::Objective, NoConfig> {
 public:
  static constexpr const char* kType = "test_out_of_memory";
  TestOutOfMemory(const Config& c, const redres::RobotModel& /*robot*/) : Configured(kType, c) {}
  std::optional<double> potential(const redres::Context& /*ctx*/) const override { return 0.0; }

 private:
  void add_to(const redres::Context& /*ctx*/, redres::QpBuilder& /*b*/, redres::PluginData* /*data*/) const override {
    if (failures_left.fetch_sub(1) > 0) throw std::bad_alloc();
  }
};

const bool kObjective = redres::objective_registry().add_plugin<TestOutOfMemory>(
    "test: the first $REDRES_TEST_OUT_OF_MEMORY contributions throw std::bad_alloc");

}  // namespace

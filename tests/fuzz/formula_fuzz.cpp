// libFuzzer target: the formula laws (docs/fuzzing.md).
//
// The input is one formula. It is compiled the ways the loaders compile users' formulas, and each one that compiles
// is evaluated at a few points, including non-finite ones:
// - as a constant (evaluate_constant: every number in a robot or scenario file, `--set`, `--theta`);
// - as the `expression` velocity-limit law with lower = upper = the input (a formula of theta), built from a
//   [joints.velocity_limit] table by make_velocity_limit and checked over a joint range with check_velocity_law as
//   the robot loader does;
// - as the `expression` schedule of the `manipulability` objective (a formula of t and T), built from an
//   [[objectives]] table by make_objective, whose coefficient p(t) is evaluated over a run.
//
// Exceptions derived from std::exception are the answers to bad formulas and are expected. Crashes, sanitizer
// reports, leaks, timeouts and out-of-memory are findings.

#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <memory>
#include <numbers>
#include <string>

#include "fuzz_util.hpp"
#include "redres/common/formula.hpp"
#include "redres/control/plugin.hpp"
#include "redres/model/robot.hpp"
#include "redres/model/velocity_limit.hpp"
#include "redres/objectives/manipulability.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kThetas[] = {0.0, -0.0, 1.0, -1.0, std::numbers::pi, 1e-300, -1e300, kInf, kNaN};
constexpr double kTimes[][2] = {{0.0, 40.0}, {20.0, 40.0}, {40.0, 40.0}, {0.0, 0.0}, {1.0, -1.0}, {kNaN, kInf}};

const redres::RobotModel& robot() {
  static const redres::RobotModel r = redres::load_robot(redres::fuzz::source_dir() / "robots/planar_4link.toml");
  return r;
}

// A table as the loader would see it, with `formula` under every key in `keys`.
std::shared_ptr<redres::TomlFile> table(std::initializer_list<std::pair<const char*, const char*>> fixed,
                                        std::initializer_list<const char*> keys, const std::string& formula) {
  auto file = std::make_shared<redres::TomlFile>();
  file->path = "<fuzz input>";
  for (const auto& [k, v] : fixed) file->root.insert(k, v);
  for (const char* k : keys) file->root.insert(k, formula);
  return file;
}

void as_constant(const std::string& text) {
  try {
    (void)redres::evaluate_constant(text);
  } catch (const std::invalid_argument&) {
  }
}

void as_velocity_law(const std::string& text) {
  try {
    const auto file = table({{"type", "expression"}}, {"lower", "upper"}, text);
    const auto law = redres::make_velocity_limit(redres::TableReader(file, file->root, "velocity_limit"));
    for (const double theta : kThetas) (void)law->bounds(theta);
    (void)law->describe();
    (void)law->config();
    (void)redres::check_velocity_law(*law, -std::numbers::pi / 2, std::numbers::pi / 2);
  } catch (const std::exception&) {
  }
}

void as_schedule(const std::string& text) {
  try {
    const auto file = table({{"type", "manipulability"}, {"schedule", "expression"}}, {"formula"}, text);
    const auto objective = redres::make_objective(redres::TableReader(file, file->root, "objectives"), robot());
    const auto* m = dynamic_cast<const redres::Manipulability*>(objective.get());
    if (m == nullptr) std::abort();  // the registry built another type: a finding
    for (const auto& tT : kTimes) (void)m->coefficient(tT[0], tT[1]);
    for (int k = 0; k <= 20; ++k) (void)m->coefficient(2.0 * k, 40.0);
  } catch (const std::exception&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  (void)robot();  // loaded once, before the first input
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  as_constant(text);
  as_velocity_law(text);
  as_schedule(text);
  return 0;
}

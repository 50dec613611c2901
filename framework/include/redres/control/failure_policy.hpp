#pragma once
/// @file
/// What a step whose QP is not solved does: one type from the scenario file's `[solver] on_infeasible` through the
/// controller to Python (docs/motion.md has the table), and the elastic QP that the `relax` and `brake` policies
/// fall back on (the braking law itself is control/brake.hpp).

#include <array>
#include <memory>
#include <string_view>
#include <utility>

#include "redres/qp/elastic.hpp"
#include "redres/qp/lvi.hpp"

namespace redres {

/// The failure policy:
/// - kHold ("hold"; "continue" is its older name): theta_dot = 0 at once. Refused for a robot with acceleration
///   limits (a velocity jump).
/// - kStop ("stop"): the step gives up as kHold does (a robot with acceleration limits brakes), and a run ends there.
/// - kRelax ("relax"): solves the elastic QP (rows relaxed into a weighted penalty, every bound kept); when that fails
///   too, brakes (a robot with acceleration limits) or holds.
/// - kBrake ("brake", the default for a robot with acceleration limits on every joint): decelerates every joint along
///   the previous command within its acceleration (and jerk) limits (control/brake.hpp). While the task's position
///   error exceeds the recovery bound (a step after braking falls behind its moving target) the elastic QP is tried
///   first, so that the arm catches up within its limits instead of braking again.
enum class FailurePolicy { kHold, kStop, kRelax, kBrake };

/// The names of the policies as files and Python write them (the first name of each is the one written back).
inline auto enum_names(FailurePolicy) {
  return std::array{std::pair{FailurePolicy::kHold, std::string_view("hold")},
                    std::pair{FailurePolicy::kStop, std::string_view("stop")},
                    std::pair{FailurePolicy::kRelax, std::string_view("relax")},
                    std::pair{FailurePolicy::kHold, std::string_view("continue")},
                    std::pair{FailurePolicy::kBrake, std::string_view("brake")}};
}

/// The policy named `name`; std::invalid_argument naming the choices otherwise.
[[nodiscard]] FailurePolicy failure_policy_from_name(std::string_view name);
/// The policy's name ("hold", "stop", "relax" or "brake").
[[nodiscard]] std::string_view failure_policy_name(FailurePolicy policy);

/// The elastic QP of a failed step, with its own engine of the step engine's type and settings: made once
/// (setup(), which allocates), then solved without allocating.
class ElasticFallback {
 public:
  /// Sizes it for `qp` and makes an engine like `like` (allocates).
  void setup(const QpProblem& qp, const LviEngine& like);
  /// Frees the engine and the QP (a policy without a fallback).
  void release() noexcept { engine_.reset(); }
  [[nodiscard]] bool ready() const noexcept { return engine_ != nullptr; }
  /// Solves the elastic QP of `qp` with weight rho > 0; on `solved`, row_miss() is max_r |J_r x - d_r|.
  const SolverResult& solve(const QpProblem& qp, double rho);
  [[nodiscard]] const SolverResult& result() const noexcept { return result_; }
  [[nodiscard]] double row_miss() const noexcept { return row_miss_; }

 private:
  std::unique_ptr<LviEngine> engine_;
  ElasticQp elastic_;
  SolverResult result_;
  Eigen::VectorXd miss_;  // J x - d
  double row_miss_ = 0.0;
};

}  // namespace redres

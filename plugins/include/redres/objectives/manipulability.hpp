#pragma once
/// @file
/// `manipulability`: the manipulability-maximising term of eq. 5, zeta += -weight p(t) grad w. Together with
/// `min_velocity_norm` (W = I) it is the paper's index |x - p q|^2 / 2 up to a constant (eq. 4). The measure is
/// w = det(J J') (`det`, the paper), Yoshikawa's sqrt(det(J J')) (`yoshikawa`), or log det(J J') (`log_det`); the
/// gradients come from the kinematics (adjugate / SVD forms, exact at singularities; grad log w = grad w / w, with w
/// floored at 1e-300: below the floor the potential is flat but the gradient still points away from the singularity).
/// `log_det` is scale-free: its gradient does not change when the arm's lengths are scaled, so one p serves arms whose
/// w is 1e-2 (spatial 7-DOF arms) and 1 alike; docs/paper.md says how to choose p.
///
/// Coefficient schedules p(t), t in [0, T]:
/// - `constant`: p(t) = p;
/// - `sine`: p(t) = p sin(pi t / T) (the paper's TVCMM with p = 2; p(0) = p(T) = 0);
/// - `smoothstep`: p s(t / t_r) while t < t_r, p while t_r <= t <= T - t_r, p s((T - t) / t_r) after, with
///   s(u) = 3u^2 - 2u^3 and t_r = ramp_fraction T;
/// - `expression`: p(t) = `formula` of t and T (muParser); `p` is not used.

#include <array>
#include <memory>
#include <optional>
#include <string>

#include "redres/common/formula.hpp"
#include "redres/control/plugin.hpp"

namespace redres {

/// The configuration of `manipulability`. Designated initialisers follow this order, e.g.
/// `Manipulability::Config{.p = 2.0, .schedule = Manipulability::Schedule::kSine}`.
struct ManipulabilityConfig {
  enum class Measure { kDet, kYoshikawa, kLogDet };
  enum class Schedule { kConstant, kSine, kSmoothstep, kExpression };

  double p = 2.0;                        //!< coefficient magnitude
  Schedule schedule = Schedule::kSine;   //!< p(t)
  Measure measure = Measure::kDet;       //!< det(JJ') (the paper), sqrt(det(JJ')) or log det(JJ')
  double ramp_fraction = 0.25;           //!< smoothstep: each ramp's share of T
  std::optional<std::string> formula{};  //!< expression: p(t) as a formula of t and T

  static const Schema<ManipulabilityConfig>& schema();
};

/// Names of the enums in TOML.
inline auto enum_names(ManipulabilityConfig::Measure) {
  using M = ManipulabilityConfig::Measure;
  return std::array{std::pair{M::kDet, std::string_view("det")},
                    std::pair{M::kYoshikawa, std::string_view("yoshikawa")},
                    std::pair{M::kLogDet, std::string_view("log_det")}};
}
inline auto enum_names(ManipulabilityConfig::Schedule) {
  using S = ManipulabilityConfig::Schedule;
  return std::array{std::pair{S::kConstant, std::string_view("constant")},
                    std::pair{S::kSine, std::string_view("sine")},
                    std::pair{S::kSmoothstep, std::string_view("smoothstep")},
                    std::pair{S::kExpression, std::string_view("expression")}};
}

/// The manipulability objective.
class Manipulability final : public Configured<Objective, ManipulabilityConfig> {
 public:
  static constexpr const char* kType = "manipulability";
  using Measure = ManipulabilityConfig::Measure;
  using Schedule = ManipulabilityConfig::Schedule;

  Manipulability(const Config& config, const RobotModel& robot);
  /// Both levels: zeta = -weight p(t) grad w pushes x (theta_dot or theta_ddot) up the gradient.
  [[nodiscard]] bool supports(ControlOrder /*order*/) const override { return true; }

  /// The coefficient p(t).
  [[nodiscard]] double coefficient(double t, double T) const;
  [[nodiscard]] KinematicsLevel kinematics_level() const override;
  [[nodiscard]] std::optional<double> potential(const Context& ctx) const override;
  /// The expression schedule is finite at every step time of the run (t = k tau and T; Heun's second stage uses
  /// the same times), so that no step meets a NaN or an infinite p(t).
  void check_run(double T, double tau) const override;

 private:
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const override;

  std::unique_ptr<Formula> formula_;
};

}  // namespace redres

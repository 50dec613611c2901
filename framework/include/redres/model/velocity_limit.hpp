#pragma once
/// @file
/// Per-joint velocity-limit laws: theta_dot^-(theta) <= theta_dot <= theta_dot^+(theta) (eq. 8). A law is a
/// plugin, chosen by `type` in the robot file's `[joints.velocity_limit]` table. Built in: `constant`,
/// `push_rod` (eq. 2), `expression` (muParser formulas of theta) and `table` (piecewise linear in theta).

#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "redres/config/config.hpp"
#include "redres/config/toml_reader.hpp"

namespace redres {

/// Joint-velocity limits at one joint position, in rad/s (revolute) or m/s (prismatic).
struct VelocityBounds {
  double lower = 0.0;  //!< theta_dot^-(theta), < 0
  double upper = 0.0;  //!< theta_dot^+(theta), > 0
};

/// Where a law is undefined inside a range: the angle and the reason.
struct UndefinedAt {
  double theta = 0.0;  //!< joint position (rad or m)
  std::string reason;  //!< e.g. "cos(theta) = 0"
};

/// A velocity-limit law. Immutable after construction; bounds() is allocation-free. A law is a plugin with a typed
/// Config (config.hpp): derive from Configured<VelocityLimitLaw, MyConfig> and register with
/// velocity_limit_registry().add_plugin<MyLaw>("summary") (parsers/velocity_limit_registry.hpp).
class VelocityLimitLaw {
 public:
  VelocityLimitLaw(const VelocityLimitLaw&) = delete;
  VelocityLimitLaw& operator=(const VelocityLimitLaw&) = delete;
  virtual ~VelocityLimitLaw() = default;

  /// Lower and upper velocity limits at joint position `theta`.
  [[nodiscard]] virtual VelocityBounds bounds(double theta) const = 0;
  /// The registry type name.
  [[nodiscard]] const std::string& type() const noexcept { return type_; }
  /// One line with the parameters, e.g. "push_rod(a=0.25 m, b=0.08 m, ...)".
  [[nodiscard]] virtual std::string describe() const = 0;
  /// The first position in [lo, hi] where the law is not defined, if any (checked at load before sampling).
  [[nodiscard]] virtual std::optional<UndefinedAt> undefined_in(double lo, double hi) const {
    (void)lo;
    (void)hi;
    return std::nullopt;
  }
  /// The configuration (`type` and the law's keys), readable by the same registry.
  [[nodiscard]] toml::table config() const;

 protected:
  explicit VelocityLimitLaw(std::string type) : type_(std::move(type)) {}

 private:
  virtual void write_config(toml::table& out) const = 0;
  std::string type_;
};

/// Number of positions (including both ends) at which a law is sampled at load.
inline constexpr int kVelocityLawSamples = 2001;

/// Checks a law over [lo, hi]: defined everywhere, finite, lower < 0 < upper and |limit| <= bound at every sample.
/// Returns the first failure (position and reason), or nothing when the law is valid. The laws serve velocity,
/// acceleration and jerk limits alike; `bound` is the physical range of the one being read (physical_bound of
/// "rad/s or m/s", "rad/s^2 or m/s^2", "rad/s^3 or m/s^3").
[[nodiscard]] std::optional<UndefinedAt> check_velocity_law(const VelocityLimitLaw& law, double lo, double hi,
                                                            double bound = 1e3);

}  // namespace redres

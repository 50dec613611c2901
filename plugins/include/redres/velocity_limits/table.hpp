#pragma once
/// @file
/// `table`: limits piecewise linear in theta through the points (theta_k, lower_k, upper_k). The points are given
/// inline (`theta`, `lower`, `upper` arrays) or in a CSV file (`file`, columns theta,lower,upper with a header
/// line, resolved relative to the robot file). theta must be strictly increasing and must cover the joint's range
/// (checked at load); outside the table the end values hold.

#include <filesystem>
#include <optional>
#include <vector>

#include "redres/model/velocity_limit.hpp"

namespace redres {

/// The configuration of `table`: either `file`, or `theta`, `lower` and `upper` (group "points").
struct TableLawConfig {
  std::vector<double> theta{};                  //!< joint positions (rad or m), strictly increasing
  std::vector<double> lower{};                  //!< lower limits at those positions
  std::vector<double> upper{};                  //!< upper limits at those positions
  std::optional<std::filesystem::path> file{};  //!< CSV with columns theta,lower,upper (instead of the arrays)

  static const Schema<TableLawConfig>& schema();
};

/// Limits interpolated in a table.
class TableLaw final : public Configured<VelocityLimitLaw, TableLawConfig> {
 public:
  static constexpr const char* kType = "table";
  explicit TableLaw(const Config& config);
  [[nodiscard]] VelocityBounds bounds(double theta) const override;
  [[nodiscard]] std::string describe() const override;
  [[nodiscard]] std::optional<UndefinedAt> undefined_in(double lo, double hi) const override;

 private:
  std::vector<double> theta_, lower_, upper_;
};

}  // namespace redres

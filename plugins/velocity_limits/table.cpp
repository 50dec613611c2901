#include "redres/velocity_limits/table.hpp"

#include <algorithm>
#include <sstream>

#include "redres/common/csv.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"

namespace redres {

namespace {
// The points as given (arrays) or read from the file; FieldError names the key at fault.
void check_points(const std::vector<double>& theta, const std::vector<double>& lower, const std::vector<double>& upper,
                  const char* where) {
  if (theta.size() < 2)
    throw FieldError(where, "expected at least 2 table points, got " + std::to_string(theta.size()));
  if (lower.size() != theta.size() || upper.size() != theta.size()) {
    throw FieldError(where, "expected as many lower and upper limits as theta points (" + std::to_string(theta.size()) +
                                "), got " + std::to_string(lower.size()) + " and " + std::to_string(upper.size()));
  }
  for (std::size_t k = 1; k < theta.size(); ++k) {
    if (!(theta[k] > theta[k - 1])) {
      throw FieldError(where, "expected strictly increasing theta, but point " + std::to_string(k + 1) + " (" +
                                  std::to_string(theta[k]) + ") does not exceed point " + std::to_string(k) + " (" +
                                  std::to_string(theta[k - 1]) + ")");
    }
  }
}
}  // namespace

const Schema<TableLawConfig>& TableLawConfig::schema() {
  using C = TableLawConfig;
  static const Schema<C> s{
      {field("theta", &C::theta, "rad or m", "joint positions, strictly increasing").in_group("points"),
       field("lower", &C::lower, "rad/s^k or m/s^k", "lower limits at those positions").in_group("points"),
       field("upper", &C::upper, "rad/s^k or m/s^k", "upper limits at those positions").in_group("points"),
       field("file", &C::file, "", "CSV file with columns theta,lower,upper, relative to the robot file")
           .in_group("points")},
      [](const C& c) {
        const bool arrays = !c.theta.empty() || !c.lower.empty() || !c.upper.empty();
        if (c.file && arrays)
          throw FieldError("file", "expected either `file` or the `theta`/`lower`/`upper` arrays, not both");
        if (!c.file && !arrays) throw FieldError("", "expected `file`, or the `theta`, `lower` and `upper` arrays");
        if (!c.file) check_points(c.theta, c.lower, c.upper, "theta");
      },
      {{"points", "give `file`, or all three of `theta`, `lower` and `upper`"}}};
  return s;
}

TableLaw::TableLaw(const Config& config) : Configured(kType, config) {
  if (config_.file) {
    // A file that is missing, not a regular file or empty is reported at the `file` key; an error inside the file
    // is a ConfigError at its own file:line:col.
    const CsvTable csv = [&] {
      try {
        return read_csv(*config_.file, {"theta", "lower", "upper"});
      } catch (const ConfigError& e) {
        if (e.where().line == 0) throw FieldError("file", e.what());
        throw;
      }
    }();
    theta_ = csv.column("theta");
    lower_ = csv.column("lower");
    upper_ = csv.column("upper");
    check_points(theta_, lower_, upper_, "file");
  } else {
    theta_ = config_.theta;
    lower_ = config_.lower;
    upper_ = config_.upper;
  }
}

VelocityBounds TableLaw::bounds(double theta) const {
  if (theta <= theta_.front()) return {lower_.front(), upper_.front()};
  if (theta >= theta_.back()) return {lower_.back(), upper_.back()};
  const auto k = static_cast<std::size_t>(std::upper_bound(theta_.begin(), theta_.end(), theta) - theta_.begin());
  const double t = (theta - theta_[k - 1]) / (theta_[k] - theta_[k - 1]);
  return {lower_[k - 1] + t * (lower_[k] - lower_[k - 1]), upper_[k - 1] + t * (upper_[k] - upper_[k - 1])};
}

std::string TableLaw::describe() const {
  std::ostringstream s;
  s.precision(10);
  s << "table(" << theta_.size() << " points on [" << theta_.front() << ", " << theta_.back() << "]"
    << (config_.file ? " from " + config_.file->string() : std::string()) << ")";
  return s.str();
}

std::optional<UndefinedAt> TableLaw::undefined_in(double lo, double hi) const {
  std::ostringstream why;
  why.precision(10);
  why << "outside the table, which covers [" << theta_.front() << ", " << theta_.back() << "]";
  if (lo < theta_.front()) return UndefinedAt{lo, why.str()};
  if (hi > theta_.back()) return UndefinedAt{hi, why.str()};
  return std::nullopt;
}

namespace {
const bool kTableRegistered =
    velocity_limit_registry().add_plugin<TableLaw>("limits piecewise linear in theta, inline or from a CSV file");
}  // namespace

}  // namespace redres

/// `table`: limits piecewise linear in theta through the points (theta_k, lower_k, upper_k). The points are given
/// inline (`theta`, `lower`, `upper` arrays) or in a CSV file (`file`, columns theta,lower,upper with a header
/// line, resolved relative to the robot file). theta must be strictly increasing and must cover the joint's range
/// (checked at load); outside the table the end values hold.
/// TOML keys: `theta`, `lower`, `upper` (arrays of equal length >= 2), or `file` (path).

#include <algorithm>
#include <sstream>

#include "redres/csv.hpp"
#include "redres/velocity_limit.hpp"

namespace redres {
namespace {

class TableLaw final : public VelocityLimitLaw {
 public:
  TableLaw(std::vector<double> theta, std::vector<double> lower, std::vector<double> upper, std::string origin)
      : theta_(std::move(theta)), lower_(std::move(lower)), upper_(std::move(upper)), origin_(std::move(origin)) {}

  VelocityBounds bounds(double theta) const override {
    if (theta <= theta_.front()) return {lower_.front(), upper_.front()};
    if (theta >= theta_.back()) return {lower_.back(), upper_.back()};
    const auto k = static_cast<std::size_t>(std::upper_bound(theta_.begin(), theta_.end(), theta) - theta_.begin());
    const double t = (theta - theta_[k - 1]) / (theta_[k] - theta_[k - 1]);
    return {lower_[k - 1] + t * (lower_[k] - lower_[k - 1]), upper_[k - 1] + t * (upper_[k] - upper_[k - 1])};
  }

  std::string type() const override { return "table"; }
  std::string describe() const override {
    std::ostringstream s;
    s.precision(10);
    s << "table(" << theta_.size() << " points on [" << theta_.front() << ", " << theta_.back() << "]" << origin_
      << ")";
    return s.str();
  }

  std::optional<UndefinedAt> undefined_in(double lo, double hi) const override {
    std::ostringstream why;
    why.precision(10);
    why << "outside the table, which covers [" << theta_.front() << ", " << theta_.back() << "]";
    if (lo < theta_.front()) return UndefinedAt{lo, why.str()};
    if (hi > theta_.back()) return UndefinedAt{hi, why.str()};
    return std::nullopt;
  }

 private:
  std::vector<double> theta_, lower_, upper_;
  std::string origin_;
};

std::unique_ptr<VelocityLimitLaw> make_table(const TableReader& r) {
  std::vector<double> theta, lower, upper;
  std::string origin;
  const char* where = "theta";
  if (r.has("file")) {
    if (r.has("theta") || r.has("lower") || r.has("upper")) {
      r.fail("file", "expected either `file` or the `theta`/`lower`/`upper` arrays, not both");
    }
    const CsvTable csv = read_csv(r.path("file"), {"theta", "lower", "upper"});
    theta = csv.column("theta");
    lower = csv.column("lower");
    upper = csv.column("upper");
    origin = " from " + csv.path;
    where = "file";
  } else {
    theta = r.numbers("theta");
    lower = r.numbers("lower", theta.size());
    upper = r.numbers("upper", theta.size());
  }
  if (theta.size() < 2) r.fail(where, "expected at least 2 table points, got " + std::to_string(theta.size()));
  for (std::size_t k = 1; k < theta.size(); ++k) {
    if (!(theta[k] > theta[k - 1])) {
      r.fail(where, "expected strictly increasing theta, but point " + std::to_string(k + 1) + " (" +
                        std::to_string(theta[k]) + ") does not exceed point " + std::to_string(k) + " (" +
                        std::to_string(theta[k - 1]) + ")");
    }
  }
  return std::make_unique<TableLaw>(std::move(theta), std::move(lower), std::move(upper), origin);
}

const bool kRegistered = velocity_limit_registry().add({
    "table",
    "limits piecewise linear in theta, inline or from a CSV file",
    {{"theta", "", "joint positions (rad or m), strictly increasing"},
     {"lower", "", "lower limits at those positions"},
     {"upper", "", "upper limits at those positions"},
     {"file", "", "CSV file with columns theta,lower,upper (instead of the arrays), relative to the robot file"}},
    make_table,
});

}  // namespace
}  // namespace redres

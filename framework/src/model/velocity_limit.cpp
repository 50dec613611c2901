#include "redres/model/velocity_limit.hpp"
#include "redres/common/hot.hpp"

#include <cmath>
#include <sstream>

namespace redres {

toml::table VelocityLimitLaw::config() const {
  toml::table out;
  out.insert("type", type_);
  write_config(out);
  return out;
}

REDRES_HOT std::optional<UndefinedAt> check_velocity_law(const VelocityLimitLaw& law, double lo, double hi,
                                                         double bound) {
  if (auto bad = law.undefined_in(lo, hi)) return bad;
  for (int k = 0; k < kVelocityLawSamples; ++k) {
    const double theta =
        k == kVelocityLawSamples - 1 ? hi : lo + (hi - lo) * static_cast<double>(k) / (kVelocityLawSamples - 1);
    const VelocityBounds b = law.bounds(theta);
    const bool finite = std::isfinite(b.lower) && std::isfinite(b.upper);
    if (finite && b.lower < 0.0 && 0.0 < b.upper && -bound <= b.lower && b.upper <= bound) continue;
    std::ostringstream why;
    why.precision(10);
    if (!finite) {
      why << "limits are not finite (lower " << b.lower << ", upper " << b.upper << ")";
    } else if (b.lower < 0.0 && 0.0 < b.upper) {
      why << "expected limits within the physical range |x| <= " << bound << ", got lower " << b.lower << ", upper "
          << b.upper;
    } else {
      why << "expected lower < 0 < upper, got lower " << b.lower << ", upper " << b.upper;
    }
    return UndefinedAt{theta, why.str()};
  }
  return std::nullopt;
}

}  // namespace redres

#include "redres/control/collision_rows.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "redres/config/config.hpp"
#include "redres/control/plugin.hpp"

namespace redres {

PairDistances::PairDistances(int pairs, Damper damper)
    : distance_(static_cast<std::size_t>(pairs), std::numeric_limits<double>::infinity()), damper_(damper) {
  measured_.reserve(static_cast<std::size_t>(pairs));
}

void PairDistances::start() {
  for (const int p : measured_) distance_[static_cast<std::size_t>(p)] = std::numeric_limits<double>::infinity();
  measured_.clear();
}

bool PairDistances::take(int row, const ShapeDistance& d, bool planar, const Eigen::Vector3d& fallback,
                         Eigen::Vector3d& n) {
  const double distance = d.ok ? d.distance : std::numeric_limits<double>::quiet_NaN();
  double& slot = distance_[static_cast<std::size_t>(row)];
  // A pair reading +inf is not in the list yet (the list holds each pair once, so it never outgrows its reserve).
  if (slot == std::numeric_limits<double>::infinity() && measured_.size() < measured_.capacity())
    measured_.push_back(row);
  slot = distance;
  failures_ += d.ok ? 0 : 1;  // FCL failed on this pair (rare; near-touching boxes): its row stays slack
  return d.ok && distance <= damper_.influence_distance && witness_normal(d, planar, fallback, n);
}

void check_damper(double influence_distance, double safety_distance) {
  if (!(safety_distance >= 0.0)) throw FieldError("safety_distance", "expected a safety distance >= 0 m");
  if (!(influence_distance > safety_distance)) {
    throw FieldError("influence_distance", "expected an influence distance > the safety distance (" +
                                               std::to_string(safety_distance) + " m)");
  }
}

bool PairDistances::violated() const {
  for (const int p : measured_) {
    const double d = distance_[static_cast<std::size_t>(p)];
    if (d < 0.0 || std::isnan(d)) return true;  // NaN: not measured, so it may overlap
  }
  return false;
}

std::string PairDistances::describe_violation(const std::function<std::string(int)>& describe_row) const {
  const int w = worst();
  if (distance_[static_cast<std::size_t>(w)] < 0.0) return "in collision: " + describe_row(w);
  int failed = -1;
  for (const int p : measured_) {
    if (std::isnan(distance_[static_cast<std::size_t>(p)]) && (failed < 0 || p < failed)) failed = p;
  }
  if (failed >= 0) {
    return "cannot measure the distance (the shapes may overlap; FCL failed on the pair): " + describe_row(failed);
  }
  return {};
}

int PairDistances::worst() const {
  int w = -1;
  for (const int p : measured_) {
    const double d = distance_[static_cast<std::size_t>(p)];
    if (std::isnan(d)) continue;  // an FCL failure
    const double dw = w < 0 ? 0.0 : distance_[static_cast<std::size_t>(w)];
    if (w < 0 || d < dw || (d == dw && p < w)) w = p;
  }
  return w < 0 ? 0 : w;
}

void PairDistances::record(double* values) const {
  double low = std::numeric_limits<double>::infinity();
  int active = 0;
  for (const int p : measured_) {
    const double d = distance_[static_cast<std::size_t>(p)];
    if (std::isnan(d)) continue;
    low = std::min(low, d);
    active += d <= damper_.influence_distance ? 1 : 0;
  }
  values[0] = low;
  values[1] = active;
}

void damper_row(const Damper& damper, double d, const Eigen::Vector3d& n, const Eigen::Matrix3Xd& D,
                const Eigen::Vector3d& v_b, Eigen::Ref<Eigen::RowVectorXd, 0, Eigen::InnerStride<>> A_row, double& b) {
  if (d > damper.influence_distance) {
    slack_row(A_row, b);
    return;
  }
  // Column by column: a product expression here would go through a temporary (an allocation per row).
  for (Eigen::Index c = 0; c < D.cols(); ++c) A_row(c) = -n.dot(D.col(c));
  b = -damper.min_rate(d) - n.dot(v_b);
}

namespace {
bool unit(Eigen::Vector3d v, bool planar, Eigen::Vector3d& n) {
  if (planar) v.z() = 0.0;
  const double len = v.norm();
  if (!(len > 1e-12)) return false;
  n = v / len;
  return true;
}
}  // namespace

bool witness_normal(const ShapeDistance& d, bool planar, const Eigen::Vector3d& fallback, Eigen::Vector3d& n) {
  const Eigen::Vector3d diff = d.point_a - d.point_b;
  if (diff.norm() > 1e-9 && unit((d.distance < 0.0 ? -1.0 : 1.0) * diff, planar, n)) return true;
  if (unit(fallback, planar, n)) return true;
  n.setZero();
  return false;
}

}  // namespace redres

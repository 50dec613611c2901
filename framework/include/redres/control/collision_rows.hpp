#pragma once
/// @file
/// The pieces of a collision-avoidance row, shared by `obstacle_avoidance`, `self_collision` and plugins of one's
/// own: the Jacobian of a point attached to a link, the normal between two witness points (with FCL's sign flip on
/// penetration and the planar projection), and the velocity damper.
///
/// The row (Faverjon and Tournassoud's velocity damper): for a pair at signed distance d <= d_i,
///   n' (J_a - J_b) x >= -xi (d - d_s) / (d_i - d_s) + n' v_b,
/// where n is the unit normal from body b's witness point to body a's (a is a link; b an obstacle with velocity
/// v_b and J_b = 0, or another link with v_b = 0), so that n' (J_a - J_b) x is the rate of change of d. For
/// d_s < d <= d_i the distance may shrink at most at xi (d - d_s) / (d_i - d_s) (m/s): xi at the influence
/// distance, zero at the safety distance. For d < d_s the bound turns positive: the pair must separate at
/// xi (d_s - d) / (d_i - d_s), a speed bounded by the penetration; the arm is pushed out, not held.

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/common/error.hpp"
#include "redres/control/plugin.hpp"
#include "redres/model/collision.hpp"
#include "redres/model/frames.hpp"  // point_jacobian
#include "redres/model/kinematics.hpp"

namespace redres {

/// The damper's parameters.
struct Damper {
  double influence_distance = 0.1;  //!< d_i (m): rows are written for pairs closer than this
  double safety_distance = 0.02;    //!< d_s (m): the distance the damper holds
  double gain = 0.1;                //!< xi (m/s): the largest approach speed, at d_i

  /// The lower bound on d_dot at distance d: -xi (d - d_s) / (d_i - d_s).
  [[nodiscard]] double min_rate(double d) const {
    return -gain * (d - safety_distance) / (influence_distance - safety_distance);
  }
};

/// The distances of a collision constraint's pairs at its last contribution, and what both collision constraints
/// derive from them: the per-step values, the violation (a pair that overlaps) and FCL's failures.
class PairDistances {
 public:
  /// `pairs` rows held by `damper`.
  PairDistances(int pairs, Damper damper);

  /// Starts a contribution: every pair reads as beyond d_i (+inf) until it is measured again (a pair the broadphase
  /// or the cull rules out is never measured). Costs the pairs measured at the last contribution, not all of them,
  /// so that far pairs cost nothing.
  void start();
  /// Records pair `row`'s query (an FCL failure as NaN, counted) and finds its normal (witness_normal(), with
  /// `fallback`). Returns whether the pair gets a damper row: the query worked, the pair is within d_i and the normal
  /// is defined; otherwise the caller writes a slack row.
  bool take(int row, const ShapeDistance& d, bool planar, const Eigen::Vector3d& fallback, Eigen::Vector3d& n);
  /// The damper the pairs are held by.
  [[nodiscard]] const Damper& damper() const noexcept { return damper_; }
  /// Pair `row`'s distance at the last contribution (+inf: not measured, beyond d_i).
  [[nodiscard]] double operator[](int row) const { return distance_[static_cast<std::size_t>(row)]; }
  /// A pair overlaps, or could not be measured (it may overlap).
  [[nodiscard]] bool violated() const;
  /// "in collision: <the worst pair>", or "cannot measure the distance ...: <the pair>" (describe_row(row) names a
  /// pair); empty when nothing is violated.
  [[nodiscard]] std::string describe_violation(const std::function<std::string(int)>& describe_row) const;
  /// The pair with the smallest distance (FCL failures skipped; the lowest index among equals; 0 when none was
  /// measured).
  [[nodiscard]] int worst() const;
  /// Writes the smallest distance and the number of pairs within d_i (two values).
  void record(double* values) const;
  /// Queries FCL failed on since the data was made.
  [[nodiscard]] int failures() const noexcept { return failures_; }

 private:
  std::vector<double> distance_;
  // The pairs whose distance is not +inf (each once; sized for every pair at construction): what the scans read.
  std::vector<int> measured_;
  Damper damper_;
  int failures_ = 0;
};

/// One controller's data of a collision constraint: its own distance query (FCL's objects move with every query, so
/// two controllers never share one) and its pairs' distances at the last contribution.
struct PairData : PluginData {
  /// A query over `shapes`, and `pairs` distances held by `damper`.
  PairData(const std::vector<ShapeSpec>& shapes, int pairs, Damper damper) : query(shapes), distances(pairs, damper) {}
  DistanceQuery query;      //!< the shapes of the constraint's pairs
  PairDistances distances;  //!< one per pair
  int short_of_rows = 0;    //!< contributions with more pairs within d_i than rows (the farthest went without)
};

/// The base of a collision constraint with Config C, whose data derives from PairData (filled by the derived
/// add_to() through PairDistances::take/beyond): the violation (a pair that overlaps or could not be measured,
/// described by the derived describe_inequality_row()).
template <class C>
class PairConstraint : public Configured<Constraint, C> {
 public:
  [[nodiscard]] bool violated(const PluginData* data) const override { return pair_data(data).distances.violated(); }
  [[nodiscard]] std::string describe_violation(const PluginData* data) const override {
    return pair_data(data).distances.describe_violation(
        [this, data](int pair) { return this->describe_pair(data, pair); });
  }
  /// Names pair `pair` (default: the inequality row of the same index, for a constraint with one row per pair).
  [[nodiscard]] virtual std::string describe_pair(const PluginData* data, int pair) const {
    return this->describe_inequality_row(data, pair);
  }

 protected:
  using Configured<Constraint, C>::Configured;
  /// The PairData that make_data() made (std::invalid_argument for none).
  template <class D = PairData>
  [[nodiscard]] static const D& pair_data(const PluginData* data) {
    REDRES_REQUIRE(data != nullptr, "PairConstraint", "the data that make_data() made is given");
    return static_cast<const D&>(*data);
  }
  template <class D = PairData>
  [[nodiscard]] static D& pair_data(PluginData* data) {
    REDRES_REQUIRE(data != nullptr, "PairConstraint", "the data that make_data() made is given");
    return static_cast<D&>(*data);
  }
};

/// Checks the damper's keys of a collision constraint's Config: d_s >= 0 and d_i > d_s (FieldError naming the key).
void check_damper(double influence_distance, double safety_distance);

/// A row that every x meets and that leaves the duals alone: A_row = 0, b = 1.
inline void slack_row(Eigen::Ref<Eigen::RowVectorXd, 0, Eigen::InnerStride<>> A_row, double& b) {
  A_row.setZero();
  b = 1.0;
}

/// Writes the row of the damper as `A_row x <= b` for a pair at distance d with normal n (from b to a), the rate
/// Jacobian D = J_a - J_b (3 x n) and b's velocity v_b: A_row = -n' D, b = -min_rate(d) - n' v_b. A pair farther
/// than d_i gets a slack row (A_row = 0, b = 1).
void damper_row(const Damper& damper, double d, const Eigen::Vector3d& n, const Eigen::Matrix3Xd& D,
                const Eigen::Vector3d& v_b, Eigen::Ref<Eigen::RowVectorXd, 0, Eigen::InnerStride<>> A_row, double& b);

/// The unit normal from witness point `on_b` to `on_a` for signed distance d (FCL's points swap sides when the
/// shapes overlap, so the direction is sign(d) (on_a - on_b)). For a planar robot the normal is projected into the
/// plane z = 0. When it is undefined (touching points, or a projection that vanishes, as for two crossing planar
/// capsules) `fallback` (from b's centre to a's, say) is used, projected the same way. Returns false when that
/// too is degenerate; then `n` is zero.
bool witness_normal(const ShapeDistance& d, bool planar, const Eigen::Vector3d& fallback, Eigen::Vector3d& n);

}  // namespace redres

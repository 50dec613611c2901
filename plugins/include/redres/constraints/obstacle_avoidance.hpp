#pragma once
/// @file
/// `obstacle_avoidance`: keeps the robot's collision shapes (the `collision` shapes of its joints in the robot
/// file) away from obstacles, one inequality row per (link shape, obstacle) pair, the velocity damper of
/// collision_rows.hpp:
///   n' J_p x >= -xi (d - d_s) / (d_i - d_s) + n' v_obstacle     for d <= d_i (slack otherwise),
/// with d the signed distance (FCL), n the unit normal from the obstacle's witness point to the link's, and J_p
/// the translational Jacobian of the link's witness point. Below d_s the bound pushes the link out at a speed
/// proportional to the penetration. Obstacles are spheres, capsules, cylinders or boxes with a pose in the world
/// (base) frame, optionally moving at a constant velocity; for a planar robot they lie in the plane z = 0.
/// Records per step `min_obstacle_distance` (m) and `obstacle_rows_active`; reports `min_obstacle_distance` and
/// `steps_with_active_rows` to the run summary, and its obstacles to summary.json's `obstacles` (for drawing).
///
/// Pairs: brute force over the fixed list (every link shape against every obstacle: about 0.1 us per analytic
/// pair), or, for scenes with many pairs (`broadphase = "auto"`: more than kBroadphasePairs), FCL's dynamic AABB tree
/// over the obstacles, which returns every obstacle whose bounding box lies within d_i of a link shape's; only those
/// pairs are measured, the others are beyond d_i and keep a slack row (their distance is not computed: recorded as
/// +inf). The rows are the same either way.

#include <array>
#include <string_view>
#include <utility>
#include <vector>

#include "redres/control/collision_rows.hpp"
#include "redres/control/plugin.hpp"
#include "redres/model/collision.hpp"
#include "redres/run/collision_output.hpp"

namespace redres {

/// The configuration of `obstacle_avoidance`.
struct ObstacleAvoidanceConfig {
  std::vector<ShapeSpec> obstacles{};  //!< required: the obstacles, in the world frame
  double influence_distance = 0.10;    //!< d_i (m)
  double safety_distance = 0.02;       //!< d_s (m)
  double xi = 0.1;                     //!< damper gain (m/s): the largest approach speed, at d_i
  /// How pairs are found: `auto` (the tree above kBroadphasePairs pairs), `always` (the tree), `never` (brute force).
  enum class Broadphase { kAuto, kAlways, kNever };
  Broadphase broadphase = Broadphase::kAuto;  //!< see above
  /// The most inequality rows: pairs within d_i share them, the nearest first (a scene of 10,000 obstacles needs
  /// rows for the few pairs near the arm, not for every pair: the QP's size, and the engines' memory, stay bounded).
  int max_rows = 64;

  static const Schema<ObstacleAvoidanceConfig>& schema();
};

/// The obstacle-avoidance constraint.
/// Names of the broadphase modes in TOML.
inline auto enum_names(ObstacleAvoidanceConfig::Broadphase) {
  using B = ObstacleAvoidanceConfig::Broadphase;
  return std::array{std::pair{B::kAuto, std::string_view("auto")}, std::pair{B::kAlways, std::string_view("always")},
                    std::pair{B::kNever, std::string_view("never")}};
}

/// Above this many (link shape, obstacle) pairs, `broadphase = "auto"` uses FCL's tree.
inline constexpr int kBroadphasePairs = 256;
/// The most (link shape, obstacle) pairs a scene may have, checked at load (each pair keeps its distance, a few
/// bytes; the rows are bounded by `max_rows`).
inline constexpr long kMaxObstaclePairs = 10'000'000;

class ObstacleAvoidance final : public PairConstraint<ObstacleAvoidanceConfig>, public PairOutput {
 public:
  static constexpr const char* kType = "obstacle_avoidance";
  ObstacleAvoidance(const Config& config, const RobotModel& robot);
  ~ObstacleAvoidance() override;

  /// A distance query over the link shapes and the obstacles (its broadphase tree over the obstacles when it is
  /// used), the pairs' distances, and the scratch of a step.
  [[nodiscard]] std::unique_ptr<PluginData> make_data() const override;
  [[nodiscard]] int inequality_rows(const RobotModel& robot) const override;
  [[nodiscard]] std::string describe_inequality_row(const PluginData* data, int row) const override;
  void describe_inequality_row_to(const PluginData* data, int row, TextSink& out) const override;
  [[nodiscard]] std::string describe_pair(const PluginData* data, int pair) const override;
  /// Its obstacles, as configured (summary.json's `obstacles`).
  void scene_obstacles(std::vector<ShapeSpec>& out) const override;

  /// The obstacle's world pose at time t (its pose moved by velocity * t).
  [[nodiscard]] Eigen::Isometry3d obstacle_pose(int k, double t) const;

 private:
  // Writes pair `pair` (link, obstacle, distance) into `out`.
  void describe_pair_to(const PluginData* data, int pair, TextSink& out) const;
  struct Data;
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const override;
  // The row of link shape l (at Tl) against obstacle o (at To): measured, then a damper or a slack row.
  void pair_row(Data& data, const KinematicsData& kin, int l, const Eigen::Isometry3d& Tl, int o,
                const Eigen::Isometry3d& To, Eigen::Block<Eigen::MatrixXd>& A,
                Eigen::VectorBlock<Eigen::VectorXd>& b) const;
  // A shared row for `pair` at `distance` (the farthest pair's when all are taken and this one is nearer), or -1.
  // `sub`: 0 for the witness point's row, 1 to 8 for a box corner's.
  int claim_row(Data& data, int pair, int sub, double distance) const;
  // The rows of a pair with link shape l: 9 for a box (its witness point and its corners), else 1.
  [[nodiscard]] int rows_of_link(int l) const;
  // The broadphase path of add_to(): only the pairs the tree finds near are measured.
  void add_near_pairs(Data& data, const Context& ctx, QpBuilder& builder) const;

  const RobotModel* robot_;
  std::vector<ShapeSpec> shapes_;  // the query's shapes: link shapes first, then the obstacles
  int links_ = 0, obstacles_ = 0;
  int rows_ = 0;                // inequality rows: one per pair (nine for a box link), or max_rows shared
  bool pooled_ = false;         // more rows than max_rows: the pairs within d_i share max_rows rows
  std::vector<int> first_row_;  // not pooled: pair p's rows are [first_row_[p], first_row_[p + 1])
  // Broadphase: whether it is used; whether an obstacle moves; whether the robot is planar.
  bool broadphase_ = false, moving_ = false, planar_ = false;
  // Each obstacle's pose at t = 0 and its velocity (zero when it stands still).
  std::vector<Eigen::Isometry3d> start_poses_;
  std::vector<Eigen::Vector3d> velocities_;
};

}  // namespace redres

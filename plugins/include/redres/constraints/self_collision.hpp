#pragma once
/// @file
/// `self_collision`: keeps the robot's links away from each other: one inequality row per pair of collision
/// shapes on links that may touch (not the same link, not adjacent links, not a pair the robot file's
/// `collision_exclude` lists), the velocity damper of collision_rows.hpp with both bodies moving:
///   n' (J_a - J_b) x >= -xi (d - d_s) / (d_i - d_s)     for d <= d_i (slack otherwise),
/// with n the unit normal from link b's witness point to link a's. Below d_s the bound pushes the links apart.
/// Records per step `min_self_distance` (m) and `self_rows_active`; reports `min_self_distance` and
/// `steps_with_active_rows` to the run summary.

#include <utility>
#include <vector>

#include "redres/control/collision_rows.hpp"
#include "redres/control/plugin.hpp"
#include "redres/model/collision.hpp"
#include "redres/run/collision_output.hpp"

namespace redres {

/// The configuration of `self_collision`.
struct SelfCollisionConfig {
  double influence_distance = 0.05;  //!< d_i (m)
  double safety_distance = 0.01;     //!< d_s (m)
  double xi = 0.1;                   //!< damper gain (m/s)

  static const Schema<SelfCollisionConfig>& schema();
};

/// The self-collision constraint.
class SelfCollision final : public PairConstraint<SelfCollisionConfig>, public PairOutput {
 public:
  static constexpr const char* kType = "self_collision";
  SelfCollision(const Config& config, const RobotModel& robot);
  ~SelfCollision() override;

  /// A distance query over the link shapes, the pairs' distances, and the two witness points' Jacobians.
  [[nodiscard]] std::unique_ptr<PluginData> make_data() const override;
  [[nodiscard]] int inequality_rows(const RobotModel& robot) const override;
  [[nodiscard]] std::string describe_inequality_row(const PluginData* data, int row) const override;
  void describe_inequality_row_to(const PluginData* data, int row, TextSink& out) const override;
  /// The checked pairs (indices into RobotModel::link_shapes()).
  [[nodiscard]] const std::vector<std::pair<int, int>>& pairs() const noexcept { return pairs_; }

 private:
  struct Data;
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const override;

  const RobotModel* robot_;
  std::vector<ShapeSpec> shapes_;  // the link shapes
  std::vector<std::pair<int, int>> pairs_;
};

}  // namespace redres

#include "redres/constraints/self_collision.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace redres {

// One controller's data: the query, the distances, and the Jacobians of the two witness points.
struct SelfCollision::Data : PairData {
  Data(const std::vector<ShapeSpec>& shapes, int pairs, Damper damper, int dof) : PairData(shapes, pairs, damper) {
    ja.setZero(3, dof);
    jb.setZero(3, dof);
  }
  Eigen::Matrix3Xd ja, jb;
};

const Schema<SelfCollisionConfig>& SelfCollisionConfig::schema() {
  using C = SelfCollisionConfig;
  static const Schema<C> s{
      {field("influence_distance", &C::influence_distance, "m", "d_i: rows for pairs closer than this"),
       field("safety_distance", &C::safety_distance, "m", "d_s: the distance the damper holds"),
       field("xi", &C::xi, "m/s", "damper gain: the largest approach speed, at d_i", greater(0.0))},
      [](const C& c) { check_damper(c.influence_distance, c.safety_distance); },
      {}};
  return s;
}

SelfCollision::SelfCollision(const Config& config, const RobotModel& robot)
    : PairConstraint(kType, config), PairOutput(*this, "min_self_distance", "self_rows_active"), robot_(&robot) {
  const auto& links = robot.link_shapes();
  if (links.empty()) {
    throw FieldError("", "robot '" + robot.name() +
                             "' has no collision shapes: give its joints `collision` shapes (docs/collision.md)");
  }
  for (const auto& l : links) shapes_.push_back(l.spec);
  for (std::size_t i = 0; i < links.size(); ++i) {
    for (std::size_t j = i + 1; j < links.size(); ++j) {
      if (robot.self_collision_bodies(links[i].body, links[j].body)) {
        pairs_.emplace_back(static_cast<int>(i), static_cast<int>(j));
      }
    }
  }
  if (pairs_.empty()) {
    throw FieldError("", "robot '" + robot.name() +
                             "' has no pair of link shapes to check: every pair is on one link, "
                             "on neighbouring links or in collision_exclude (docs/collision.md)");
  }
  (void)DistanceQuery(shapes_);  // checks the shapes' sizes now, naming the shape, rather than at the first run
}

SelfCollision::~SelfCollision() = default;

std::unique_ptr<PluginData> SelfCollision::make_data() const {
  return std::make_unique<Data>(shapes_, static_cast<int>(pairs_.size()),
                                Damper{config_.influence_distance, config_.safety_distance, config_.xi}, robot_->dof());
}

int SelfCollision::inequality_rows(const RobotModel& /*robot*/) const { return static_cast<int>(pairs_.size()); }

void SelfCollision::add_to(const Context& ctx, QpBuilder& builder, PluginData* plugin_data) const {
  Data& data = pair_data<Data>(plugin_data);
  const KinematicsData& kin = *ctx.kinematics;
  const bool planar = robot_->kind() == ChainKind::kPlanar;
  auto A = builder.inequality_matrix();
  auto b = builder.inequality_rhs();
  const auto& links = robot_->link_shapes();
  data.distances.start();  // a pair whose closed-form lower bound exceeds d_i is beyond d_i: not measured, +inf
  const double within = data.distances.damper().influence_distance;
  for (std::size_t row = 0; row < pairs_.size(); ++row) {
    const auto& sa = links[static_cast<std::size_t>(pairs_[row].first)];
    const auto& sb = links[static_cast<std::size_t>(pairs_[row].second)];
    const Eigen::Isometry3d Ta = kin.link_frames[static_cast<std::size_t>(sa.link)] * sa.pose;
    const Eigen::Isometry3d Tb = kin.link_frames[static_cast<std::size_t>(sb.link)] * sb.pose;
    const auto r = static_cast<Eigen::Index>(row);
    if (data.query.lower_bound(pairs_[row].first, Ta, pairs_[row].second, Tb) > within) {
      slack_row(A.row(r), b(r));
      continue;
    }
    const ShapeDistance d = data.query.distance(pairs_[row].first, Ta, pairs_[row].second, Tb);
    Eigen::Vector3d n;
    if (!data.distances.take(static_cast<int>(row), d, planar, Ta.translation() - Tb.translation(), n)) {
      slack_row(A.row(r), b(r));
      continue;
    }
    point_jacobian(*robot_, kin, sa.link, d.point_a, data.ja);
    point_jacobian(*robot_, kin, sb.link, d.point_b, data.jb);
    data.ja -= data.jb;
    damper_row(data.distances.damper(), d.distance, n, data.ja, Eigen::Vector3d::Zero(), A.row(r), b(r));
  }
}

void SelfCollision::describe_inequality_row_to(const PluginData* data, int row, TextSink& s) const {
  if (row < 0 || row >= static_cast<int>(pairs_.size()) || data == nullptr) return;
  const auto& links = robot_->link_shapes();
  const auto& sa = links[static_cast<std::size_t>(pairs_[static_cast<std::size_t>(row)].first)];
  const auto& sb = links[static_cast<std::size_t>(pairs_[static_cast<std::size_t>(row)].second)];
  s << "link '" << robot_->bodies()[static_cast<std::size_t>(sa.body)].name << "' ";
  sa.spec.describe(s);
  s << " vs link '" << robot_->bodies()[static_cast<std::size_t>(sb.body)].name << "' ";
  sb.spec.describe(s);
  s.precision(4);
  s << " at distance " << pair_data(data).distances[row] << " m";
}

std::string SelfCollision::describe_inequality_row(const PluginData* data, int row) const {
  return text_of([&](TextSink& s) { describe_inequality_row_to(data, row, s); });
}

namespace {
const bool kSelfCollisionRegistered = constraint_registry().add_plugin<SelfCollision>(
    "n' (J_a - J_b) x >= -xi (d - d_s)/(d_i - d_s): links kept away from each other (FCL distances)");
}  // namespace

}  // namespace redres

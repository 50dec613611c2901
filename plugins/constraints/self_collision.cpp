#include "redres/constraints/self_collision.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "redres/run/trajectory.hpp"

namespace redres {

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
    : PairConstraint(kType, config), robot_(&robot) {
  const auto& links = robot.link_shapes();
  if (links.empty()) {
    throw FieldError("", "robot '" + robot.name() +
                             "' has no collision shapes: give its joints `collision` shapes (docs/collision.md)");
  }
  std::vector<ShapeSpec> shapes;
  for (const auto& l : links) shapes.push_back(l.spec);
  for (std::size_t i = 0; i < links.size(); ++i) {
    for (std::size_t j = i + 1; j < links.size(); ++j) {
      if (robot.self_collision_pair(links[i].link, links[j].link)) {
        pairs_.emplace_back(static_cast<int>(i), static_cast<int>(j));
      }
    }
  }
  query_ = std::make_unique<DistanceQuery>(shapes);
  ja_.setZero(3, robot.dof());
  jb_.setZero(3, robot.dof());
  distances_ =
      PairDistances(static_cast<int>(pairs_.size()), {config.influence_distance, config.safety_distance, config.xi},
                    "min_self_distance", "self_rows_active");
}

SelfCollision::~SelfCollision() = default;

int SelfCollision::inequality_rows(const RobotModel& /*robot*/) const { return static_cast<int>(pairs_.size()); }

void SelfCollision::add_to(const Context& ctx, QpBuilder& builder) const {
  const KinematicsData& kin = *ctx.kinematics;
  const bool planar = robot_->kind() == ChainKind::kPlanar;
  auto A = builder.inequality_matrix();
  auto b = builder.inequality_rhs();
  const auto& links = robot_->link_shapes();
  for (std::size_t row = 0; row < pairs_.size(); ++row) {
    const auto& sa = links[static_cast<std::size_t>(pairs_[row].first)];
    const auto& sb = links[static_cast<std::size_t>(pairs_[row].second)];
    const Eigen::Isometry3d Ta = kin.link_frames[static_cast<std::size_t>(sa.link)] * sa.pose;
    const Eigen::Isometry3d Tb = kin.link_frames[static_cast<std::size_t>(sb.link)] * sb.pose;
    const ShapeDistance d = query_->distance(pairs_[row].first, Ta, pairs_[row].second, Tb);
    const auto r = static_cast<Eigen::Index>(row);
    Eigen::Vector3d n;
    if (!distances_.take(static_cast<int>(row), d, planar, Ta.translation() - Tb.translation(), n)) {
      slack_row(A.row(r), b(r));
      continue;
    }
    point_jacobian(*robot_, kin, sa.link, d.point_a, ja_);
    point_jacobian(*robot_, kin, sb.link, d.point_b, jb_);
    ja_ -= jb_;
    damper_row(distances_.damper(), d.distance, n, ja_, Eigen::Vector3d::Zero(), A.row(r), b(r));
  }
}

std::string SelfCollision::describe_inequality_row(int row) const {
  if (row < 0 || row >= static_cast<int>(pairs_.size())) return {};
  const auto& links = robot_->link_shapes();
  const auto& sa = links[static_cast<std::size_t>(pairs_[static_cast<std::size_t>(row)].first)];
  const auto& sb = links[static_cast<std::size_t>(pairs_[static_cast<std::size_t>(row)].second)];
  std::ostringstream s;
  s.precision(4);
  s << "link '" << robot_->joint(sa.link).name << "' " << sa.spec.describe() << " vs link '"
    << robot_->joint(sb.link).name << "' " << sb.spec.describe() << " at distance " << distances_[row] << " m";
  return s.str();
}

namespace {
const bool kRegistered = constraint_registry().add_plugin<SelfCollision>(
    "n' (J_a - J_b) x >= -xi (d - d_s)/(d_i - d_s): links kept away from each other (FCL distances)");
}  // namespace

}  // namespace redres

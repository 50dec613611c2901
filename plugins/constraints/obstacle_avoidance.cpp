#include "redres/constraints/obstacle_avoidance.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "redres/parsers/cloud_file.hpp"

namespace redres {

// One controller's data: the query (and its tree), the distances, and a step's scratch: the witness point's
// Jacobian, whether the tree holds the obstacles' poses yet, the obstacles' poses this step, and the candidates
// near() returns for one link shape.
struct ObstacleAvoidance::Data : PairData {
  Data(const std::vector<ShapeSpec>& shapes, int pairs, Damper damper, int dof) : PairData(shapes, pairs, damper) {
    jacobian.setZero(3, dof);
  }
  Eigen::Matrix3Xd jacobian;
  bool placed = false;
  std::vector<Eigen::Isometry3d> poses;
  std::vector<int> candidates;
  // Shared rows (more pairs than max_rows): the pair each row holds at this contribution (-1: none) and its distance.
  std::vector<int> row_pair, row_sub;  // row_sub: 0 the witness point's row, 1 to 8 a box corner's
  std::vector<double> row_distance;
  int used = 0, dropped = 0;
};

const Schema<ObstacleAvoidanceConfig>& ObstacleAvoidanceConfig::schema() {
  using C = ObstacleAvoidanceConfig;
  static const Schema<C> s{
      {field("obstacles", &C::obstacles, "", "the obstacles (world frame)").required(),
       field("influence_distance", &C::influence_distance, "m", "d_i: rows for pairs closer than this"),
       field("safety_distance", &C::safety_distance, "m", "d_s: the distance the damper holds"),
       field("xi", &C::xi, "m/s", "damper gain: the largest approach speed, at d_i", greater(0.0)),
       field("broadphase", &C::broadphase, "",
             "how pairs are found: auto (FCL's AABB tree above 256 pairs, a closed-form cull below), always (the "
             "tree), never (every pair measured)"),
       field("max_rows", &C::max_rows, "",
             "the most inequality rows: with more pairs, those within d_i share them, the nearest first",
             between<int>(1, 100000))},
      [](const C& c) {
        check_damper(c.influence_distance, c.safety_distance);
        for (std::size_t k = 0; k < c.obstacles.size(); ++k) {
          const ShapeSpec& o = c.obstacles[k];
          if (o.shape == ShapeSpec::Kind::kCapsule && !o.from && !o.length) {
            throw FieldError("obstacles", "obstacle " + std::to_string(k + 1) +
                                              ": a capsule obstacle needs `length` (with xyz, rpy) or `from`/`to`");
          }
        }
      },
      {}};
  return s;
}

ObstacleAvoidance::ObstacleAvoidance(const Config& config, const RobotModel& robot)
    : PairConstraint(kType, config),
      PairOutput(*this, "min_obstacle_distance", "obstacle_rows_active"),
      robot_(&robot) {
  const auto& links = robot.link_shapes();
  if (links.empty()) {
    throw FieldError(
        "obstacles",
        "robot '" + robot.name() + "' has no collision shapes: give its joints `collision` shapes (docs/collision.md)");
  }
  const bool planar = robot.kind() == ChainKind::kPlanar;
  std::vector<ShapeSpec>& shapes = shapes_;
  for (const auto& l : links) shapes.push_back(l.spec);
  for (std::size_t k = 0; k < config_.obstacles.size(); ++k) {
    ShapeSpec& o = config_.obstacles[k];
    if (o.is_cloud()) {
      // Read once here; every controller's query shares the cells.
      try {
        load_cloud(o);
      } catch (const std::invalid_argument& e) {
        throw FieldError("obstacles", "obstacle " + std::to_string(k + 1) + " (" +
                                          std::string(config_io::enum_name(o.shape)) + "): " + e.what());
      }
    } else if (planar && (o.pose().translation().z() != 0.0 || (o.velocity && (*o.velocity)[2] != 0.0))) {
      throw FieldError("obstacles", "obstacle " + std::to_string(k + 1) +
                                        ": a planar robot moves in the plane z = 0; centre its obstacles there (and "
                                        "keep their velocity in it)");
    }
    shapes.push_back(o);
  }
  links_ = static_cast<int>(links.size());
  obstacles_ = static_cast<int>(config_.obstacles.size());
  const long pairs = static_cast<long>(links_) * obstacles_;
  if (pairs > kMaxObstaclePairs) {
    throw FieldError("obstacles", std::to_string(obstacles_) + " obstacles and " + std::to_string(links_) +
                                      " link shapes make " + std::to_string(pairs) + " pairs; at most " +
                                      std::to_string(kMaxObstaclePairs) + " are checked");
  }
  // A box link gets a row for each corner besides its witness point's: with one row per pair, a flat face held at
  // d_s by its lowest corner could turn the next corner through d_s within a step.
  long rows = 0;
  first_row_.assign(static_cast<std::size_t>(pairs) + 1, 0);
  for (long p = 0; p < pairs; ++p) {
    first_row_[static_cast<std::size_t>(p)] = static_cast<int>(std::min<long>(rows, INT32_MAX));
    rows += rows_of_link(static_cast<int>(p % links_));
  }
  first_row_.back() = static_cast<int>(std::min<long>(rows, INT32_MAX));
  rows_ = static_cast<int>(std::min<long>(rows, config_.max_rows));
  pooled_ = rows_ < rows;
  if (pooled_) first_row_.clear();
  (void)DistanceQuery(shapes);  // checks the shapes' sizes now, naming the shape, rather than at the first run
  using B = Config::Broadphase;
  broadphase_ =
      config_.broadphase == B::kAlways || (config_.broadphase == B::kAuto && links_ * obstacles_ > kBroadphasePairs);
  planar_ = robot.kind() == ChainKind::kPlanar;
  for (const ShapeSpec& o : config_.obstacles) {
    start_poses_.push_back(o.pose());
    velocities_.push_back(o.velocity ? Eigen::Vector3d(o.velocity->data()) : Eigen::Vector3d::Zero());
    moving_ = moving_ || o.velocity.has_value();
  }
}

ObstacleAvoidance::~ObstacleAvoidance() = default;

std::unique_ptr<PluginData> ObstacleAvoidance::make_data() const {
  auto data =
      std::make_unique<Data>(shapes_, links_ * obstacles_,
                             Damper{config_.influence_distance, config_.safety_distance, config_.xi}, robot_->dof());
  if (broadphase_) {
    data->query.build_broadphase(links_, obstacles_);
    data->poses.resize(static_cast<std::size_t>(obstacles_));
    data->candidates.resize(static_cast<std::size_t>(obstacles_));
  }
  if (pooled_) {
    data->row_pair.assign(static_cast<std::size_t>(rows_), -1);
    data->row_sub.assign(static_cast<std::size_t>(rows_), 0);
    data->row_distance.assign(static_cast<std::size_t>(rows_), 0.0);
  }
  return data;
}

int ObstacleAvoidance::inequality_rows(const RobotModel& /*robot*/) const { return rows_; }

int ObstacleAvoidance::rows_of_link(int l) const {
  return robot_->link_shapes()[static_cast<std::size_t>(l)].spec.shape == ShapeSpec::Kind::kBox ? 9 : 1;
}

int ObstacleAvoidance::claim_row(Data& data, int pair, int sub, double distance) const {
  int row = -1;
  if (data.used < rows_) {
    row = data.used++;
  } else {
    // Every row holds a pair: this one takes the farthest's row if it is nearer (that pair goes without).
    ++data.dropped;
    const auto far = std::max_element(data.row_distance.begin(), data.row_distance.end());
    if (!(distance < *far)) return -1;
    row = static_cast<int>(far - data.row_distance.begin());
  }
  data.row_pair[static_cast<std::size_t>(row)] = pair;
  data.row_sub[static_cast<std::size_t>(row)] = sub;
  data.row_distance[static_cast<std::size_t>(row)] = distance;
  return row;
}

Eigen::Isometry3d ObstacleAvoidance::obstacle_pose(int k, double t) const {
  Eigen::Isometry3d T = start_poses_[static_cast<std::size_t>(k)];
  T.translation() += t * velocities_[static_cast<std::size_t>(k)];
  return T;
}

void ObstacleAvoidance::add_to(const Context& ctx, QpBuilder& builder, PluginData* plugin_data) const {
  Data& data = pair_data<Data>(plugin_data);
  const KinematicsData& kin = *ctx.kinematics;
  auto A = builder.inequality_matrix();
  auto b = builder.inequality_rhs();
  const auto& links = robot_->link_shapes();
  data.distances.start();  // every pair beyond d_i until measured: far pairs cost nothing
  if (pooled_) {
    data.used = data.dropped = 0;
    std::fill(data.row_pair.begin(), data.row_pair.end(), -1);
  }
  // Rows start slack (at most max_rows: the rows are shared past that); near pairs write theirs below.
  for (int r = 0; r < rows_; ++r) slack_row(A.row(r), b(r));
  if (broadphase_) {
    add_near_pairs(data, ctx, builder);
  } else {
    // Too few pairs for the tree: each pair is culled by its closed-form lower bound (unless broadphase = "never",
    // which measures every pair); a culled pair is beyond d_i, its distance reads +inf and its rows are slack.
    const bool cull = config_.broadphase != Config::Broadphase::kNever;
    const double within = data.distances.damper().influence_distance;
    for (int o = 0; o < obstacles_; ++o) {
      const Eigen::Isometry3d To = obstacle_pose(o, ctx.t);
      for (int l = 0; l < links_; ++l) {
        const auto& shape = links[static_cast<std::size_t>(l)];
        const Eigen::Isometry3d Tl = kin.link_frames[static_cast<std::size_t>(shape.link)] * shape.pose;
        if (cull && data.query.lower_bound(l, Tl, links_ + o, To) > within) continue;
        pair_row(data, kin, l, Tl, o, To, A, b);
      }
    }
  }
  if (data.dropped > 0) ++data.short_of_rows;
}

void ObstacleAvoidance::pair_row(Data& data, const KinematicsData& kin, int l, const Eigen::Isometry3d& Tl, int o,
                                 const Eigen::Isometry3d& To, Eigen::Block<Eigen::MatrixXd>& A,
                                 Eigen::VectorBlock<Eigen::VectorXd>& b) const {
  const int pair = o * links_ + l;
  const int first = pooled_ ? -1 : first_row_[static_cast<std::size_t>(pair)];
  const int count = pooled_ ? 0 : first_row_[static_cast<std::size_t>(pair) + 1] - first;
  const ShapeDistance d = data.query.distance(l, Tl, links_ + o, To, data.distances.damper().influence_distance);
  Eigen::Vector3d n;
  if (!data.distances.take(pair, d, planar_, Tl.translation() - To.translation(), n)) {
    for (int r = first; r < first + count; ++r) slack_row(A.row(r), b(r));  // shared rows start slack
    return;
  }
  const auto& shape = robot_->link_shapes()[static_cast<std::size_t>(l)];
  const Damper& damper = data.distances.damper();
  const Eigen::Vector3d& v = velocities_[static_cast<std::size_t>(o)];
  const int row = pooled_ ? claim_row(data, pair, 0, d.distance) : first;
  if (row >= 0) {
    point_jacobian(*robot_, kin, shape.link, d.point_a, data.jacobian);
    damper_row(damper, d.distance, n, data.jacobian, v, A.row(row), b(row));
  }
  if (shape.spec.shape != ShapeSpec::Kind::kBox) return;
  // The box's corners within d_i get rows of their own (a corner inside the obstacle is left to the witness row).
  const std::array<double, 3>& size = *shape.spec.size;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d local(((c & 1) ? 0.5 : -0.5) * size[0], ((c & 2) ? 0.5 : -0.5) * size[1],
                                ((c & 4) ? 0.5 : -0.5) * size[2]);
    const Eigen::Vector3d p = Tl * local;
    const Eigen::Vector3d q = data.query.nearest_point(links_ + o, To, p);
    Eigen::Vector3d nc = p - q;
    if (planar_) nc.z() = 0.0;
    const double dc = (p - q).norm();
    int r = pooled_ ? -1 : first + 1 + c;
    if (!(dc > 0.0 && dc < damper.influence_distance && nc.norm() > 1e-12 * dc)) {
      if (!pooled_) slack_row(A.row(r), b(r));
      continue;
    }
    if (pooled_ && (r = claim_row(data, pair, c + 1, dc)) < 0) continue;
    nc.normalize();
    point_jacobian(*robot_, kin, shape.link, p, data.jacobian);
    damper_row(damper, dc, nc, data.jacobian, v, A.row(r), b(r));
  }
}

void ObstacleAvoidance::add_near_pairs(Data& data, const Context& ctx, QpBuilder& builder) const {
  const KinematicsData& kin = *ctx.kinematics;
  auto A = builder.inequality_matrix();
  auto b = builder.inequality_rhs();
  const auto& links = robot_->link_shapes();
  // The tree holds the obstacles' boxes: static ones are placed once, moving ones moved and refitted every step.
  if (moving_ || !data.placed) {
    for (int o = 0; o < obstacles_; ++o) data.poses[static_cast<std::size_t>(o)] = obstacle_pose(o, ctx.t);
    data.query.move_group(data.poses.data());
    data.placed = true;
  }
  for (int l = 0; l < links_; ++l) {
    const auto& shape = links[static_cast<std::size_t>(l)];
    const Eigen::Isometry3d Tl = kin.link_frames[static_cast<std::size_t>(shape.link)] * shape.pose;
    // The pairs the tree does not return are beyond d_i: their distance reads +inf and their rows stay slack.
    const int count = data.query.near(l, Tl, data.distances.damper().influence_distance, data.candidates.data());
    for (int k = 0; k < count; ++k) {
      const int o = data.candidates[static_cast<std::size_t>(k)] - links_;
      pair_row(data, kin, l, Tl, o, data.poses[static_cast<std::size_t>(o)], A, b);
    }
  }
}

void ObstacleAvoidance::describe_inequality_row_to(const PluginData* data, int row, TextSink& s) const {
  if (row < 0 || row >= rows_ || data == nullptr) return;
  int pair = 0, sub = 0;
  if (pooled_) {
    pair = pair_data<Data>(data).row_pair[static_cast<std::size_t>(row)];
    sub = pair_data<Data>(data).row_sub[static_cast<std::size_t>(row)];
    if (pair < 0) {
      s << "a shared row that no pair within d_i held";
      return;
    }
  } else {
    pair = static_cast<int>(std::upper_bound(first_row_.begin(), first_row_.end(), row) - first_row_.begin()) - 1;
    sub = row - first_row_[static_cast<std::size_t>(pair)];
  }
  describe_pair_to(data, pair, s);
  if (sub > 0) s << " (corner " << sub << " of the link's box)";
}

std::string ObstacleAvoidance::describe_inequality_row(const PluginData* data, int row) const {
  return text_of([&](TextSink& s) { describe_inequality_row_to(data, row, s); });
}

void ObstacleAvoidance::describe_pair_to(const PluginData* data, int pair, TextSink& s) const {
  if (pair < 0 || pair >= links_ * obstacles_ || data == nullptr) return;
  const int o = pair / links_, l = pair % links_;
  const auto& shape = robot_->link_shapes()[static_cast<std::size_t>(l)];
  s << "link '" << robot_->bodies()[static_cast<std::size_t>(shape.body)].name << "' ";
  shape.spec.describe(s);
  s << " vs obstacle " << o + 1 << " ";
  config_.obstacles[static_cast<std::size_t>(o)].describe(s);
  s.precision(4);
  s << " at distance " << pair_data(data).distances[pair] << " m";
}

std::string ObstacleAvoidance::describe_pair(const PluginData* data, int pair) const {
  return text_of([&](TextSink& s) { describe_pair_to(data, pair, s); });
}

void ObstacleAvoidance::scene_obstacles(std::vector<ShapeSpec>& out) const {
  out.insert(out.end(), config_.obstacles.begin(), config_.obstacles.end());
}

namespace {
// For the conformance checks (obstacles have no default): a sphere in the plane, near the test arms' reach.
ObstacleAvoidanceConfig example() {
  ShapeSpec sphere;
  sphere.shape = ShapeSpec::Kind::kSphere;
  sphere.radius = 0.1;
  sphere.xyz = {0.6, 0.6, 0.0};
  ObstacleAvoidanceConfig c;
  c.obstacles = {sphere};
  c.influence_distance = 2.0;  // every pair gets a row, so the checks see real rows
  return c;
}

const bool kObstacleAvoidanceRegistered = constraint_registry().add_plugin<ObstacleAvoidance>(
    "n' J_p x >= -xi (d - d_s)/(d_i - d_s) + n' v_obstacle: links kept away from obstacles (FCL distances)", example());
}  // namespace

}  // namespace redres

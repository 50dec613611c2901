// DistanceQuery: the shapes built once as FCL geometry and as cores (model/shape_cores.hpp, the measures made without
// FCL), and the distance, nearest-point and lower-bound queries on them, with FCL's broadphase. The only translation
// unit that includes FCL (its headers cost seconds and hundreds of MB to compile).

#include "redres/model/collision.hpp"

#include "redres/common/error.hpp"
#include "redres/model/convex.hpp"

#include "model/closed_form_distance.hpp"
#include "model/occupancy.hpp"
#include "model/shape_cores.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>
#include <fcl/narrowphase/distance_request.h>
#include <fcl/narrowphase/distance_result.h>

namespace redres {

namespace {

Eigen::Vector3d vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

}  // namespace

// The FCL side of the shapes, beside their cores.
struct DistanceQuery::Impl : ShapeCores {
  std::vector<Eigen::Isometry3d> object_offset;  // the FCL object's pose in the shape's frame (a cloud's box)
  // One CollisionObject per shape: FCL's object overload of distance() allocates nothing for analytic pairs, while
  // its geometry-and-transform overload allocates once per call (measured: one per query).
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  fcl::DistanceRequestd unsigned_request;
  mutable fcl::DistanceResultd result;
  // The broadphase over the group [group_first, group_first + group_count): its objects carry their shape index as
  // user data.
  std::unique_ptr<fcl::DynamicAABBTreeCollisionManagerd> tree;
  int group_first = 0, group_count = 0;
};

namespace {

// What near()'s callback collects: group objects whose bounding box is closer than `within` to the query's.
struct NearData {
  const fcl::AABBd* query = nullptr;
  double within = 0.0;
  int* out = nullptr;
  int count = 0;
};

// FCL's tree calls this for each leaf whose box is closer to the query's than `dist` (leaves reached before the
// first call are not filtered, hence the test here). Keeping dist just above `within` makes the tree return every
// leaf at most `within` away (as brute force keeps pairs with d <= d_i), rather than only the nearest (its own
// callbacks lower dist to the smallest distance found).
bool near_callback(fcl::CollisionObjectd* group_object, fcl::CollisionObjectd* /*query*/, void* data, double& dist) {
  auto& d = *static_cast<NearData*>(data);
  if (group_object->getAABB().distance(*d.query) <= d.within) {
    d.out[d.count++] = static_cast<int>(reinterpret_cast<std::intptr_t>(group_object->getUserData()));
  }
  dist = std::nextafter(d.within, std::numeric_limits<double>::infinity());  // the tree prunes boxes at >= dist
  return false;                                                              // never stop early
}

}  // namespace

DistanceQuery::DistanceQuery(const std::vector<ShapeSpec>& shapes) : impl_(std::make_unique<Impl>()) {
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const ShapeSpec& s = shapes[i];
    try {
      check_config(s, ShapeSpec::schema());
    } catch (const FieldError& e) {
      throw std::invalid_argument("DistanceQuery: shape " + std::to_string(i) + ": " + e.what());
    }
    const bool round = s.shape == ShapeSpec::Kind::kSphere || s.shape == ShapeSpec::Kind::kCapsule;
    const double radius = s.radius.value_or(0.0);
    impl_->object_offset.push_back(Eigen::Isometry3d::Identity());
    if (s.is_cloud()) {
      const std::shared_ptr<const OccupancyMap>& cloud = s.cloud;
      if (!cloud) {
        throw std::invalid_argument("DistanceQuery: shape " + std::to_string(i) + " (" +
                                    std::string(config_io::enum_name(s.shape)) + ", " +
                                    (s.file ? s.file->string() : std::string("no file")) +
                                    "): its cells are not read yet; load_cloud() (redres/parsers/cloud_file.hpp) reads "
                                    "them");
      }
      const OccupancyInfo& info = cloud->info();
      const Eigen::Vector3d grow = Eigen::Vector3d::Constant(cloud->grow());
      impl_->cloud.push_back(cloud);
      impl_->cloud_lo.push_back(info.min - grow);
      impl_->cloud_hi.push_back(info.max + grow);
      impl_->round.push_back({});
      impl_->box_half.push_back(std::nullopt);
      impl_->cylinder_radius.push_back(0.0);
      impl_->cylinder_half.push_back(0.0);
      impl_->hull.push_back(nullptr);
      impl_->core_vertices.emplace_back();
      impl_->core_centre.emplace_back(Eigen::Vector3d::Zero());
      impl_->core_planes.emplace_back();
      // The farthest corner of the grown cells' box from the cloud's origin.
      impl_->bound.push_back(impl_->cloud_lo.back().cwiseAbs().cwiseMax(impl_->cloud_hi.back().cwiseAbs()).norm() *
                             (1.0 + 1e-12));
      // In the broadphase a cloud is the box of its grown cells.
      const Eigen::Vector3d side = impl_->cloud_hi.back() - impl_->cloud_lo.back();
      impl_->object_offset.back().translation() = 0.5 * (impl_->cloud_lo.back() + impl_->cloud_hi.back());
      impl_->objects.push_back(
          std::make_unique<fcl::CollisionObjectd>(std::make_shared<fcl::Boxd>(side.x(), side.y(), side.z())));
      continue;
    }
    impl_->cloud.push_back(nullptr);
    impl_->cloud_lo.emplace_back(Eigen::Vector3d::Zero());
    impl_->cloud_hi.emplace_back(Eigen::Vector3d::Zero());
    impl_->hull.push_back(s.shape == ShapeSpec::Kind::kConvex ? s.hull : nullptr);
    // The core's vertices: a sphere's centre, a capsule's two ends, a box's corners, a hull's vertices.
    std::vector<Eigen::Vector3d> corners;
    Eigen::Vector3d inner = Eigen::Vector3d::Zero();
    switch (s.shape) {
      case ShapeSpec::Kind::kSphere: corners.emplace_back(Eigen::Vector3d::Zero()); break;
      case ShapeSpec::Kind::kCapsule:
        corners.emplace_back(0.0, 0.0, -0.5 * s.axis_length());
        if (s.axis_length() > 0.0) corners.emplace_back(0.0, 0.0, 0.5 * s.axis_length());
        break;
      case ShapeSpec::Kind::kBox:
        for (int c = 0; c < 8; ++c) {
          corners.emplace_back(((c & 1) ? 0.5 : -0.5) * (*s.size)[0], ((c & 2) ? 0.5 : -0.5) * (*s.size)[1],
                               ((c & 4) ? 0.5 : -0.5) * (*s.size)[2]);
        }
        break;
      case ShapeSpec::Kind::kConvex:
        corners = s.hull->vertices;
        for (const auto& v : corners) inner += v;
        inner /= static_cast<double>(corners.size());
        break;
      case ShapeSpec::Kind::kCylinder:
      case ShapeSpec::Kind::kOctree:
      case ShapeSpec::Kind::kPoints: break;  // a smooth support; clouds above
    }
    // Face planes: a box's six; a hull's distinct ones (qhull's triangles split a facet into several).
    std::vector<Eigen::Vector4d> planes;
    if (s.shape == ShapeSpec::Kind::kBox) {
      for (int k = 0; k < 3; ++k) {
        for (const double side : {-1.0, 1.0}) {
          Eigen::Vector4d p = Eigen::Vector4d::Zero();
          p(k) = side;
          p(3) = 0.5 * (*s.size)[static_cast<std::size_t>(k)];
          planes.push_back(p);
        }
      }
    } else if (s.hull) {
      for (const auto& f : s.hull->faces) {
        const Eigen::Vector3d& v0 = s.hull->vertices[static_cast<std::size_t>(f[0])];
        Eigen::Vector3d n = (s.hull->vertices[static_cast<std::size_t>(f[1])] - v0)
                                .cross(s.hull->vertices[static_cast<std::size_t>(f[2])] - v0);
        if (!(n.norm() > 1e-12 * s.hull->bound * s.hull->bound)) continue;  // a sliver
        n.normalize();
        if (n.dot(v0 - inner) < 0.0) n = -n;  // outward
        const double h = n.dot(v0);
        const bool seen = std::any_of(planes.begin(), planes.end(), [&](const Eigen::Vector4d& p) {
          return p.head<3>().dot(n) > 1.0 - 1e-12 && std::abs(p(3) - h) <= 1e-12 * s.hull->bound;
        });
        if (!seen) planes.emplace_back(n.x(), n.y(), n.z(), h);
      }
    }
    impl_->core_planes.push_back(std::move(planes));
    impl_->core_vertices.push_back(std::move(corners));
    impl_->core_centre.push_back(inner);
    impl_->round.push_back(
        {round, round ? radius : 0.0, s.shape == ShapeSpec::Kind::kCapsule ? 0.5 * s.axis_length() : 0.0});
    impl_->box_half.push_back(s.shape == ShapeSpec::Kind::kBox ? std::optional<Eigen::Vector3d>(0.5 * vec(*s.size))
                                                               : std::nullopt);
    const bool cyl = s.shape == ShapeSpec::Kind::kCylinder;
    impl_->cylinder_radius.push_back(cyl ? radius : 0.0);
    impl_->cylinder_half.push_back(cyl ? 0.5 * *s.length : 0.0);
    double bound = radius + impl_->round.back().half_length;  // a sphere or capsule
    if (impl_->box_half.back()) bound = impl_->box_half.back()->norm();
    if (cyl) bound = std::hypot(radius, 0.5 * *s.length);
    if (s.hull) bound = s.hull->bound;
    impl_->bound.push_back(bound * (1.0 + 1e-12));  // rounding never culls a pair within reach
    std::shared_ptr<fcl::CollisionGeometryd> geometry;
    switch (s.shape) {
      case ShapeSpec::Kind::kSphere: geometry = std::make_shared<fcl::Sphered>(radius); break;
      case ShapeSpec::Kind::kCapsule:
        // A capsule of zero length is a sphere (FCL's capsule code divides by its length in places).
        if (s.axis_length() <= 1e-12) {
          geometry = std::make_shared<fcl::Sphered>(radius);
        } else {
          geometry = std::make_shared<fcl::Capsuled>(radius, s.axis_length());
        }
        break;
      case ShapeSpec::Kind::kCylinder: geometry = std::make_shared<fcl::Cylinderd>(radius, *s.length); break;
      case ShapeSpec::Kind::kBox:
        geometry = std::make_shared<fcl::Boxd>((*s.size)[0], (*s.size)[1], (*s.size)[2]);
        break;
      case ShapeSpec::Kind::kConvex: {
        // In the broadphase a hull is the box of its vertices, centred on its frame's origin (convex_hull()).
        const Eigen::Vector3d side = 2.0 * s.hull->half_extent;
        geometry = std::make_shared<fcl::Boxd>(side.x(), side.y(), side.z());
        break;
      }
      case ShapeSpec::Kind::kOctree:
      case ShapeSpec::Kind::kPoints: break;  // above
    }
    impl_->objects.push_back(std::make_unique<fcl::CollisionObjectd>(geometry));  // it keeps the geometry
  }
  // The libccd solver (unsigned queries only: signed ones are never made, see collision.hpp).
  // GJK to 1e-12: at libccd's 1e-8 a cylinder's distance came out up to 1.9e-6 m too large; at 1e-12 every pair matches
  // an independent computation (alternating projections, tests/framework/model/collision_test.cpp) to 1e-9 m.
  impl_->unsigned_request = fcl::DistanceRequestd(true, false, 0.0, 0.0, 1e-12, fcl::GST_LIBCCD);
}

DistanceQuery::~DistanceQuery() = default;

int DistanceQuery::size() const noexcept { return static_cast<int>(impl_->objects.size()); }

ShapeDistance DistanceQuery::distance(int a, const Eigen::Isometry3d& Ta, int b, const Eigen::Isometry3d& Tb,
                                      double within) const {
  ShapeDistance out;
  const int n = size();
  if (a < 0 || a >= n || b < 0 || b >= n) {
    out.error = "shape index out of range";
    return out;
  }
  if (impl_->cloud[static_cast<std::size_t>(a)] || impl_->cloud[static_cast<std::size_t>(b)]) {
    return impl_->cloud_distance(a, Ta, b, Tb, within);
  }
  if (impl_->hull[static_cast<std::size_t>(a)] || impl_->hull[static_cast<std::size_t>(b)]) {
    // A convex hull against any shape: GJK/MPR on support functions (model/convex_distance.hpp), without FCL.
    return impl_->convex_pair(static_cast<std::size_t>(a), Ta, static_cast<std::size_t>(b), Tb);
  }
  {
    const Impl::Round& ra = impl_->round[static_cast<std::size_t>(a)];
    const Impl::Round& rb = impl_->round[static_cast<std::size_t>(b)];
    const bool box_a = impl_->box_half[static_cast<std::size_t>(a)].has_value();
    const bool box_b = impl_->box_half[static_cast<std::size_t>(b)].has_value();
    if ((ra.round && box_b) || (box_a && rb.round)) {
      // A sphere or capsule against a box (a link and a table, say), apart or overlapping, without FCL (see round_box),
      // whose GJK allocates on every such query and whose EPA (for an overlap) can abort the process in 0.7 (a live
      // assert in Debian's build).
      const bool a_round = ra.round;
      const Impl::Round& rr = a_round ? ra : rb;
      const Eigen::Isometry3d& Tr = a_round ? Ta : Tb;
      const Eigen::Vector3d z = Tr.linear().col(2) * rr.half_length;
      Eigen::Vector3d on_round, on_box;
      round_box(Tr.translation() - z, Tr.translation() + z, rr.radius, a_round ? Tb : Ta,
                *impl_->box_half[static_cast<std::size_t>(a_round ? b : a)], out.distance, on_round, on_box);
      out.ok = true;
      out.point_a = a_round ? on_round : on_box;
      out.point_b = a_round ? on_box : on_round;
      return out;
    }
  }
  fcl::CollisionObjectd* oa = impl_->objects[static_cast<std::size_t>(a)].get();
  fcl::CollisionObjectd* ob = impl_->objects[static_cast<std::size_t>(b)].get();
  oa->setTransform(fcl::Transform3d(Ta.matrix()));
  ob->setTransform(fcl::Transform3d(Tb.matrix()));
  fcl::DistanceResultd& r = impl_->result;
  try {
    r.clear();  // a stale negative result would be kept: FCL only lowers min_distance
    fcl::distance(oa, ob, impl_->unsigned_request, r);
    if (!(r.min_distance > 0.0)) {
      const Impl::Round& ra = impl_->round[static_cast<std::size_t>(a)];
      const Impl::Round& rb = impl_->round[static_cast<std::size_t>(b)];
      if (ra.round && rb.round) {
        // Overlapping spheres and capsules: the penetration from their axes. FCL's unsigned query gives -1 for
        // sphere pairs, and its signed query (GJK/EPA) on penetrating capsules was seen to loop forever in 0.7.
        const Eigen::Vector3d za = Ta.linear().col(2) * ra.half_length, zb = Tb.linear().col(2) * rb.half_length;
        const Eigen::Vector3d a0 = Ta.translation() - za, a1 = Ta.translation() + za;
        const Eigen::Vector3d b0 = Tb.translation() - zb, b1 = Tb.translation() + zb;
        double sa = 0.0, sb = 0.0;
        closest_on_segments(a0, a1, b0, b1, sa, sb);
        const Eigen::Vector3d ca = a0 + sa * (a1 - a0), cb = b0 + sb * (b1 - b0);
        const double centres = (ca - cb).norm();
        const Eigen::Vector3d u = centres > 0.0 ? Eigen::Vector3d((ca - cb) / centres) : Eigen::Vector3d::Zero();
        out.ok = true;
        out.distance = centres - ra.radius - rb.radius;
        out.point_a = ca - ra.radius * u;
        out.point_b = cb + rb.radius * u;
        return out;
      }
      // Other overlapping pairs (a cylinder, or two boxes) would need FCL's EPA, which loops or aborts on such
      // pairs in 0.7: the pair is reported as not measured rather than risk the process.
      out.error = "the shapes overlap, and FCL 0.7 cannot measure the depth of a cylinder or box-box overlap reliably";
      return out;
    }
  } catch (const std::exception&) {
    out.error = "FCL failed on this pair (GJK/EPA)";
    return out;
  }
  if (!std::isfinite(r.min_distance)) {
    out.error = "FCL returned a non-finite distance";
    return out;
  }
  out.ok = true;
  out.distance = r.min_distance;
  out.point_a = r.nearest_points[0];
  out.point_b = r.nearest_points[1];
  // Spheres and capsules are measured in closed form by FCL (exact to rounding); GJK's answers are polished.
  if (!impl_->round[static_cast<std::size_t>(a)].round || !impl_->round[static_cast<std::size_t>(b)].round)
    impl_->polish(static_cast<std::size_t>(a), Ta, static_cast<std::size_t>(b), Tb, out);
  return out;
}

Eigen::Vector3d DistanceQuery::nearest_point(int k, const Eigen::Isometry3d& T, const Eigen::Vector3d& w) const {
  REDRES_REQUIRE(k >= 0 && k < size(), "DistanceQuery::nearest_point", "0 <= shape < size()");
  if (const auto& cloud = impl_->cloud[static_cast<std::size_t>(k)]) {
    const Eigen::Vector3d local = T.inverse() * w;
    const RoundMetric m(local, local, 0.0, cloud->grow());
    Eigen::Vector3d on_query, on_cloud;
    const double d = cloud->nearest(m, std::numeric_limits<double>::infinity(), on_query, on_cloud);
    if (!(d > 0.0)) return w;  // inside the cloud (or an empty one): the point itself, as for any shape
    return T * on_cloud;
  }
  return impl_->project(static_cast<std::size_t>(k), T, w);
}

double DistanceQuery::lower_bound(int a, const Eigen::Isometry3d& Ta, int b, const Eigen::Isometry3d& Tb) const {
  const auto ka = static_cast<std::size_t>(a), kb = static_cast<std::size_t>(b);
  const double from_a = (Ta.translation() - impl_->project(kb, Tb, Ta.translation())).norm() - impl_->bound[ka];
  const double from_b = (Tb.translation() - impl_->project(ka, Ta, Tb.translation())).norm() - impl_->bound[kb];
  return std::max(from_a, from_b);
}

void DistanceQuery::build_broadphase(int first, int count) {
  if (first < 0 || count < 0 || first + count > size()) {
    throw std::invalid_argument("DistanceQuery::build_broadphase: shapes [" + std::to_string(first) + ", " +
                                std::to_string(first + count) + ") are not within the " + std::to_string(size()) +
                                " shapes");
  }
  impl_->tree = std::make_unique<fcl::DynamicAABBTreeCollisionManagerd>();
  impl_->group_first = first;
  impl_->group_count = count;
  std::vector<fcl::CollisionObjectd*> group;
  for (int k = 0; k < count; ++k) {
    fcl::CollisionObjectd* o = impl_->objects[static_cast<std::size_t>(first + k)].get();
    o->setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(first + k)));
    o->computeAABB();
    group.push_back(o);
  }
  impl_->tree->registerObjects(group);
  impl_->tree->setup();
}

void DistanceQuery::move_group(const Eigen::Isometry3d* poses) {
  if (!impl_->tree) return;
  for (int k = 0; k < impl_->group_count; ++k) {
    fcl::CollisionObjectd* o = impl_->objects[static_cast<std::size_t>(impl_->group_first + k)].get();
    const Eigen::Isometry3d T = poses[k] * impl_->object_offset[static_cast<std::size_t>(impl_->group_first + k)];
    o->setTransform(fcl::Transform3d(T.matrix()));
    o->computeAABB();
  }
  impl_->tree->update();
}

int DistanceQuery::near(int a, const Eigen::Isometry3d& Ta, double within, int* out) const {
  if (!impl_->tree || a < 0 || a >= size()) return 0;
  fcl::CollisionObjectd* q = impl_->objects[static_cast<std::size_t>(a)].get();
  q->setTransform(fcl::Transform3d(Ta.matrix()));
  q->computeAABB();
  NearData data{&q->getAABB(), within, out, 0};
  impl_->tree->distance(q, &data, near_callback);
  return data.count;
}

}  // namespace redres

#pragma once
/// @file
/// Collision geometry and distances. Shapes are described without FCL (ShapeSpec, with a schema so that robot and
/// scenario files read them strictly); distances between two shapes at given world poses come from FCL (Debian's
/// libfcl 0.7) behind DistanceQuery, whose one .cpp is the only place that includes FCL.
///
/// FCL 0.7 facts the implementation respects (measured on Debian's package; docs/collision.md):
/// - an overlapping pair queried without signed distance returns -1 with zeroed points, and FCL's signed distance
///   (GJK/EPA) loops or aborts on some overlapping pairs (Debian builds with live asserts; the independent solver
///   aborts on penetrating capsules): every query is unsigned, and an overlap of a sphere or capsule with a sphere,
///   capsule or box is measured without FCL, from the capsule's axis; the depth of other overlapping pairs (a cylinder,
///   two boxes) is not measured, and the query reports the pair as failed (ok = false);
/// - the result is cleared before every query, and `min_distance` is read (not the return value);
/// - witness points are in the world frame, and p_b - p_a flips when the shapes overlap;
/// - Halfspace and Plane distance queries crash, so they are not offered (a wall is a thin box);
/// - FCL throws std::logic_error from GJK in rare near-touching box configurations: caught, reported as a status.

#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "redres/config/config.hpp"

namespace redres {

/// A primitive shape with a pose in its owner's frame (a link's frame, or the world for an obstacle). Capsules and
/// cylinders have their axis along the local z axis, centred on the pose's origin; a capsule may instead be given
/// by the two end points of its axis (`from`, `to`).
struct ShapeSpec {
  enum class Kind { kSphere, kCapsule, kCylinder, kBox };
  Kind shape = Kind::kCapsule;                      //!< which primitive
  std::optional<double> radius{};                   //!< sphere, capsule, cylinder (m)
  std::optional<double> length{};                   //!< capsule, cylinder: axis length (m)
  std::optional<std::array<double, 3>> size{};      //!< box: full side lengths (m)
  std::array<double, 3> xyz = {0.0, 0.0, 0.0};      //!< position in the owner's frame (m)
  std::array<double, 3> rpy = {0.0, 0.0, 0.0};      //!< roll, pitch, yaw in the owner's frame (rad)
  std::optional<std::array<double, 3>> from{};      //!< capsule: one end of the axis (m)
  std::optional<std::array<double, 3>> to{};        //!< capsule: the other end of the axis (m)
  std::optional<std::array<double, 3>> velocity{};  //!< obstacles: constant linear velocity (m/s)

  static const Schema<ShapeSpec>& schema();

  /// The pose of the shape in its owner's frame (from xyz/rpy, or from `from`/`to` for a capsule).
  [[nodiscard]] Eigen::Isometry3d pose() const;
  /// The same shape moved by `at` (a pose in the owner's frame becomes at * pose): a `from`/`to` capsule moves its
  /// end points, any other shape gets the xyz/rpy of at * pose().
  [[nodiscard]] ShapeSpec placed(const Eigen::Isometry3d& at) const;
  /// The capsule's axis length (from `length`, or |to - from|).
  [[nodiscard]] double axis_length() const;
  /// One line, e.g. "capsule(r = 0.05 m, l = 0.3 m)".
  [[nodiscard]] std::string describe() const;
};

/// R = Rz(yaw) Ry(pitch) Rx(roll) from {roll, pitch, yaw} (rad): ShapeSpec's and URDF's convention.
[[nodiscard]] Eigen::Matrix3d rpy_matrix(const std::array<double, 3>& rpy);
/// Roll, pitch, yaw of R = Rz(yaw) Ry(pitch) Rx(roll) (ShapeSpec's and URDF's convention); at pitch = +-pi/2 the
/// whole turn about z goes into yaw.
[[nodiscard]] std::array<double, 3> rpy_of(const Eigen::Matrix3d& R);

inline auto enum_names(ShapeSpec::Kind) {
  using K = ShapeSpec::Kind;
  return std::array{std::pair{K::kSphere, std::string_view("sphere")},
                    std::pair{K::kCapsule, std::string_view("capsule")},
                    std::pair{K::kCylinder, std::string_view("cylinder")}, std::pair{K::kBox, std::string_view("box")}};
}

/// The outcome of one distance query.
struct ShapeDistance {
  bool ok = false;        //!< false when FCL failed (see error); then the other fields are meaningless
  double distance = 0.0;  //!< signed distance (m): > 0 apart, < 0 overlapping (minus the penetration depth)
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();  //!< witness point on shape a (world)
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();  //!< witness point on shape b (world)
  const char* error = "";  //!< FCL's message when !ok (a static string or the exception's what(), copied nowhere)
};

/// Distances between a fixed set of shapes. Not thread-safe (FCL's objects are not): one per controller.
class DistanceQuery {
 public:
  /// Builds one FCL geometry per shape (sizes checked: std::invalid_argument naming the shape).
  explicit DistanceQuery(const std::vector<ShapeSpec>& shapes);
  ~DistanceQuery();
  DistanceQuery(const DistanceQuery&) = delete;
  DistanceQuery& operator=(const DistanceQuery&) = delete;

  /// Number of shapes.
  [[nodiscard]] int size() const noexcept;
  /// Signed distance between shape a at world pose Ta and shape b at world pose Tb (each pose is the shape's own,
  /// i.e. owner pose * ShapeSpec::pose()). Allocation-free for sphere and capsule pairs and for any overlap it
  /// measures; pairs apart that involve a box or a cylinder run FCL's GJK, which may allocate.
  [[nodiscard]] ShapeDistance distance(int a, const Eigen::Isometry3d& Ta, int b, const Eigen::Isometry3d& Tb) const;
  /// The point of shape k at world pose T nearest to the world point `w` (w itself when it is inside): exact, in
  /// closed form, allocation-free.
  [[nodiscard]] Eigen::Vector3d nearest_point(int k, const Eigen::Isometry3d& T, const Eigen::Vector3d& w) const;
  /// A lower bound on the distance between shape a at Ta and shape b at Tb, in closed form and a few dozen flops:
  /// the larger of dist(centre of a, b) - R_a and dist(centre of b, a) - R_b, with R the radius of the ball about
  /// the shape's centre that holds it. A pair whose bound exceeds the influence distance needs no query (the
  /// collision constraints' cull for scenes too small for the AABB tree).
  [[nodiscard]] double lower_bound(int a, const Eigen::Isometry3d& Ta, int b, const Eigen::Isometry3d& Tb) const;

  /// Broadphase, for scenes with many pairs: puts shapes [first, first + count) (the "group", e.g. the obstacles)
  /// into FCL's dynamic AABB tree. Call once, then move_group() before the first near().
  void build_broadphase(int first, int count);
  /// Places group shape first + k at poses[k] (world), for every k, and refits the tree. (FCL does not refresh an
  /// object's bounding box on setTransform; this calls computeAABB() on each and then the tree's update().)
  void move_group(const Eigen::Isometry3d* poses);
  /// The group shapes whose bounding boxes come within `within` (inclusive) of the bounding box of shape a at pose
  /// Ta: a superset of the group shapes within `within` of shape a. Writes their indices (first + k) into `out`, which
  /// must hold the group's size, and returns how many. Without build_broadphase(), every group is empty.
  int near(int a, const Eigen::Isometry3d& Ta, double within, int* out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace redres

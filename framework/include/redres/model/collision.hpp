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
#include <cstddef>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "redres/common/text_sink.hpp"
#include "redres/config/config.hpp"

namespace redres {

class OccupancyMap;
struct ConvexHull;

/// A primitive shape with a pose in its owner's frame (a link's frame, or the world for an obstacle). Capsules and
/// cylinders have their axis along the local z axis, centred on the pose's origin; a capsule may instead be given
/// by the two end points of its axis (`from`, `to`).
///
/// Obstacles may also be occupied space read from a file (docs/collision.md, "Point clouds and octrees"): an OctoMap
/// octree (`octree`, `.bt` or `.ot`) or a point cloud (`points`, `.ply`, `.pcd` or `.xyz`) put into cubic cells of
/// edge `resolution`. The obstacle is the union of the occupied cells grown by `radius` (0 for an octree unless
/// given), placed by xyz/rpy. The file is read once (load_cloud(), redres/parsers/cloud_file.hpp) and the cells are
/// shared by every copy of the spec.
///
/// A robot link may also be the convex hull of a collision mesh piece (`convex`, made by a robot file's
/// `collision_model = "hull"`, docs/robot_format.md "Meshes"): its vertices and faces in `hull`, shared by every copy
/// of the spec, placed by xyz/rpy, its mesh in `file`. Files cannot write one by hand (it has no size to give).
struct ShapeSpec {
  enum class Kind { kSphere, kCapsule, kCylinder, kBox, kOctree, kPoints, kConvex };
  Kind shape = Kind::kCapsule;                      //!< which primitive
  std::optional<double> radius{};                   //!< sphere, capsule, cylinder (m)
  std::optional<double> length{};                   //!< capsule, cylinder: axis length (m)
  std::optional<std::array<double, 3>> size{};      //!< box: full side lengths (m)
  std::array<double, 3> xyz = {0.0, 0.0, 0.0};      //!< position in the owner's frame (m)
  std::array<double, 3> rpy = {0.0, 0.0, 0.0};      //!< roll, pitch, yaw in the owner's frame (rad)
  std::optional<std::array<double, 3>> from{};      //!< capsule: one end of the axis (m)
  std::optional<std::array<double, 3>> to{};        //!< capsule: the other end of the axis (m)
  std::optional<std::array<double, 3>> velocity{};  //!< obstacles: constant linear velocity (m/s)
  std::optional<std::filesystem::path> file{};      //!< octree, points: the file (relative to the file naming it)
  std::optional<double> resolution{};               //!< points: the cell edge the points are put into (m)
  /// octree, points: the occupied cells, once read (load_cloud(), redres/parsers/cloud_file.hpp); shared by the spec's
  /// copies.
  std::shared_ptr<const OccupancyMap> cloud{};
  /// A robot's shapes: the body (a URDF link riding on the joint) it belongs to; empty: the joint's own link. Not a
  /// key of the files (a URDF link's shapes are given by the link's name).
  std::string body{};
  /// A robot's shapes made from a mesh: the mesh file (empty: written by hand, or a URDF primitive). Not a key.
  std::filesystem::path source{};
  /// convex: the hull's vertices and faces (in the shape's frame); shared by the spec's copies.
  std::shared_ptr<const ConvexHull> hull{};

  static const Schema<ShapeSpec>& schema();

  /// The pose of the shape in its owner's frame (from xyz/rpy, or from `from`/`to` for a capsule).
  [[nodiscard]] Eigen::Isometry3d pose() const;
  /// The same shape moved by `at` (a pose in the owner's frame becomes at * pose): a `from`/`to` capsule moves its
  /// end points, any other shape gets the xyz/rpy of at * pose().
  [[nodiscard]] ShapeSpec placed(const Eigen::Isometry3d& at) const;
  /// The capsule's axis length (from `length`, or |to - from|).
  [[nodiscard]] double axis_length() const;
  /// One line, e.g. "capsule(r = 0.05 m, l = 0.3 m)", "points(cloud.ply: 100000 points in 5310 cells of 0.01 m,
  /// r = 0.005 m)" or "convex(412 vertices, 820 faces, from link3.stl)".
  [[nodiscard]] std::string describe() const;
  /// The same, written into `out` (allocation-free, for a failed step's diagnosis).
  void describe(TextSink& out) const;
  /// An octree or a point cloud (occupied space read from a file), not a primitive.
  [[nodiscard]] bool is_cloud() const noexcept { return shape == Kind::kOctree || shape == Kind::kPoints; }
};

/// What a cloud obstacle's file held, once read.
struct OccupancyInfo {
  std::size_t points = 0;                         //!< points read (points), or occupied leaves (octree)
  std::size_t cells = 0;                          //!< occupied leaf cells of the tree (after merging)
  double resolution = 0.0;                        //!< the smallest cell's edge (m)
  std::size_t memory_bytes = 0;                   //!< the tree's memory (OctoMap's own count)
  Eigen::Vector3d min = Eigen::Vector3d::Zero();  //!< the occupied cells' bounding box, in the cloud's frame (m)
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

/// The occupied space of `points` (in the cloud's frame) put into cubic cells of edge `resolution` (m, > 0), grown by
/// `grow` (m). Throws std::invalid_argument naming the first point out of the octree's reach (+-32768 cells), or when
/// no cell is occupied. (The files are read by redres/parsers/cloud_file.hpp.)
[[nodiscard]] std::shared_ptr<const OccupancyMap> occupancy_of_points(const std::vector<Eigen::Vector3d>& points,
                                                                      double resolution, double grow);
/// An occupancy octree from the nodes of an OctoMap file (binary: a .bt file's, else an .ot file's), of cell edge
/// `resolution`, grown by `grow`; `size` >= 0 is the node count its header gives. The nodes are walked before OctoMap
/// reads them (its readers recurse without a depth limit and read past the end of the data): throws
/// std::invalid_argument when they end early or nest deeper than 16 levels, when the tree does not hold `size` nodes,
/// or when no cell is occupied.
[[nodiscard]] std::shared_ptr<const OccupancyMap> occupancy_of_octree(std::string_view nodes, bool binary,
                                                                      double resolution, long size, double grow);
/// The statistics of a loaded cloud.
[[nodiscard]] OccupancyInfo occupancy_info(const OccupancyMap& cloud);
/// The centres and edges of the occupied leaf cells, in the cloud's frame (for plots and tests): [x, y, z, edge].
[[nodiscard]] std::vector<std::array<double, 4>> occupied_cells(const OccupancyMap& cloud);

/// R = Rz(yaw) Ry(pitch) Rx(roll) from {roll, pitch, yaw} (rad): ShapeSpec's and URDF's convention.
[[nodiscard]] Eigen::Matrix3d rpy_matrix(const std::array<double, 3>& rpy);
/// Roll, pitch, yaw of R = Rz(yaw) Ry(pitch) Rx(roll) (ShapeSpec's and URDF's convention); at pitch = +-pi/2 the
/// whole turn about z goes into yaw.
[[nodiscard]] std::array<double, 3> rpy_of(const Eigen::Matrix3d& R);

inline auto enum_names(ShapeSpec::Kind) {
  using K = ShapeSpec::Kind;
  return std::array{
      std::pair{K::kSphere, std::string_view("sphere")},     std::pair{K::kCapsule, std::string_view("capsule")},
      std::pair{K::kCylinder, std::string_view("cylinder")}, std::pair{K::kBox, std::string_view("box")},
      std::pair{K::kOctree, std::string_view("octree")},     std::pair{K::kPoints, std::string_view("points")},
      std::pair{K::kConvex, std::string_view("convex")}};
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
  /// Builds one FCL geometry per shape (sizes checked: std::invalid_argument naming the shape). A cloud shape (octree,
  /// points) must hold its cells (read by load_cloud(), redres/parsers/cloud_file.hpp): one that does not is refused
  /// with std::invalid_argument naming the shape and its file.
  explicit DistanceQuery(const std::vector<ShapeSpec>& shapes);
  ~DistanceQuery();
  DistanceQuery(const DistanceQuery&) = delete;
  DistanceQuery& operator=(const DistanceQuery&) = delete;

  /// Number of shapes.
  [[nodiscard]] int size() const noexcept;
  /// Signed distance between shape a at world pose Ta and shape b at world pose Tb (each pose is the shape's own,
  /// i.e. owner pose * ShapeSpec::pose()). Allocation-free for sphere and capsule pairs and for any overlap it
  /// measures; pairs apart that involve a box or a cylinder run FCL's GJK, which may allocate.
  ///
  /// A pair with a cloud (b, or a) is measured by a depth-first search of its octree, nearest cell first, with every
  /// cell's distance in closed form (allocation-free): exact for a sphere or capsule against the grown cells; a box or
  /// cylinder is measured to each cell's bounding ball, which errs on the near side by at most 0.37 of the cell's edge.
  /// Cells farther than `within` are not searched: a pair with no cell within it reads +inf.
  [[nodiscard]] ShapeDistance distance(int a, const Eigen::Isometry3d& Ta, int b, const Eigen::Isometry3d& Tb,
                                       double within = std::numeric_limits<double>::infinity()) const;
  /// The point of shape k at world pose T nearest to the world point `w` (w itself when it is inside): exact, in
  /// closed form, allocation-free (a cloud: by the search distance() makes, to its grown cells).
  [[nodiscard]] Eigen::Vector3d nearest_point(int k, const Eigen::Isometry3d& T, const Eigen::Vector3d& w) const;
  /// A lower bound on the distance between shape a at Ta and shape b at Tb, in closed form and a few dozen flops:
  /// the larger of dist(centre of a, b) - R_a and dist(centre of b, a) - R_b, with R the radius of the ball about
  /// the shape's centre that holds it (a cloud counts as the bounding box of its grown cells). A pair whose bound
  /// exceeds the influence distance needs no query (the collision constraints' cull for scenes too small for the AABB
  /// tree).
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

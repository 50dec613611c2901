#pragma once
/// @file
/// Desired end-effector paths r_d(t), r_d_dot(t) and r_d_ddot(t) on [0, T] (position rows only: 2 for planar tasks,
/// 3 for spatial ones); all three are analytic. A path is geometry (lines, arcs, helices, grouped into strokes) plus a
/// timing law:
///
/// - timing laws sigma(u), u in [0, 1], sigma(0) = 0, sigma(1) = 1 (the share of arc length covered):
///   `cycloidal` u - sin(2 pi u) / (2 pi); `sin2` sin^2(pi u / 2) (the 2 pi sin^2(pi t / 2T) style law);
///   `quintic` 10u^3 - 15u^4 + 6u^5. cycloidal and quintic start and stop with zero speed and acceleration,
///   sin2 with zero speed;
/// - scope `per_stroke` (each stroke gets a share of T proportional to its length and runs the law from rest to
///   rest, so r_d_dot is continuous at every corner) or `whole` (one law over the total length).
///
/// Placement: the path's local coordinates are rotated (planar: `rotation_deg` about z; spatial: `rpy_deg`) and
/// translated to `origin`, which is absolute (`placement = "absolute"`) or an offset from the end effector's
/// initial position f(theta(0)) (`placement = "relative"`, the default).
///
/// Paths are plugins: `type` selects a factory in path_registry(); the placement and timing keys above
/// (PathPlacement) are read by the framework, the geometry keys by the path type's Config.

#include <any>
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/config/config.hpp"
#include "redres/config/registry.hpp"

namespace redres {

/// One geometric piece, parameterised by arc length.
struct PathSegment {
  enum class Kind { kLine, kArc, kHelix };
  Kind kind = Kind::kLine;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();    //!< line start, or arc/helix centre (m)
  Eigen::Vector3d b = Eigen::Vector3d::Zero();    //!< line end (m)
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX();  //!< arc/helix plane axes (orthonormal)
  Eigen::Vector3d e2 = Eigen::Vector3d::UnitY();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  //!< helix axis (unit)
  double radius = 0.0;                              //!< arc/helix radius (m)
  double start_angle = 0.0;                         //!< angle at the segment start (rad), measured from e1 towards e2
  double sweep = 0.0;                               //!< signed angle swept (rad); negative is clockwise about e1 x e2
  double rise = 0.0;                                //!< helix: advance along the axis over the whole segment (m)
  double length = 0.0;  //!< arc length (m), set by line() and arc() (a helix sets it itself)

  /// A line from p to q.
  static PathSegment line(const Eigen::Vector3d& p, const Eigen::Vector3d& q);
  /// An arc about `centre` in the plane (e1, e2).
  static PathSegment arc(const Eigen::Vector3d& centre, double radius, double start_angle, double sweep,
                         const Eigen::Vector3d& e1 = Eigen::Vector3d::UnitX(),
                         const Eigen::Vector3d& e2 = Eigen::Vector3d::UnitY());
  /// Point and unit tangent at arc length s in [0, length].
  void at(double s, Eigen::Vector3d& point, Eigen::Vector3d& tangent) const;
  /// Point, unit tangent and d^2 point / ds^2 (the curvature vector: zero on a line, towards the axis on an arc or
  /// a helix) at arc length s in [0, length]; point and tangent are bit-identical to the overload above.
  void at(double s, Eigen::Vector3d& point, Eigen::Vector3d& tangent, Eigen::Vector3d& d2point) const;
  /// Start and end points.
  [[nodiscard]] Eigen::Vector3d start() const;
  [[nodiscard]] Eigen::Vector3d end() const;
};

/// Orthonormal in-plane axes e1, e2 (with e1 x e2 = n) for a unit plane normal n.
void plane_axes(const Eigen::Vector3d& n, Eigen::Vector3d& e1, Eigen::Vector3d& e2);

/// Timing law sigma(u).
enum class TimingLaw { kCycloidal, kSin2, kQuintic };
/// Where the timing law applies.
enum class TimingScope { kPerStroke, kWhole };
/// Where the path origin is.
enum class Placement { kRelative, kAbsolute };

inline auto enum_names(TimingLaw) {
  return std::array{std::pair{TimingLaw::kCycloidal, std::string_view("cycloidal")},
                    std::pair{TimingLaw::kSin2, std::string_view("sin2")},
                    std::pair{TimingLaw::kQuintic, std::string_view("quintic")}};
}
inline auto enum_names(TimingScope) {
  return std::array{std::pair{TimingScope::kPerStroke, std::string_view("per_stroke")},
                    std::pair{TimingScope::kWhole, std::string_view("whole")}};
}
inline auto enum_names(Placement) {
  return std::array{std::pair{Placement::kRelative, std::string_view("relative")},
                    std::pair{Placement::kAbsolute, std::string_view("absolute")}};
}

/// Geometry in local path coordinates: strokes of consecutive segments, and the placement and timing the shape
/// prefers where the scenario does not say (e.g. the letter R is upright when rotated by 180 degrees).
struct PathGeometry {
  std::vector<std::vector<PathSegment>> strokes{};  //!< each stroke is drawn from rest to rest (per_stroke timing)
  double rotation_deg = 0.0;                        //!< default planar rotation of the shape
  TimingScope scope = TimingScope::kPerStroke;      //!< default timing scope of the shape
};

/// Geometry from consecutive segments: one stroke, or (`stroke_each`) one stroke per segment, each drawn from rest
/// to rest.
[[nodiscard]] PathGeometry strokes_from(std::vector<PathSegment> segments, bool stroke_each);

/// sigma(u) and d sigma / du for u in [0, 1] (u is clamped to it).
void timing(TimingLaw law, double u, double& sigma, double& dsigma);
/// sigma(u), d sigma / du and d^2 sigma / du^2 for u in [0, 1] (u is clamped to it); sigma and dsigma are
/// bit-identical to the overload above. sin2's d2sigma is pi^2/2 at u = 0 and -pi^2/2 at u = 1 (it starts and stops
/// with a jump in acceleration); cycloidal's and quintic's are zero there.
void timing(TimingLaw law, double u, double& sigma, double& dsigma, double& d2sigma);

/// A desired end-effector path on [0, T]. Immutable; evaluate() is allocation-free.
class Path {
 public:
  /// Builds from geometry; `dim` is 2 (planar, z ignored) or 3. Throws std::invalid_argument on empty or
  /// zero-length geometry.
  Path(PathGeometry geometry, int dim, double duration, TimingLaw law, TimingScope scope,
       const Eigen::Matrix3d& rotation, const Eigen::Vector3d& origin, std::string description);

  /// r_d(t) and r_d_dot(t) (size dim); t is clamped to [0, T].
  void evaluate(double t, Eigen::Ref<Eigen::VectorXd> r, Eigen::Ref<Eigen::VectorXd> r_dot) const;
  /// r_d(t), r_d_dot(t) and r_d_ddot(t) (size dim); r and r_dot are bit-identical to the overload above. On [0, T]
  /// r_ddot = R (tangent s'' + d^2p/ds^2 s'^2), s the arc length, R the placement rotation; at a time where it jumps
  /// (a segment joint, where the curvature changes; a stroke boundary under sin2 timing) it is the value of the
  /// piece that starts there (t = T: of the piece that ends there). Outside [0, T] the path is held at its end
  /// point with r_dot at its end value (zero), so r_ddot is zero there.
  void evaluate(double t, Eigen::Ref<Eigen::VectorXd> r, Eigen::Ref<Eigen::VectorXd> r_dot,
                Eigen::Ref<Eigen::VectorXd> r_ddot) const;
  /// Rows it provides (2 or 3).
  [[nodiscard]] int dim() const noexcept { return dim_; }
  /// Duration T (s).
  [[nodiscard]] double duration() const noexcept { return duration_; }
  /// Total length (m).
  [[nodiscard]] double length() const noexcept { return total_; }
  /// One line, e.g. "letter_r (3 strokes, 0.4236 m, cycloidal per stroke)".
  [[nodiscard]] const std::string& description() const noexcept { return description_; }

 private:
  std::vector<PathSegment> segments_{};
  std::vector<double> seg_start_{};     // arc length at each segment start (whole path)
  std::vector<int> stroke_first_{};     // first segment of each stroke
  std::vector<double> stroke_start_{};  // arc length at each stroke start
  std::vector<double> stroke_length_{};
  std::vector<double> stroke_t0_{};  // start time of each stroke
  std::vector<double> stroke_T_{};   // duration of each stroke
  int dim_;
  double duration_;
  double total_ = 0.0;
  TimingLaw law_;
  TimingScope scope_;
  Eigen::Matrix3d rotation_;
  Eigen::Vector3d origin_;
  std::string description_{};

  // The placed point, velocity and (when `acceleration` is not null) acceleration at t, in 3-D.
  void evaluate_3d(double t, Eigen::Vector3d& point, Eigen::Vector3d& velocity, Eigen::Vector3d* acceleration) const;
};

/// What a path plugin receives besides its Config.
struct PathContext {
  int dim = 2;                                      //!< 2 or 3
  Eigen::Vector3d start = Eigen::Vector3d::Zero();  //!< f(theta(0)) position (z = 0 for planar)
  double duration = 0.0;                            //!< T (s)
};

/// The placement and timing keys that every path takes besides its own. Unset optionals take the shape's
/// preference (PathGeometry) or, for `origin`, zero.
struct PathPlacement {
  Placement placement = Placement::kRelative;      //!< origin absolute, or relative to f(theta(0))
  std::optional<std::vector<double>> origin{};     //!< path origin (m), 2 or 3 numbers
  std::optional<double> rotation_deg{};            //!< planar: rotation about z (deg); default: the shape's
  std::optional<std::array<double, 3>> rpy_deg{};  //!< spatial: roll, pitch, yaw (deg)
  TimingLaw timing = TimingLaw::kCycloidal;        //!< timing law
  std::optional<TimingScope> timing_scope{};       //!< per stroke or whole path; default: the shape's

  static const Schema<PathPlacement>& schema();
};

/// Path plugins: a Config and a factory make(const Config&, const PathContext&) -> std::unique_ptr<PathGeometry>
/// in local coordinates; a geometry that cannot be built throws FieldError naming the key. A new curve type is
/// one .cpp that calls path_registry().add<MyConfig>("name", "summary", make).
using PathRegistry = Registry<PathGeometry, const PathContext&>;
/// The process-wide path registry.
PathRegistry& path_registry();

/// Builds a path from a [path] table: `type`, the type's keys and the PathPlacement keys; strict.
[[nodiscard]] std::unique_ptr<Path> make_path(const TableReader& table, const PathContext& context);

/// Builds a path from C++: the type, its Config (e.g. LetterRConfig{.height = 0.15}) and the placement.
[[nodiscard]] std::unique_ptr<Path> make_path(const std::string& type, const std::any& config,
                                              const PathPlacement& placement, const PathContext& context);

}  // namespace redres

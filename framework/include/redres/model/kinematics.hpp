#pragma once
/// @file
/// Exact kinematics of a RobotModel: f(theta), J, the kinematic Hessian dJ/dtheta_i, the manipulability
/// w = det(J J') with its gradient q (eq. 5, docs/paper.md), and Yoshikawa's mu = sqrt(det(J J')) with its
/// gradient. All results live in a KinematicsData workspace sized once for the model; compute() allocates
/// nothing.
///
/// Gradients that stay valid at singular configurations:
/// - q_i = d det(A)/d theta_i = trace(adj(A) dA/dtheta_i) with A = J J' (Jacobi's formula; the paper's
///   w trace(A^-1 dA/dtheta_i) wherever A is invertible) = 2 <adj(A) J, dJ/dtheta_i>_F. The adjugate is formed
///   from cofactors (m <= 3) or from A's eigen-decomposition (adj = V diag(prod_{j != k} lambda_j) V'), never
///   from an inverse.
/// - mu = prod_k s_k (singular values of J), d mu/d theta_i = sum_k (prod_{j != k} s_j) u_k' dJ/dtheta_i v_k,
///   which is finite at every configuration and exact wherever the singular values are distinct.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "redres/model/robot.hpp"

namespace redres {

/// How much compute() evaluates; each level includes the previous ones.
enum class KinematicsLevel {
  kPosition,        //!< f, end-effector pose, joint frames
  kJacobian,        //!< + J
  kMeasure,         //!< + w (without its gradient: what a run records when no plugin needs more)
  kGradient,        //!< + q = grad w (dJ is not filled in)
  kManipulability,  //!< + dJ/dtheta_i
  kAll,             //!< + Yoshikawa's mu and grad mu
};

class KinematicsData;
namespace detail {
struct KinematicsKernels;
}  // namespace detail

/// Eigen-decomposition of an m x m task-space matrix, m <= 6 task rows. Its storage is fixed at 6 x 6, so that
/// compute() allocates nothing: with dynamic storage, Eigen's tridiagonalisation allocates a work vector per call.
using TaskEigenSolver = Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>>;

/// Per-call buffers and results for one model. Reentrant: use one per thread.
class KinematicsData {
 public:
  /// Sizes every buffer for `model`.
  explicit KinematicsData(const RobotModel& model);

  Eigen::VectorXd theta;      //!< configuration the results belong to (n)
  Eigen::VectorXd f;          //!< reference coordinates f(theta) (reference_dim()): m, rad, rot. vector
  Eigen::Isometry3d ee_pose;  //!< end-effector pose in the world frame (the base pose applied)
  Eigen::Matrix3Xd axes;      //!< z_j, joint axes in the world frame (3 x n)
  Eigen::Matrix3Xd origins;   //!< p_j, points on the joint axes (3 x n), m
  std::vector<Eigen::Isometry3d> link_frames;          //!< frame of each link: joint j's frame after its motion (n)
  Eigen::MatrixXd J;                                   //!< task Jacobian (m x n)
  Eigen::MatrixXd dJ;                                  //!< [dJ/dtheta_1, ..., dJ/dtheta_n] (m x n*n); see dJ_block()
  double w = 0.0;                                      //!< det(J J')
  Eigen::VectorXd grad_w;                              //!< q = d w / d theta (n)
  double mu = 0.0;                                     //!< Yoshikawa's sqrt(det(J J'))
  Eigen::VectorXd grad_mu;                             //!< d mu / d theta (n)
  KinematicsLevel level = KinematicsLevel::kPosition;  //!< what the last compute() filled in

  /// dJ/dtheta_i (m x n).
  [[nodiscard]] auto dJ_block(int i) { return dJ.middleCols(static_cast<Eigen::Index>(i) * J.cols(), J.cols()); }
  [[nodiscard]] auto dJ_block(int i) const { return dJ.middleCols(static_cast<Eigen::Index>(i) * J.cols(), J.cols()); }

 private:
  friend struct detail::KinematicsKernels;
  friend void kinematic_hessian_revolute(const RobotModel&, KinematicsData&);
  Eigen::MatrixXd jjt_;                    // A = J J' (m x m)
  Eigen::MatrixXd adj_;                    // adj(A) (m x m)
  Eigen::MatrixXd weighted_;               // adj(A) J or U diag(c) V' (m x n)
  Eigen::VectorXd products_;               // prod_{j != k} s_j (m)
  TaskEigenSolver eig_;                    // for adj(A) when m > 3
  Eigen::JacobiSVD<Eigen::MatrixXd> svd_;  // for mu
  Eigen::Matrix3Xd linear_;                // the linear part of every joint's Jacobian column (3 x n)
  Eigen::VectorXd terms_;                  // planar kernel: h_j . W_j (n)
};

/// The kinematic Hessian dJ/dtheta_i into data.dJ from the frames, axes, origins, end-effector pose and the linear
/// parts of J's columns already in `data` (compute_kinematics at kJacobian). Two formulas, which compute_kinematics
/// chooses between: the general one (any joints: the motion of each joint applied to every downstream axis and point),
/// and for chains of revolute joints only the same derivative written as one cross product per entry (z_i x Jv_j). The
/// tests check both against central differences and against each other.
void kinematic_hessian_general(const RobotModel& model, KinematicsData& data);
void kinematic_hessian_revolute(const RobotModel& model, KinematicsData& data);

/// Evaluates the kinematics of `model` at `theta` into `data`, up to `level`. Throws std::invalid_argument when
/// theta has the wrong size or is not finite. Allocation-free.
///
/// Planar chains take a kernel of their own: the angles phi_j = base angle + theta_1 + ... + theta_j, the joint
/// points in one pass, J's columns from p_e - p_j, and grad w in O(m n) without the kinematic Hessian. (For a
/// planar chain dJ/dtheta_i has column j equal to h_max(i,j), h_c = -(p_e - p_c) in the x and y rows and 0 in the
/// phi row, so q_i = 2 (h_i . sum_{j <= i} W_j + sum_{j > i} h_j . W_j) with W = adj(J J') J: one prefix and one
/// suffix sum.) Spatial chains of revolute joints at kGradient get grad w the same way, from two suffix sums and a
/// prefix sum of cross products along the chain, without dJ. Everything else, and every chain through
/// compute_kinematics_general(), takes the general path: 3-D frame products, J from the axes, dJ/dtheta_i, and
/// q_i = 2 <adj(J J') J, dJ/dtheta_i>_F. The tests check that both give the same results to rounding.
void compute_kinematics(const RobotModel& model, const Eigen::Ref<const Eigen::VectorXd>& theta, KinematicsData& data,
                        KinematicsLevel level = KinematicsLevel::kManipulability);

/// The general path for any chain (the reference the kernels are tested against). Same contract as
/// compute_kinematics().
void compute_kinematics_general(const RobotModel& model, const Eigen::Ref<const Eigen::VectorXd>& theta,
                                KinematicsData& data, KinematicsLevel level = KinematicsLevel::kManipulability);

/// det(A) and adj(A) of a symmetric m x m matrix (m <= 6) without inverting it (cofactors for m <= 3,
/// eigen-decomposition otherwise, using `eig` as scratch). Allocation-free when `adj` is sized.
double symmetric_det_adjugate(const Eigen::Ref<const Eigen::MatrixXd>& A, Eigen::Ref<Eigen::MatrixXd> adj,
                              TaskEigenSolver& eig);

/// The rotation matrix of rotation vector w (angle |w| about w / |w|; the identity for w = 0): how f's orientation
/// rows and the desired orientation of a spatial pose task read as rotations.
[[nodiscard]] inline Eigen::Matrix3d rotation_from_vector(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  return angle > 0.0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
}

/// The orientation error of a frame at rotation R against the desired rotation R_d: the rotation R_d R' that turns R
/// into R_d, as an angle in [0, pi] and an axis. The one definition that every orientation row (the end-effector
/// task, frame tasks), the recorded orientation error and the inverse kinematics use.
[[nodiscard]] inline Eigen::AngleAxisd orientation_error(const Eigen::Matrix3d& R_d, const Eigen::Matrix3d& R) {
  return Eigen::AngleAxisd(R_d * R.transpose());
}

/// Its rotation vector (angle times axis): what orientation rows feed back.
[[nodiscard]] inline Eigen::Vector3d orientation_error_vector(const Eigen::Matrix3d& R_d, const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd e = orientation_error(R_d, R);
  return e.angle() * e.axis();
}

}  // namespace redres

#include "redres/model/kinematics.hpp"
#include "redres/common/hot.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace redres {

namespace {

using Eigen::Vector3d;

// Velocity of a point p (or a free vector when `point` is false) induced by a unit rate of joint i.
Vector3d joint_motion(bool revolute, const Vector3d& z_i, const Vector3d& p_i, const Vector3d& p) {
  return revolute ? Vector3d(z_i.cross(p - p_i)) : z_i;
}

// Writes the task rows of a spatial 6-vector (linear; angular) into column `col` of `out`.
void put_rows(const RobotModel& model, const Vector3d& lin, const Vector3d& ang, Eigen::Ref<Eigen::MatrixXd> out,
              Eigen::Index col) {
  const int m = model.task_dim();
  for (int i = 0; i < m; ++i) {
    const int r = model.twist_row(i);
    out(i, col) = r < 3 ? lin(r) : ang(r - 3);
  }
}

}  // namespace

KinematicsData::KinematicsData(const RobotModel& model)
    : theta(Eigen::VectorXd::Zero(model.dof())),
      f(Eigen::VectorXd::Zero(model.reference_dim())),
      ee_pose(Eigen::Isometry3d::Identity()),
      axes(Eigen::Matrix3Xd::Zero(3, model.dof())),
      origins(Eigen::Matrix3Xd::Zero(3, model.dof())),
      link_frames(static_cast<std::size_t>(model.dof()), Eigen::Isometry3d::Identity()),
      J(Eigen::MatrixXd::Zero(model.task_dim(), model.dof())),
      dJ(Eigen::MatrixXd::Zero(model.task_dim(), static_cast<Eigen::Index>(model.dof()) * model.dof())),
      grad_w(Eigen::VectorXd::Zero(model.dof())),
      grad_mu(Eigen::VectorXd::Zero(model.dof())),
      jjt_(Eigen::MatrixXd::Zero(model.task_dim(), model.task_dim())),
      adj_(Eigen::MatrixXd::Zero(model.task_dim(), model.task_dim())),
      weighted_(Eigen::MatrixXd::Zero(model.task_dim(), model.dof())),
      products_(Eigen::VectorXd::Zero(model.task_dim())),
      eig_(model.task_dim()),
      svd_(model.task_dim(), model.dof(), Eigen::ComputeThinU | Eigen::ComputeThinV),
      linear_(Eigen::Matrix3Xd::Zero(3, model.dof())),
      terms_(Eigen::VectorXd::Zero(model.dof())) {
  // A planar chain's axes are z, and its frames turn about z in the plane z = 0: the planar kernel writes only the
  // entries that move (the general path writes these same values).
  if (model.kind() == ChainKind::kPlanar) axes.row(2).setOnes();
}

double symmetric_det_adjugate(const Eigen::Ref<const Eigen::MatrixXd>& A, Eigen::Ref<Eigen::MatrixXd> adj,
                              TaskEigenSolver& eig) {
  const Eigen::Index m = A.rows();
  switch (m) {
    case 1: adj(0, 0) = 1.0; return A(0, 0);
    case 2:
      adj(0, 0) = A(1, 1);
      adj(1, 1) = A(0, 0);
      adj(0, 1) = -A(0, 1);
      adj(1, 0) = -A(1, 0);
      return A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
    case 3: {
      // adj(A)_{ij} = cofactor C_{ji}; A symmetric so adj is too.
      adj(0, 0) = A(1, 1) * A(2, 2) - A(1, 2) * A(2, 1);
      adj(0, 1) = A(0, 2) * A(2, 1) - A(0, 1) * A(2, 2);
      adj(0, 2) = A(0, 1) * A(1, 2) - A(0, 2) * A(1, 1);
      adj(1, 0) = A(1, 2) * A(2, 0) - A(1, 0) * A(2, 2);
      adj(1, 1) = A(0, 0) * A(2, 2) - A(0, 2) * A(2, 0);
      adj(1, 2) = A(0, 2) * A(1, 0) - A(0, 0) * A(1, 2);
      adj(2, 0) = A(1, 0) * A(2, 1) - A(1, 1) * A(2, 0);
      adj(2, 1) = A(0, 1) * A(2, 0) - A(0, 0) * A(2, 1);
      adj(2, 2) = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
      return A(0, 0) * adj(0, 0) + A(0, 1) * adj(1, 0) + A(0, 2) * adj(2, 0);
    }
    default: {
      eig.compute(A);
      const auto& lambda = eig.eigenvalues();
      const auto& V = eig.eigenvectors();
      adj.setZero();
      double det = 1.0;
      for (Eigen::Index k = 0; k < m; ++k) {
        det *= lambda(k);
        double others = 1.0;
        for (Eigen::Index j = 0; j < m; ++j) {
          if (j != k) others *= lambda(j);
        }
        adj.noalias() += others * V.col(k) * V.col(k).transpose();
      }
      return det;
    }
  }
}

void kinematic_hessian_general(const RobotModel& model, KinematicsData& data) {
  // A unit rate of joint i moves every axis z_j and point p_j with j > i, and p_e.
  const int n = model.dof();
  const Vector3d p_e = data.ee_pose.translation();
  for (int i = 0; i < n; ++i) {
    const bool rev_i = model.joint(i).type == JointType::kRevolute;
    const Vector3d z_i = data.axes.col(i);
    const Vector3d p_i = data.origins.col(i);
    const Vector3d dp_e = joint_motion(rev_i, z_i, p_i, p_e);
    auto block = data.dJ_block(i);
    for (int j = 0; j < n; ++j) {
      const Vector3d z_j = data.axes.col(j);
      const Vector3d p_j = data.origins.col(j);
      const bool downstream = i < j;
      const Vector3d dz_j = (downstream && rev_i) ? Vector3d(z_i.cross(z_j)) : Vector3d::Zero();
      const Vector3d dp_j = downstream ? joint_motion(rev_i, z_i, p_i, p_j) : Vector3d::Zero();
      if (model.joint(j).type == JointType::kRevolute) {
        put_rows(model, dz_j.cross(p_e - p_j) + z_j.cross(dp_e - dp_j), dz_j, block, j);
      } else {
        put_rows(model, dz_j, Vector3d::Zero(), block, j);
      }
    }
  }
}

void kinematic_hessian_revolute(const RobotModel& model, KinematicsData& data) {
  // With revolute joints only, the motion of joint i turns everything downstream about z_i, so (by the Jacobi
  // identity) d(z_j x (p_e - p_j))/dtheta_i = z_i x Jv_j for i <= j and z_j x Jv_i for i > j, with
  // Jv_j = z_j x (p_e - p_j); and dz_j/dtheta_i = z_i x z_j for i < j, else 0. One cross product per entry.
  const int n = model.dof();
  const auto& lin = data.linear_;  // Jv_j = z_j x (p_e - p_j), from the Jacobian stage
  if (model.kind() == ChainKind::kPlanar) {
    // Every axis is the world z: z x v = (-v_y, v_x, 0) exactly (the cross product's other terms are exact zeros),
    // and z_i x z_j = 0.
    // Written straight into dJ's columns (contiguous, column-major): each task row takes x, y, or 0 for phi.
    const int m = model.task_dim();
    int rows[6];
    for (int r = 0; r < m; ++r) rows[r] = model.twist_row(r);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        const int c = std::max(i, j);
        const double vx = -lin(1, c), vy = lin(0, c);
        double* col = data.dJ.col(static_cast<Eigen::Index>(i) * n + j).data();
        for (int r = 0; r < m; ++r) col[r] = rows[r] == 0 ? vx : rows[r] == 1 ? vy : 0.0;
      }
    }
    return;
  }
  for (int i = 0; i < n; ++i) {
    const Vector3d z_i = data.axes.col(i);
    auto block = data.dJ_block(i);
    for (int j = 0; j < n; ++j) {
      if (i <= j) {
        const Vector3d z_j = data.axes.col(j);
        put_rows(model, z_i.cross(lin.col(j)), i < j ? Vector3d(z_i.cross(z_j)) : Vector3d::Zero(), block, j);
      } else {
        put_rows(model, data.axes.col(j).cross(lin.col(i)), Vector3d::Zero(), block, j);
      }
    }
  }
}

namespace detail {

// The stages of compute_kinematics(); a struct so that they may use KinematicsData's workspace.
struct KinematicsKernels {
  // Checks the sizes and copies theta into data.theta, checking that it is finite on the way.
  REDRES_HOT static void check_and_copy(const RobotModel& model, const Eigen::Ref<const Eigen::VectorXd>& theta,
                                        KinematicsData& data) {
    const int n = model.dof();
    REDRES_REQUIRE(
        theta.size() == n, "compute_kinematics",
        "theta.size() == dof() (got " + std::to_string(theta.size()) + ", expected " + std::to_string(n) + ")");
    REDRES_REQUIRE(data.J.cols() == n && data.J.rows() == model.task_dim() && data.theta.size() == n,
                   "compute_kinematics", "data was sized for this model (KinematicsData(model))");
    data.theta = theta;
    REDRES_REQUIRE(finite_probe(theta.data(), n) == 0.0, "compute_kinematics",
                   "theta is finite (it contains NaN or Inf)");
  }

  // General path: joint frames, end-effector pose and f by 3-D frame products.
  static void forward_general(const RobotModel& model, KinematicsData& data) {
    const int n = model.dof();
    const Eigen::VectorXd& theta = data.theta;
    Eigen::Isometry3d T = model.base();
    double phi = model.base_angle();  // planar end-effector angle, kept unwrapped
    // The short cuts (frame_shape) skip products with the identity and with zeros: they give the very bits of the
    // full products, which add only exact zeros to the same terms in the same order.
    for (int j = 0; j < n; ++j) {
      const JointSpec& joint = model.joint(j);
      const Vector3d& u = model.axis(j);
      const RobotModel::FrameShape& shape = model.frame_shape(j);
      if (!shape.before_identity) T = T * model.before(j);
      // For the z axis, T.linear() * u is T's third column exactly (products with 0 and 1 round nothing).
      data.axes.col(j) = shape.z_axis ? Vector3d(T.linear().col(2)) : Vector3d(T.linear() * u);
      data.origins.col(j) = T.translation();
      if (joint.type == JointType::kRevolute) {
        if (shape.z_axis) {
          // T.rotate(Rz(theta)): the first two columns turn by theta, the third stays.
          const double c = std::cos(theta(j)), s = std::sin(theta(j));
          const Vector3d c0 = T.linear().col(0), c1 = T.linear().col(1);
          T.linear().col(0) = c0 * c + c1 * s;
          T.linear().col(1) = c0 * -s + c1 * c;
        } else {
          T.rotate(Eigen::AngleAxisd(theta(j), u));
        }
        phi += theta(j);
      } else {
        T.translate(theta(j) * u);
      }
      data.link_frames[static_cast<std::size_t>(j)] = T;
      if (shape.after_translation) {
        T.translation() += T.linear() * model.after(j).translation();
      } else {
        T = T * model.after(j);
      }
    }
    T = T * model.end_effector();
    data.ee_pose = T;
    const Vector3d p_e = T.translation();
    if (model.kind() == ChainKind::kPlanar) {
      data.f(0) = p_e.x();
      data.f(1) = p_e.y();
      if (model.task() == TaskRows::kPose) data.f(2) = phi + model.end_effector_angle();
    } else {
      data.f.head<3>() = p_e;
      if (model.task() == TaskRows::kPose) {
        const Eigen::AngleAxisd aa(T.linear());
        data.f.tail<3>() = aa.angle() * aa.axis();
      }
    }
  }

  // General path: the geometric Jacobian, task rows only.
  // The linear part of each column goes to linear_ too (the Hessian and the revolute kernel read it).
  static void jacobian_general(const RobotModel& model, KinematicsData& data) {
    const Vector3d p_e = data.ee_pose.translation();
    for (int j = 0; j < model.dof(); ++j) {
      const Vector3d z = data.axes.col(j);
      if (model.joint(j).type == JointType::kRevolute) {
        data.linear_.col(j) = z.cross(p_e - data.origins.col(j));
        put_rows(model, data.linear_.col(j), z, data.J, j);
      } else {
        data.linear_.col(j) = z;
        put_rows(model, z, Vector3d::Zero(), data.J, j);
      }
    }
  }

  static void hessian(const RobotModel& model, KinematicsData& data) {
    if (model.all_revolute()) {
      kinematic_hessian_revolute(model, data);
    } else {
      kinematic_hessian_general(model, data);
    }
  }

  // w = det(J J') and W = adj(J J') J into weighted_.
  static void det_and_weighted(KinematicsData& data) {
    data.jjt_.noalias() = data.J * data.J.transpose();
    data.w = symmetric_det_adjugate(data.jjt_, data.adj_, data.eig_);
    data.weighted_.noalias() = data.adj_ * data.J;
  }

  // General path: w and q_i = 2 <adj(J J') J, dJ_i>_F, from dJ.
  static void gradient_general(const RobotModel& model, KinematicsData& data) {
    det_and_weighted(data);
    for (int i = 0; i < model.dof(); ++i) data.grad_w(i) = 2.0 * data.weighted_.cwiseProduct(data.dJ_block(i)).sum();
  }

  // Planar kernel: frames, f, and (when `jacobian`) J, in two passes over the joints.
  REDRES_HOT static void forward_planar(const RobotModel& model, KinematicsData& data, bool jacobian) {
    const int n = model.dof();
    const double* theta = data.theta.data();
    double* origins = data.origins.data();
    double phi = model.base_angle();
    double px = model.base().translation().x(), py = model.base().translation().y();
    double c = 1.0, s = 0.0;
    const JointSpec* joints = model.joints().data();
    Eigen::Isometry3d* frames = data.link_frames.data();
    // Only the entries that move are written: the axes (z), the origins' z (0) and the frames' third rows and
    // columns (those of the identity) keep the values KinematicsData(model) gave them.
    for (int j = 0; j < n; ++j) {
      origins[3 * j] = px;
      origins[3 * j + 1] = py;
      phi += theta[j];
      c = std::cos(phi);
      s = std::sin(phi);
      // The link frame: Rz(phi_j) at p_j (column-major 4 x 4).
      double* F = frames[j].matrix().data();
      F[0] = c, F[1] = s;
      F[4] = -s, F[5] = c;
      F[12] = px, F[13] = py;
      const double l = joints[j].length;
      px += l * c;
      py += l * s;
    }
    // The last link's end point, turned by phi_n (c, s), then the end effector's fixed transform E:
    // ee = [Rz(phi_n) R_E, Rz(phi_n) t_E + (px, py, 0)], written out (Rz leaves E's third row alone).
    const Eigen::Matrix4d& E = model.end_effector().matrix();
    Eigen::Matrix4d& P = data.ee_pose.matrix();
    for (int col = 0; col < 4; ++col) {
      P(0, col) = c * E(0, col) - s * E(1, col);
      P(1, col) = s * E(0, col) + c * E(1, col);
      P(2, col) = E(2, col);
      P(3, col) = E(3, col);
    }
    P(0, 3) += px;
    P(1, 3) += py;
    const double ex = P(0, 3), ey = P(1, 3);
    data.f(0) = ex;
    data.f(1) = ey;
    if (model.task() == TaskRows::kPose) data.f(2) = phi + model.end_effector_angle();
    if (!jacobian) return;
    switch (model.task_dim()) {
      case 1: jacobian_planar<1>(model, data); break;
      case 2: jacobian_planar<2>(model, data); break;
      default: jacobian_planar<3>(model, data); break;
    }
  }

  // Planar kernel: column j of J is z x (p_e - p_j) = (-(e_y - p_jy), e_x - p_jx) in the x and y rows, 1 in the phi
  // row. M = m, as in gradient_planar.
  template <int M>
  [[gnu::noinline]] REDRES_HOT static void jacobian_planar(const RobotModel& model, KinematicsData& data) {
    const int n = model.dof();
    const double ex = data.ee_pose.translation().x(), ey = data.ee_pose.translation().y();
    int rows[M];
    for (int r = 0; r < M; ++r) rows[r] = model.twist_row(r);
    const double* origins = data.origins.data();
    double* J = data.J.data();
    double* lin = data.linear_.data();
    for (int j = 0; j < n; ++j) {
      const double vx = -(ey - origins[3 * j + 1]), vy = ex - origins[3 * j];
      lin[3 * j] = vx;
      lin[3 * j + 1] = vy;  // the z entry stays 0
      for (int r = 0; r < M; ++r) J[j * M + r] = rows[r] == 0 ? vx : rows[r] == 1 ? vy : 1.0;
    }
  }

  // Planar kernel: w = det(J J') (with adj(J J') for the gradient). M is the number of task rows m (1 to 3), fixed at
  // compile time so that the loops over the rows unroll.
  template <int M>
  [[gnu::noinline]] REDRES_HOT static void measure_planar(const RobotModel& model, KinematicsData& data) {
    const int n = model.dof();
    constexpr int m = M;
    const double* J = data.J.data();
    // A = J J' (lower triangle summed, then mirrored).
    double A[3][3] = {};
    for (int j = 0; j < n; ++j) {
      const double* col = J + j * m;
      for (int r = 0; r < m; ++r) {
        for (int q = 0; q <= r; ++q) A[r][q] += col[r] * col[q];
      }
    }
    for (int r = 0; r < m; ++r) {
      for (int q = 0; q <= r; ++q) data.jjt_(r, q) = data.jjt_(q, r) = A[r][q];
    }
    if constexpr (M == 2) {
      data.adj_(0, 0) = A[1][1];
      data.adj_(1, 1) = A[0][0];
      data.adj_(0, 1) = data.adj_(1, 0) = -A[1][0];
      data.w = A[0][0] * A[1][1] - A[1][0] * A[1][0];
    } else {
      data.w = symmetric_det_adjugate(data.jjt_, data.adj_, data.eig_);
    }
  }

  // Planar kernel: w (measure_planar<M>) and grad w in O(m n) from the prefix and suffix sums of the class comment.
  template <int M>
  [[gnu::noinline]] REDRES_HOT static void gradient_planar(const RobotModel& model, KinematicsData& data) {
    measure_planar<M>(model, data);
    const int n = model.dof();
    constexpr int m = M;
    const double* J = data.J.data();
    const double* lin = data.linear_.data();
    // W = adj(A) J in the x and y rows only (h is zero in the phi row).
    double adj_x[3] = {}, adj_y[3] = {};
    bool has_x = false, has_y = false;
    for (int r = 0; r < m; ++r) {
      const int t = model.twist_row(r);
      if (t > 1) continue;
      for (int q = 0; q < m; ++q) (t == 0 ? adj_x : adj_y)[q] = data.adj_(r, q);
      (t == 0 ? has_x : has_y) = true;
    }
    // h_c = (-(e_x - p_cx), -(e_y - p_cy)) = (-Jv_y, Jv_x) for Jv_c = linear_.col(c).
    double* g = data.grad_w.data();
    double* terms = data.terms_.data();
    double sum_x = 0.0, sum_y = 0.0;  // sum_{j <= i} of W's x and y rows
    for (int i = 0; i < n; ++i) {
      const double* col = J + i * m;
      double wx = 0.0, wy = 0.0;
      for (int q = 0; q < m; ++q) {
        wx += adj_x[q] * col[q];
        wy += adj_y[q] * col[q];
      }
      sum_x += wx;
      sum_y += wy;
      const double hx = -lin[3 * i + 1], hy = lin[3 * i];
      g[i] = hx * sum_x + hy * sum_y;
      terms[i] = hx * wx + hy * wy;
    }
    double suffix = 0.0;  // sum_{j > i} h_j . W_j
    for (int i = n - 1; i >= 0; --i) {
      g[i] = 2.0 * (g[i] + suffix);
      suffix += terms[i];
    }
    // Joint 1 turns the whole arm rigidly, which leaves J J' unchanged when the task has both position rows or
    // neither: q_1 = 0 exactly, where the sums above leave rounding of either sign.
    if (has_x == has_y) g[0] = 0.0;
  }

  // Spatial chains of revolute joints at kGradient: w and grad w in O(m n) without the kinematic Hessian. With the
  // revolute Hessian (kinematic_hessian_revolute) and W = adj(J J') J split into its linear rows Wl_j and angular
  // rows Wa_j (zero where a row is not a task row), a.(b x c) = b.(c x a) turns q_i = 2 sum_j <W_j, dJ_i e_j> into
  //   q_i = 2 (z_i . (sum_{j >= i} Jv_j x Wl_j + sum_{j > i} z_j x Wa_j) + Jv_i . sum_{j < i} Wl_j x z_j),
  // two suffix sums and one prefix sum.
  static void gradient_revolute(const RobotModel& model, KinematicsData& data) {
    const int n = model.dof(), m = model.task_dim();
    det_and_weighted(data);
    const auto& lin = data.linear_;  // Jv_j, from the Jacobian stage
    // The suffix sums, from the tip: S_i = sum_{j >= i} Jv_j x Wl_j + sum_{j > i} z_j x Wa_j (into grad_w as
    // z_i . S_i), then the prefix sum C_i = sum_{j < i} Wl_j x z_j.
    const auto split = [&](int j, Vector3d& wl, Vector3d& wa) {
      wl.setZero();
      wa.setZero();
      for (int r = 0; r < m; ++r) {
        const int t = model.twist_row(r);
        (t < 3 ? wl(t) : wa(t - 3)) = data.weighted_(r, j);
      }
    };
    Vector3d suffix = Vector3d::Zero(), wl, wa;
    for (int i = n - 1; i >= 0; --i) {
      split(i, wl, wa);
      const Vector3d z = data.axes.col(i);
      suffix += lin.col(i).cross(wl);
      data.grad_w(i) = z.dot(suffix);
      suffix += z.cross(wa);  // counts for the joints before i only
    }
    Vector3d prefix = Vector3d::Zero();
    for (int i = 0; i < n; ++i) {
      split(i, wl, wa);
      data.grad_w(i) = 2.0 * (data.grad_w(i) + lin.col(i).dot(prefix));
      prefix += wl.cross(data.axes.col(i));
    }
  }

  // mu = prod s_k and d mu = sum_k (prod_{j != k} s_j) u_k' dJ v_k. With fewer joints than task rows a
  // singular value is identically zero, so mu and its gradient vanish.
  // Away from singularities, mu = sqrt(w) and grad mu = grad w / (2 mu) give the same without a singular value
  // decomposition: used while w is at least 1e-4 of (trace(J J') / m)^m, the value w would have with all singular
  // values equal, where the division loses at most about 1e-12 relatively (tested against the decomposition).
  static void yoshikawa(const RobotModel& model, KinematicsData& data) {
    const int n = model.dof();
    const double mean_square = data.jjt_.trace() / static_cast<double>(model.task_dim());
    if (n < model.task_dim()) {
      data.mu = 0.0;
      data.grad_mu.setZero();
    } else if (data.w >= 1e-4 * std::pow(mean_square, model.task_dim()) && data.w > 0.0) {
      data.mu = std::sqrt(data.w);
      data.grad_mu = data.grad_w / (2.0 * data.mu);
    } else {
      data.svd_.compute(data.J, Eigen::ComputeThinU | Eigen::ComputeThinV);
      const auto& s = data.svd_.singularValues();
      const Eigen::Index m = s.size();
      data.mu = 1.0;
      for (Eigen::Index k = 0; k < m; ++k) {
        data.mu *= s(k);
        double others = 1.0;
        for (Eigen::Index j = 0; j < m; ++j) {
          if (j != k) others *= s(j);
        }
        data.products_(k) = others;
      }
      data.adj_.noalias() = data.svd_.matrixU() * data.products_.asDiagonal();
      data.weighted_.noalias() = data.adj_ * data.svd_.matrixV().transpose();
      for (int i = 0; i < n; ++i) data.grad_mu(i) = data.weighted_.cwiseProduct(data.dJ_block(i)).sum();
    }
  }

  REDRES_HOT static void compute(const RobotModel& model, const Eigen::Ref<const Eigen::VectorXd>& theta,
                                 KinematicsData& data, KinematicsLevel level, bool kernels) {
    check_and_copy(model, theta, data);
    const bool planar = kernels && model.kind() == ChainKind::kPlanar;
    if (planar) {
      forward_planar(model, data, level >= KinematicsLevel::kJacobian);
    } else {
      forward_general(model, data);
    }
    data.level = KinematicsLevel::kPosition;
    if (level == KinematicsLevel::kPosition) return;
    if (!planar) jacobian_general(model, data);
    data.level = KinematicsLevel::kJacobian;
    if (level == KinematicsLevel::kJacobian) return;
    if (level == KinematicsLevel::kMeasure) {  // w alone, computed as the gradient's paths compute it
      if (planar) {
        switch (model.task_dim()) {
          case 1: measure_planar<1>(model, data); break;
          case 2: measure_planar<2>(model, data); break;
          default: measure_planar<3>(model, data); break;
        }
      } else {
        data.jjt_.noalias() = data.J * data.J.transpose();
        data.w = symmetric_det_adjugate(data.jjt_, data.adj_, data.eig_);
      }
      data.level = KinematicsLevel::kMeasure;
      return;
    }
    if (planar) {
      switch (model.task_dim()) {
        case 1: gradient_planar<1>(model, data); break;
        case 2: gradient_planar<2>(model, data); break;
        default: gradient_planar<3>(model, data); break;
      }
      if (level >= KinematicsLevel::kManipulability) hessian(model, data);
    } else if (kernels && level == KinematicsLevel::kGradient && model.all_revolute()) {
      gradient_revolute(model, data);
    } else {
      hessian(model, data);
      gradient_general(model, data);
    }
    data.level = std::min(level, KinematicsLevel::kManipulability);
    if (level < KinematicsLevel::kAll) return;
    yoshikawa(model, data);
    data.level = KinematicsLevel::kAll;
  }
};

}  // namespace detail

void compute_kinematics(const RobotModel& model, const Eigen::Ref<const Eigen::VectorXd>& theta, KinematicsData& data,
                        KinematicsLevel level) {
  detail::KinematicsKernels::compute(model, theta, data, level, true);
}

void compute_kinematics_general(const RobotModel& model, const Eigen::Ref<const Eigen::VectorXd>& theta,
                                KinematicsData& data, KinematicsLevel level) {
  detail::KinematicsKernels::compute(model, theta, data, level, false);
}

}  // namespace redres

// Properties of the kinematics over random chains (planar and spatial, 2 to 9 joints, random geometry, random
// angles inside the limits): J, dJ/dtheta_i, grad w and grad mu against central differences; q_1 = 0 and w
// invariant under base rotation for planar arms; finite, correct gradients at and near singular configurations;
// no allocation.

#include <cmath>

#include <gtest/gtest.h>

#include <rapidcheck/gtest.h>
#include <Eigen/SVD>

#include "alloc_counter.hpp"
#include "random_chain.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

using testing::random_planar;
using testing::random_spatial;
using testing::random_theta;

constexpr double kStep = 1e-6;  // central-difference step (rad or m)

RobotModel random_model() {
  const bool planar = *rc::gen::arbitrary<bool>();
  const int n = *rc::gen::inRange(2, 10);
  const TaskRows task = *rc::gen::element(TaskRows::kPosition, TaskRows::kPose);
  RobotSpec spec = planar ? random_planar(n, task) : random_spatial(n, task);
  if (*rc::gen::inRange(0, 3) == 0) {
    // A random non-empty subset of the pose's rows (a selection matrix S on J).
    const std::vector<std::string> all =
        planar ? std::vector<std::string>{"x", "y", "phi"} : std::vector<std::string>{"x", "y", "z", "wx", "wy", "wz"};
    const int mask = *rc::gen::inRange(1, 1 << all.size());
    for (std::size_t r = 0; r < all.size(); ++r) {
      if ((mask >> r) & 1) spec.task_axes.push_back(all[r]);
    }
  }
  return RobotModel(std::move(spec));
}

// Central difference of the task coordinates: f for position rows and the planar angle; for spatial orientation
// rows the rotation vector of R(theta + h) R(theta - h)' (which the geometric Jacobian's angular rows match). Only
// the task rows (a subset keeps some rows of the reference).
Eigen::VectorXd task_difference(const RobotModel& model, const KinematicsData& plus, const KinematicsData& minus) {
  Eigen::VectorXd d = (plus.f - minus.f) / (2 * kStep);
  if (model.kind() == ChainKind::kSpatial && model.task() == TaskRows::kPose) {
    const Eigen::AngleAxisd aa(plus.ee_pose.linear() * minus.ee_pose.linear().transpose());
    d.tail<3>() = aa.angle() * aa.axis() / (2 * kStep);
  }
  Eigen::VectorXd rows(model.task_dim());
  for (int i = 0; i < model.task_dim(); ++i) rows(i) = d(model.task_rows()[static_cast<std::size_t>(i)]);
  return rows;
}

// |a - b|_inf <= tol (1 + |b|_inf), with a message naming the worst entry.
void expect_close(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b, double tol,
                  const std::string& what) {
  const double scale = 1.0 + b.cwiseAbs().maxCoeff();
  Eigen::Index r = 0, c = 0;
  const double err = (a - b).cwiseAbs().maxCoeff(&r, &c);
  RC_ASSERT(std::isfinite(err));
  if (err > tol * scale) {
    RC_FAIL(what + ": entry (" + std::to_string(r) + ", " + std::to_string(c) + ") analytic " +
            std::to_string(a(r, c)) + " vs central difference " + std::to_string(b(r, c)));
  }
}

RC_GTEST_PROP(KinematicsProperty, JacobianMatchesCentralDifferencesOfF, ()) {
  const RobotModel model = random_model();
  const Eigen::VectorXd theta = random_theta(model);
  KinematicsData k(model), kp(model), km(model);
  compute_kinematics(model, theta, k, KinematicsLevel::kJacobian);
  Eigen::MatrixXd fd(model.task_dim(), model.dof());
  for (int i = 0; i < model.dof(); ++i) {
    Eigen::VectorXd t = theta;
    t(i) += kStep;
    compute_kinematics(model, t, kp, KinematicsLevel::kPosition);
    t(i) -= 2 * kStep;
    compute_kinematics(model, t, km, KinematicsLevel::kPosition);
    fd.col(i) = task_difference(model, kp, km);
  }
  expect_close(k.J, fd, 1e-6, "J");
}

RC_GTEST_PROP(KinematicsProperty, HessianMatchesCentralDifferencesOfJ, ()) {
  const RobotModel model = random_model();
  const Eigen::VectorXd theta = random_theta(model);
  KinematicsData k(model), kp(model), km(model);
  compute_kinematics(model, theta, k, KinematicsLevel::kManipulability);
  for (int i = 0; i < model.dof(); ++i) {
    Eigen::VectorXd t = theta;
    t(i) += kStep;
    compute_kinematics(model, t, kp, KinematicsLevel::kJacobian);
    t(i) -= 2 * kStep;
    compute_kinematics(model, t, km, KinematicsLevel::kJacobian);
    const Eigen::MatrixXd fd = (kp.J - km.J) / (2 * kStep);
    expect_close(k.dJ_block(i), fd, 1e-6, "dJ/dtheta_" + std::to_string(i + 1));
  }
}

// The two Hessian formulas (kinematics.hpp) agree wherever both apply: on chains of revolute joints only (random
// chains with their prismatic joints made revolute), the general one and the one cross product per entry.
RC_GTEST_PROP(KinematicsProperty, TheRevoluteHessianIsTheGeneralOne, ()) {
  RobotSpec spec = *rc::gen::arbitrary<bool>() ? random_planar(*rc::gen::inRange(2, 10), TaskRows::kPose)
                                               : random_spatial(*rc::gen::inRange(2, 10), TaskRows::kPose);
  for (auto& j : spec.joints) j.type = JointType::kRevolute;
  const RobotModel model(std::move(spec));
  RC_ASSERT(model.all_revolute());
  KinematicsData a(model), b(model);
  const Eigen::VectorXd theta = random_theta(model);
  compute_kinematics(model, theta, a, KinematicsLevel::kJacobian);
  compute_kinematics(model, theta, b, KinematicsLevel::kJacobian);
  kinematic_hessian_general(model, a);
  kinematic_hessian_revolute(model, b);
  expect_close(b.dJ, a.dJ, 1e-12, "dJ");
}

// The planar kernel (compute_kinematics on a planar chain) and the general path (compute_kinematics_general) give
// the same results to rounding at every level: frames, f, J, w and grad w (the kernel's prefix and suffix sums
// against <adj(J J') J, dJ_i>), dJ, mu and grad mu; at kGradient the kernel leaves dJ alone.
RC_GTEST_PROP(KinematicsProperty, ThePlanarKernelIsTheGeneralPath, ()) {
  RobotSpec spec = random_planar(*rc::gen::inRange(1, 13), *rc::gen::element(TaskRows::kPosition, TaskRows::kPose));
  if (*rc::gen::inRange(0, 3) == 0) {
    const std::vector<std::string> all{"x", "y", "phi"};
    const int mask = *rc::gen::inRange(1, 8);
    for (std::size_t r = 0; r < all.size(); ++r) {
      if ((mask >> r) & 1) spec.task_axes.push_back(all[r]);
    }
  }
  const RobotModel model(std::move(spec));
  const Eigen::VectorXd theta = random_theta(model);
  const KinematicsLevel level =
      *rc::gen::element(KinematicsLevel::kPosition, KinematicsLevel::kJacobian, KinematicsLevel::kGradient,
                        KinematicsLevel::kManipulability, KinematicsLevel::kAll);
  KinematicsData kernel(model), general(model);
  kernel.dJ.setConstant(7.0);  // what the kernel must leave alone below kManipulability
  compute_kinematics(model, theta, kernel, level);
  compute_kinematics_general(model, theta, general, level);
  RC_ASSERT(kernel.level == general.level);
  const auto close = [](const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b,
                        const std::string& what) {
    const double err = (a - b).cwiseAbs().maxCoeff();
    if (!(err <= 1e-12 * (1.0 + b.cwiseAbs().maxCoeff()))) RC_FAIL(what + " differs by " + std::to_string(err));
  };
  close(kernel.f, general.f, "f");
  close(kernel.ee_pose.matrix(), general.ee_pose.matrix(), "ee_pose");
  close(kernel.axes, general.axes, "axes");
  close(kernel.origins, general.origins, "origins");
  for (int j = 0; j < model.dof(); ++j) {
    close(kernel.link_frames[static_cast<std::size_t>(j)].matrix(),
          general.link_frames[static_cast<std::size_t>(j)].matrix(), "link frame " + std::to_string(j + 1));
  }
  if (level >= KinematicsLevel::kJacobian) close(kernel.J, general.J, "J");
  if (level >= KinematicsLevel::kGradient) {
    RC_ASSERT(std::abs(kernel.w - general.w) <= 1e-12 * (1.0 + general.w));
    close(kernel.grad_w, general.grad_w, "grad w");
  }
  if (level == KinematicsLevel::kGradient) RC_ASSERT((kernel.dJ.array() == 7.0).all());
  if (level >= KinematicsLevel::kManipulability) close(kernel.dJ, general.dJ, "dJ");
  if (level == KinematicsLevel::kAll) {
    RC_ASSERT(std::abs(kernel.mu - general.mu) <= 1e-12 * (1.0 + general.mu));
    close(kernel.grad_mu, general.grad_mu, "grad mu");
  }
}

// Spatial chains of revolute joints at kGradient: grad w from the sums along the chain (no dJ) is the general
// path's <adj(J J') J, dJ_i>, on random chains (their prismatic joints made revolute) with random task rows.
RC_GTEST_PROP(KinematicsProperty, TheRevoluteGradientIsTheGeneralOne, ()) {
  RobotSpec spec = random_spatial(*rc::gen::inRange(1, 13), *rc::gen::element(TaskRows::kPosition, TaskRows::kPose));
  for (auto& j : spec.joints) j.type = JointType::kRevolute;
  if (spec.task == TaskRows::kPose && *rc::gen::inRange(0, 2) == 0) {
    const std::vector<std::string> all{"x", "y", "z", "wx", "wy", "wz"};
    const int mask = *rc::gen::inRange(1, 64);
    for (std::size_t r = 0; r < all.size(); ++r) {
      if ((mask >> r) & 1) spec.task_axes.push_back(all[r]);
    }
  }
  const RobotModel model(std::move(spec));
  RC_ASSERT(model.all_revolute());
  const Eigen::VectorXd theta = random_theta(model);
  KinematicsData kernel(model), general(model);
  kernel.dJ.setConstant(7.0);
  compute_kinematics(model, theta, kernel, KinematicsLevel::kGradient);
  compute_kinematics_general(model, theta, general, KinematicsLevel::kGradient);
  RC_ASSERT(kernel.level == KinematicsLevel::kGradient);
  RC_ASSERT((kernel.dJ.array() == 7.0).all());  // no Hessian
  RC_ASSERT(std::abs(kernel.w - general.w) <= 1e-12 * (1.0 + general.w));
  const double err = (kernel.grad_w - general.grad_w).cwiseAbs().maxCoeff();
  if (!(err <= 1e-12 * (1.0 + general.grad_w.cwiseAbs().maxCoeff()))) {
    RC_FAIL("grad w differs by " + std::to_string(err));
  }
}

// w alone (kMeasure, what a run records when no plugin needs its gradient) is w of the gradient's paths bit for bit,
// on planar and spatial chains with prismatic joints too, and leaves grad w and dJ untouched.
RC_GTEST_PROP(KinematicsProperty, TheMeasureAloneIsTheGradientsMeasureBitForBit, ()) {
  const RobotModel model = random_model();
  const Eigen::VectorXd theta = random_theta(model);
  KinematicsData alone(model), full(model);
  alone.grad_w.setConstant(7.0);
  alone.dJ.setConstant(7.0);
  compute_kinematics(model, theta, alone, KinematicsLevel::kMeasure);
  compute_kinematics(model, theta, full, KinematicsLevel::kGradient);
  RC_ASSERT(alone.level == KinematicsLevel::kMeasure);
  RC_ASSERT(alone.w == full.w);
  RC_ASSERT((alone.grad_w.array() == 7.0).all());  // no gradient
  RC_ASSERT((alone.dJ.array() == 7.0).all());      // no Hessian
}

// mu and grad mu, whichever way compute_kinematics takes (sqrt(w) away from singularities, the singular value
// decomposition near them), are those of the decomposition: mu = prod s_k, d mu = sum_k prod_{j != k} s_j u_k' dJ v_k.
RC_GTEST_PROP(KinematicsProperty, YoshikawaIsThatOfTheSingularValues, ()) {
  const RobotModel model = random_model();
  RC_PRE(model.dof() >= model.task_dim());
  KinematicsData k(model);
  compute_kinematics(model, random_theta(model), k, KinematicsLevel::kAll);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(k.J, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sv = svd.singularValues();
  double mu = 1.0;
  for (Eigen::Index i = 0; i < sv.size(); ++i) mu *= sv(i);
  Eigen::VectorXd grad(model.dof());
  for (int i = 0; i < model.dof(); ++i) {
    double g = 0.0;
    for (Eigen::Index a = 0; a < sv.size(); ++a) {
      double others = 1.0;
      for (Eigen::Index b = 0; b < sv.size(); ++b) others *= b == a ? 1.0 : sv(b);
      g += others * svd.matrixU().col(a).dot(k.dJ_block(i) * svd.matrixV().col(a));
    }
    grad(i) = g;
  }
  RC_ASSERT(std::abs(k.mu - mu) <= 1e-10 * (1.0 + mu));
  expect_close(k.grad_mu, grad, 1e-8, "grad mu");
}

RC_GTEST_PROP(KinematicsProperty, ManipulabilityGradientsMatchCentralDifferences, ()) {
  const RobotModel model = random_model();
  const Eigen::VectorXd theta = random_theta(model);
  KinematicsData k(model), kp(model), km(model);
  compute_kinematics(model, theta, k, KinematicsLevel::kAll);
  RC_ASSERT(std::abs(k.mu * k.mu - k.w) <= 1e-9 * (1.0 + k.w));
  Eigen::VectorXd fd_w(model.dof()), fd_mu(model.dof());
  for (int i = 0; i < model.dof(); ++i) {
    Eigen::VectorXd t = theta;
    t(i) += kStep;
    compute_kinematics(model, t, kp, KinematicsLevel::kAll);
    t(i) -= 2 * kStep;
    compute_kinematics(model, t, km, KinematicsLevel::kAll);
    fd_w(i) = (kp.w - km.w) / (2 * kStep);
    fd_mu(i) = (kp.mu - km.mu) / (2 * kStep);
  }
  expect_close(k.grad_w, fd_w, 1e-6, "grad w");
  RC_ASSERT(k.grad_mu.allFinite());
  // sqrt is smooth only away from w = 0; there the central difference of mu itself is not a derivative.
  RC_CLASSIFY(k.mu > 1e-3, "mu > 1e-3");
  if (k.mu > 1e-3) expect_close(k.grad_mu, fd_mu, 1e-5, "grad mu");
}

// The pose of the end effector, recomputed here from the spec by the formula in robot.hpp, without RobotModel's
// precomputed transforms: T = P A_1 M_1 B_1 ... A_n M_n B_n E. Checks that the model (including the base pose, joint
// origins and arbitrary axes) is built as documented; the central-difference properties above check the
// derivatives against it.
RC_GTEST_PROP(KinematicsProperty, EndEffectorPoseFollowsTheDocumentedProduct, ()) {
  const int n = *rc::gen::inRange(1, 9);
  const TaskRows task = *rc::gen::element(TaskRows::kPosition, TaskRows::kPose);
  const RobotSpec spec = random_spatial(n, task);
  const RobotModel model(spec);
  const Eigen::VectorXd theta = random_theta(model);
  Eigen::Isometry3d T = spec.base;
  for (int j = 0; j < n; ++j) {
    const JointSpec& jt = spec.joints[static_cast<std::size_t>(j)];
    Eigen::Isometry3d A = Eigen::Isometry3d::Identity(), B = Eigen::Isometry3d::Identity();
    const bool rev = jt.type == JointType::kRevolute;
    const auto Rz = [](double a) { return Eigen::Isometry3d(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ())); };
    const auto Rx = [](double a) { return Eigen::Isometry3d(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX())); };
    const auto Tr = [](double x, double y, double z) { return Eigen::Isometry3d(Eigen::Translation3d(x, y, z)); };
    Eigen::Vector3d u = Eigen::Vector3d::UnitZ();
    switch (spec.convention) {
      case DhConvention::kStandard:
        A = Rz(jt.theta_offset) * (rev ? Eigen::Isometry3d::Identity() : Tr(0, 0, jt.d));
        B = (rev ? Tr(0, 0, jt.d) : Eigen::Isometry3d::Identity()) * Tr(jt.a, 0, 0) * Rx(jt.alpha);
        break;
      case DhConvention::kModified:
        A = Rx(jt.alpha) * Tr(jt.a, 0, 0) * Rz(jt.theta_offset) *
            (rev ? Eigen::Isometry3d::Identity() : Tr(0, 0, jt.d));
        B = rev ? Tr(0, 0, jt.d) : Eigen::Isometry3d::Identity();
        break;
      case DhConvention::kJointFrames:
        A = jt.origin;
        u = jt.axis.normalized();
        break;
    }
    const Eigen::Isometry3d M =
        rev ? Eigen::Isometry3d(Eigen::AngleAxisd(theta(j), u)) : Eigen::Isometry3d(Eigen::Translation3d(theta(j) * u));
    T = T * A * M * B;
  }
  T = T * spec.end_effector;
  KinematicsData k(model);
  compute_kinematics(model, theta, k, KinematicsLevel::kPosition);
  RC_ASSERT((k.ee_pose.matrix() - T.matrix()).cwiseAbs().maxCoeff() <= 1e-12);
}

// A DH chain and the same chain written as joint frames (origin_j = B_{j-1} A_j, axis z, the last B folded into the
// end effector) give the same f, J and w: the two descriptions meet in one model.
RC_GTEST_PROP(KinematicsProperty, DhChainsAndTheirJointFramesAgree, ()) {
  const int n = *rc::gen::inRange(2, 9);
  const TaskRows task = *rc::gen::element(TaskRows::kPosition, TaskRows::kPose);
  const RobotSpec dh = random_spatial(n, task);
  RC_PRE(dh.convention != DhConvention::kJointFrames);  // a DH chain (either convention) to rewrite
  const RobotModel a(dh);
  RobotSpec frames = dh;
  frames.convention = DhConvention::kJointFrames;
  for (int j = 0; j < n; ++j) {
    JointSpec& jt = frames.joints[static_cast<std::size_t>(j)];
    jt.origin = (j > 0 ? a.after(j - 1) : Eigen::Isometry3d::Identity()) * a.before(j);
    jt.axis = Eigen::Vector3d::UnitZ();
    jt.a = jt.alpha = jt.d = jt.theta_offset = 0.0;  // (a prismatic joint's Tz(d_j) is in a.before(j) already)
  }
  frames.end_effector = a.after(n - 1) * dh.end_effector;
  const RobotModel b(frames);
  const Eigen::VectorXd theta = random_theta(a);
  KinematicsData ka(a), kb(b);
  compute_kinematics(a, theta, ka, KinematicsLevel::kManipulability);
  compute_kinematics(b, theta, kb, KinematicsLevel::kManipulability);
  RC_ASSERT((ka.f - kb.f).cwiseAbs().maxCoeff() <= 1e-12);
  RC_ASSERT((ka.J - kb.J).cwiseAbs().maxCoeff() <= 1e-12);
  RC_ASSERT(std::abs(ka.w - kb.w) <= 1e-12 * (1.0 + ka.w));
}

RC_GTEST_PROP(KinematicsProperty, PlanarBaseRotationLeavesManipulabilityUnchanged, ()) {
  const int n = *rc::gen::inRange(2, 10);
  const TaskRows task = *rc::gen::element(TaskRows::kPosition, TaskRows::kPose);
  const RobotModel model(random_planar(n, task));
  const Eigen::VectorXd theta = random_theta(model);
  KinematicsData k(model), rotated(model);
  compute_kinematics(model, theta, k, KinematicsLevel::kManipulability);
  RC_ASSERT(std::abs(k.grad_w(0)) <= 1e-9 * (1.0 + k.grad_w.cwiseAbs().maxCoeff()));
  Eigen::VectorXd t = theta;
  t(0) += testing::draw(-3.0, 3.0);
  compute_kinematics(model, t, rotated, KinematicsLevel::kManipulability);
  RC_ASSERT(std::abs(rotated.w - k.w) <= 1e-10 * (1.0 + k.w));
  RC_ASSERT((rotated.grad_w - k.grad_w).cwiseAbs().maxCoeff() <= 1e-9 * (1.0 + k.grad_w.cwiseAbs().maxCoeff()));
}

// The stretched planar 3R arm is singular (J has rank 1): w = 0, and its gradient must still be finite and
// equal to the central difference; so must it be just next to the singularity, where A = JJ' is nearly singular.
TEST(KinematicsSingular, GradientsStayFiniteAndCorrectAtAndNearSingularity) {
  const RobotModel model = load_robot(source_path("robots/yoshikawa_3link.toml"));
  KinematicsData k(model), kp(model), km(model);
  for (double eps : {0.0, 1e-9, 1e-6, 1e-3}) {
    Eigen::VectorXd theta(3);
    theta << 0.3, eps, -0.5 * eps;
    compute_kinematics(model, theta, k, KinematicsLevel::kAll);
    ASSERT_TRUE(k.grad_w.allFinite()) << "eps " << eps;
    ASSERT_TRUE(k.grad_mu.allFinite()) << "eps " << eps;
    if (eps == 0.0) {
      EXPECT_NEAR(k.w, 0.0, 1e-14);
    }
    for (int i = 0; i < 3; ++i) {
      Eigen::VectorXd t = theta;
      t(i) += 1e-5;
      compute_kinematics(model, t, kp, KinematicsLevel::kManipulability);
      t(i) -= 2e-5;
      compute_kinematics(model, t, km, KinematicsLevel::kManipulability);
      EXPECT_NEAR(k.grad_w(i), (kp.w - km.w) / 2e-5, 1e-8) << "eps " << eps << ", joint " << i + 1;
    }
  }
  // At the singularity w has a minimum (w >= 0), so its gradient vanishes.
  Eigen::VectorXd stretched = Eigen::VectorXd::Zero(3);
  compute_kinematics(model, stretched, k, KinematicsLevel::kAll);
  EXPECT_LT(k.grad_w.norm(), 1e-14);
  // The adjugate's defining identity adj(A) A = det(A) I, on SPD matrices of the cofactor sizes and of the
  // eigen-decomposition path.
  TaskEigenSolver eig(5);
  for (int m : {2, 3, 5}) {
    Eigen::MatrixXd B(m, m + 2);
    for (int r = 0; r < m; ++r)
      for (int c = 0; c < m + 2; ++c) B(r, c) = std::sin(1.0 + 3.0 * r + 7.0 * c);
    const Eigen::MatrixXd A = B * B.transpose();
    Eigen::MatrixXd adj(m, m);
    const double det = symmetric_det_adjugate(A, adj, eig);
    EXPECT_NEAR(det, A.determinant(), 1e-10 * std::abs(A.determinant()) + 1e-12) << "m = " << m;
    EXPECT_LT((adj * A - det * Eigen::MatrixXd::Identity(m, m)).norm(), 1e-9 * (1.0 + std::abs(det))) << "m = " << m;
  }
}

TEST(KinematicsInput, WrongSizeAndNanThrowWithTheCondition) {
  const RobotModel model = load_robot(source_path("robots/paper_pushrod_6dof.toml"));
  KinematicsData k(model);
  try {
    compute_kinematics(model, Eigen::VectorXd::Zero(5), k);
    FAIL() << "wrong size accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("theta.size() == dof() (got 5, expected 6)"), std::string::npos) << e.what();
  }
  Eigen::VectorXd bad = paper_theta0();
  bad(3) = std::nan("");
  try {
    compute_kinematics(model, bad, k);
    FAIL() << "NaN accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("theta is finite"), std::string::npos) << e.what();
  }
}

TEST(KinematicsRealTime, ComputeAllocatesNothing) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  for (const char* file : {"robots/paper_pushrod_6dof.toml", "robots/franka_panda.toml", "robots/kuka_iiwa14.toml",
                           "robots/planar_4link.toml"}) {
    const RobotModel model = load_robot(source_path(file));
    KinematicsData k(model);
    Eigen::VectorXd lo(model.dof()), hi(model.dof());
    const Eigen::VectorXd theta = model.home();
    compute_kinematics(model, theta, k, KinematicsLevel::kAll);  // warm-up
    long count = 0;
    {
      const testing::AllocationCounter counter;
      for (int rep = 0; rep < 10; ++rep) {
        compute_kinematics(model, theta, k, KinematicsLevel::kAll);
        model.velocity_limits(theta, lo, hi);
      }
      count = counter.count();
    }
    EXPECT_EQ(count, 0) << file;
  }
  // The counter itself works: an allocation is seen.
  const testing::AllocationCounter counter;
  auto* p = new std::vector<double>(100);
  delete p;
  EXPECT_GE(counter.count(), 1);
}

}  // namespace
}  // namespace redres

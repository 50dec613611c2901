#include "paper_baseline.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace redres::baseline {
namespace {

struct Kinematics {
  double x = 0.0, y = 0.0;
  Joints J0{}, J1{};  // the two rows of J
  double w = 0.0;
  Joints grad_w{};
};

// Planar 6R: phi_i = theta_1 + ... + theta_i; with the suffix sums X_j = sum_{i >= j} l_i cos phi_i and
// Y_j = sum_{i >= j} l_i sin phi_i, f = (X_1, Y_1), J = [-Y_j; X_j], dJ_j/dtheta_k = [-X_m; -Y_m] with m = max(j, k).
// A = J J' = [a b; b c], w = ac - b^2, and dw/dtheta_k = a' c + a c' - 2 b b'.
void kinematics(const PaperArm& arm, const Joints& theta, Kinematics& k) {
  Joints c{}, s{};
  double phi = 0.0;
  for (int i = 0; i < kJoints; ++i) {
    phi += theta[i];
    c[i] = arm.length[i] * std::cos(phi);
    s[i] = arm.length[i] * std::sin(phi);
  }
  Joints X{}, Y{};
  double sx = 0.0, sy = 0.0;
  for (int i = kJoints - 1; i >= 0; --i) {
    sx += c[i];
    sy += s[i];
    X[i] = sx;
    Y[i] = sy;
  }
  k.x = X[0];
  k.y = Y[0];
  double a = 0.0, b = 0.0, cc = 0.0;
  for (int j = 0; j < kJoints; ++j) {
    k.J0[j] = -Y[j];
    k.J1[j] = X[j];
    a += Y[j] * Y[j];
    b -= Y[j] * X[j];
    cc += X[j] * X[j];
  }
  k.w = a * cc - b * b;
  for (int q = 0; q < kJoints; ++q) {
    double da = 0.0, db = 0.0, dc = 0.0;
    for (int j = 0; j < kJoints; ++j) {
      const int m = std::max(j, q);
      da += 2.0 * Y[j] * X[m];  // 2 J0j dJ0j = 2 (-Y_j)(-X_m)
      dc -= 2.0 * X[j] * Y[m];  // 2 J1j dJ1j = 2 X_j (-Y_m)
      db += -X[m] * X[j] + Y[j] * Y[m];
    }
    k.grad_w[q] = da * cc + a * dc - 2.0 * b * db;
  }
}

// The push-rod law (eq. 2) for joints 2..6, a constant law for joint 1, intersected with eq. 9.
void bounds(const PaperArm& arm, const Joints& theta, Joints& lo, Joints& hi) {
  for (int j = 0; j < kJoints; ++j) {
    double vlo = -arm.joint1_speed, vhi = arm.joint1_speed;
    if (j > 0) {
      const double A = arm.a[j], B = arm.b[j];
      const double rate =
          arm.s * std::sqrt(A * A + B * B + 2.0 * A * B * std::sin(theta[j])) / (A * B * std::cos(theta[j]));
      vlo = std::min(rate * arm.sigma_min, rate * arm.sigma_max);
      vhi = std::max(rate * arm.sigma_min, rate * arm.sigma_max);
    }
    lo[j] = std::max(arm.kappa * ((arm.lower[j] + arm.margin[j]) - theta[j]), vlo);
    hi[j] = std::min(arm.kappa * ((arm.upper[j] - arm.margin[j]) - theta[j]), vhi);
  }
}

// min x'x/2 + zeta'x s.t. J x = d, lo <= x <= hi: x(y) = clip(-zeta - J'y), F(y) = J x(y) - d = 0 by semismooth
// Newton with a backtracking line search on |F|^2; y is warm-started by the caller. Returns the iterations (negative
// when it did not converge).
int solve(const Kinematics& k, const Joints& zeta, double d0, double d1, const Joints& lo, const Joints& hi,
          double y[2], Joints& x) {
  const auto evaluate = [&](const double* yy, Joints& xx, double& f0, double& f1) {
    f0 = -d0;
    f1 = -d1;
    for (int j = 0; j < kJoints; ++j) {
      xx[j] = std::clamp(-zeta[j] - k.J0[j] * yy[0] - k.J1[j] * yy[1], lo[j], hi[j]);
      f0 += k.J0[j] * xx[j];
      f1 += k.J1[j] * xx[j];
    }
  };
  double f0 = 0.0, f1 = 0.0;
  evaluate(y, x, f0, f1);
  const double scale = 1.0 + std::abs(d0) + std::abs(d1);
  for (int it = 1; it <= 60; ++it) {
    if (std::abs(f0) + std::abs(f1) <= 1e-14 * scale) return it - 1;
    // dF/dy = -J_free J_free' over the joints strictly inside their bounds.
    double m00 = 0.0, m01 = 0.0, m11 = 0.0;
    for (int j = 0; j < kJoints; ++j) {
      const double u = -zeta[j] - k.J0[j] * y[0] - k.J1[j] * y[1];
      if (u > lo[j] && u < hi[j]) {
        m00 += k.J0[j] * k.J0[j];
        m01 += k.J0[j] * k.J1[j];
        m11 += k.J1[j] * k.J1[j];
      }
    }
    const double reg = 1e-12 * (1.0 + m00 + m11);
    m00 += reg;
    m11 += reg;
    const double det = m00 * m11 - m01 * m01;
    const double s0 = (m11 * f0 - m01 * f1) / det, s1 = (m00 * f1 - m01 * f0) / det;
    const double merit = f0 * f0 + f1 * f1;
    double step = 1.0;
    for (int back = 0; back < 30; ++back, step *= 0.5) {
      const double trial[2] = {y[0] + step * s0, y[1] + step * s1};
      Joints xt{};
      double g0 = 0.0, g1 = 0.0;
      evaluate(trial, xt, g0, g1);
      if (g0 * g0 + g1 * g1 < merit || back == 29) {
        y[0] = trial[0];
        y[1] = trial[1];
        x = xt;
        f0 = g0;
        f1 = g1;
        break;
      }
    }
  }
  return -60;
}

}  // namespace

Joints run(const PaperArm& arm, const Joints& theta0, const double* r_d, const double* r_d_dot, int steps, double tau,
           Record& record) {
  const double T = steps * tau;
  Joints theta = theta0, x{}, zeta{}, lo{}, hi{};
  Kinematics k;
  double y[2] = {0.0, 0.0};
  double* row = record.rows.data();
  for (int step = 0; step <= steps; ++step) {
    const double t = step == steps ? T : step * tau;
    kinematics(arm, theta, k);
    bounds(arm, theta, lo, hi);
    const double p = arm.p * std::sin(std::numbers::pi * t / T);
    for (int j = 0; j < kJoints; ++j) zeta[j] = -p * k.grad_w[j];
    const double d0 = r_d_dot[2 * step] + arm.gain * (r_d[2 * step] - k.x);
    const double d1 = r_d_dot[2 * step + 1] + arm.gain * (r_d[2 * step + 1] - k.y);
    const int it = solve(k, zeta, d0, d1, lo, hi, y, x);
    record.iterations += it < 0 ? -it : it;
    record.failures += it < 0 ? 1 : 0;
    for (int j = 0; j < kJoints; ++j) {
      row[j] = theta[j];
      row[kJoints + j] = x[j];
    }
    row[2 * kJoints] = k.w;
    row += 2 * kJoints + 1;
    if (step < steps) {
      for (int j = 0; j < kJoints; ++j) theta[j] += tau * x[j];
    }
  }
  return theta;
}

}  // namespace redres::baseline

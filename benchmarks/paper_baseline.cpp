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

// The letter's segments in letter coordinates: a line from a to b, or an arc about a of radius r from angle a0
// through the sweep.
struct Segment {
  bool arc = false;
  double ax = 0.0, ay = 0.0, bx = 0.0, by = 0.0;
  double r = 0.0, a0 = 0.0, sweep = 0.0;
  double length = 0.0;
};

class LetterPath {
 public:
  LetterPath(const LetterR& letter, double ox, double oy, double T)
      : ox_(ox), oy_(oy), c_(std::cos(letter.psi)), s_(std::sin(letter.psi)) {
    const double h = letter.height, c = h / 6.0, rho = h / 4.0, pi = std::numbers::pi;
    const auto line = [](double ax, double ay, double bx, double by) {
      return Segment{false, ax, ay, bx, by, 0.0, 0.0, 0.0, std::hypot(bx - ax, by - ay)};
    };
    seg_[0] = line(0, 0, 0, h);
    seg_[1] = line(0, h, c, h);
    seg_[2] = Segment{true, c, 0.75 * h, 0.0, 0.0, rho, pi / 2.0, -pi, rho * pi};
    seg_[3] = line(c, h / 2.0, 0, h / 2.0);
    seg_[4] = line(0, h / 2.0, c + rho, 0);
    const int first[4] = {0, 1, 4, 5};  // strokes: stem, bowl, leg
    double total = 0.0;
    for (int k = 0; k < 3; ++k) {
      stroke_start_[k] = total;
      double len = 0.0;
      for (int i = first[k]; i < first[k + 1]; ++i) {
        seg_start_[i] = total + len;
        len += seg_[i].length;
      }
      stroke_length_[k] = len;
      total += len;
    }
    total_ = total;
    double t0 = 0.0;
    for (int k = 0; k < 3; ++k) {
      stroke_t0_[k] = t0;
      stroke_T_[k] = T * stroke_length_[k] / total;
      t0 += stroke_T_[k];
    }
  }

  void at(double t, double& x, double& y, double& vx, double& vy) const {
    int k = 0;
    while (k < 2 && stroke_t0_[k + 1] <= t) ++k;
    const double two_pi = 2.0 * std::numbers::pi;
    const double u = std::clamp((t - stroke_t0_[k]) / stroke_T_[k], 0.0, 1.0);
    const double sigma = u - std::sin(two_pi * u) / two_pi, dsigma = 1.0 - std::cos(two_pi * u);
    const double s = std::clamp(stroke_start_[k] + stroke_length_[k] * sigma, 0.0, total_);
    const double speed = stroke_length_[k] * dsigma / stroke_T_[k];
    int i = 0;
    while (i < 4 && seg_start_[i + 1] <= s) ++i;
    const Segment& g = seg_[i];
    const double local = std::min(s - seg_start_[i], g.length);
    double px = 0.0, py = 0.0, tx = 0.0, ty = 0.0;
    if (g.arc) {
      const double frac = local / g.length, angle = g.a0 + frac * g.sweep;
      const double c = std::cos(angle), sn = std::sin(angle), rate = g.sweep / g.length * g.r;
      px = g.ax + g.r * c;
      py = g.ay + g.r * sn;
      tx = -rate * sn;
      ty = rate * c;
    } else {
      tx = (g.bx - g.ax) / g.length;
      ty = (g.by - g.ay) / g.length;
      px = g.ax + local * tx;
      py = g.ay + local * ty;
    }
    x = ox_ + c_ * px - s_ * py;
    y = oy_ + s_ * px + c_ * py;
    vx = (c_ * tx - s_ * ty) * speed;
    vy = (s_ * tx + c_ * ty) * speed;
  }

 private:
  Segment seg_[5];
  double seg_start_[5] = {}, stroke_start_[3] = {}, stroke_length_[3] = {}, stroke_t0_[3] = {}, stroke_T_[3] = {};
  double total_ = 0.0, ox_, oy_, c_, s_;
};

// The loop shared by both runs; desired(step, t, r_d[2], r_d_dot[2]) gives the path.
template <class Desired>
Joints run_loop(const PaperArm& arm, const Joints& theta0, const Desired& desired, int steps, double tau,
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
    double r_d[2], r_d_dot[2];
    desired(step, t, r_d, r_d_dot);
    const double d0 = r_d_dot[0] + arm.gain * (r_d[0] - k.x);
    const double d1 = r_d_dot[1] + arm.gain * (r_d[1] - k.y);
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

}  // namespace

Joints run(const PaperArm& arm, const Joints& theta0, const double* r_d, const double* r_d_dot, int steps, double tau,
           Record& record) {
  return run_loop(
      arm, theta0,
      [&](int step, double /*t*/, double* r, double* v) {
        r[0] = r_d[2 * step];
        r[1] = r_d[2 * step + 1];
        v[0] = r_d_dot[2 * step];
        v[1] = r_d_dot[2 * step + 1];
      },
      steps, tau, record);
}

void letter_r_at(const LetterR& letter, double ox, double oy, double T, double t, double r[2], double v[2]) {
  LetterPath(letter, ox, oy, T).at(t, r[0], r[1], v[0], v[1]);
}

void end_effector(const PaperArm& arm, const Joints& theta, double f[2]) {
  Kinematics k;
  kinematics(arm, theta, k);
  f[0] = k.x;
  f[1] = k.y;
}

Joints run_letter_r(const PaperArm& arm, const LetterR& letter, const Joints& theta0, int steps, double tau,
                    Record& record) {
  Kinematics k0;
  kinematics(arm, theta0, k0);
  const LetterPath path(letter, k0.x + letter.offset[0], k0.y + letter.offset[1], steps * tau);
  return run_loop(
      arm, theta0, [&](int /*step*/, double t, double* r, double* v) { path.at(t, r[0], r[1], v[0], v[1]); }, steps,
      tau, record);
}

}  // namespace redres::baseline

#include "model/closed_form_distance.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace redres {

void closest_on_segments(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& q0,
                         const Eigen::Vector3d& q1, double& s, double& t) {
  const Eigen::Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  constexpr double tiny = 1e-24;
  if (a <= tiny && e <= tiny) {
    s = t = 0.0;
    return;
  }
  if (a <= tiny) {
    s = 0.0;
    t = std::clamp(f / e, 0.0, 1.0);
    return;
  }
  const double c = d1.dot(r);
  if (e <= tiny) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
    return;
  }
  const double b = d1.dot(d2), denom = a * e - b * b;
  s = denom > tiny ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
  t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
}

namespace {

// Signed distance from point q (box frame) to the box with half sides h, and the nearest point on its surface with
// the outward unit direction u (from that point towards q when q is outside; the nearest face's normal inside).
double box_point(const Eigen::Vector3d& q, const Eigen::Vector3d& h, Eigen::Vector3d& on_box, Eigen::Vector3d& u) {
  const Eigen::Vector3d excess = q.cwiseAbs() - h;
  if ((excess.array() > 0.0).any()) {
    on_box = q.cwiseMax(-h).cwiseMin(h);
    const Eigen::Vector3d diff = q - on_box;
    const double d = diff.norm();
    u = diff / d;
    return d;
  }
  Eigen::Index k = 0;
  const double d = excess.maxCoeff(&k);  // <= 0: the nearest face is the one along axis k
  const double side = q(k) < 0.0 ? -1.0 : 1.0;
  on_box = q;
  on_box(k) = side * h(k);
  u = Eigen::Vector3d::Zero();
  u(k) = side;
  return d;
}

}  // namespace

void round_box(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, double r, const Eigen::Isometry3d& Tb,
               const Eigen::Vector3d& h, double& d, Eigen::Vector3d& on_round, Eigen::Vector3d& on_box,
               Eigen::Vector3d* normal) {
  const Eigen::Isometry3d to_box = Tb.inverse();
  const Eigen::Vector3d q0 = to_box * p0, dq = to_box * p1 - q0;
  double best_s = 0.0;
  if (dq.squaredNorm() > 0.0) {
    std::array<double, 8> cuts{};
    int count = 0;
    cuts[static_cast<std::size_t>(count++)] = 0.0;
    cuts[static_cast<std::size_t>(count++)] = 1.0;
    for (int k = 0; k < 3; ++k) {
      if (dq(k) == 0.0) continue;
      for (const double side : {-1.0, 1.0}) {
        const double s = (side * h(k) - q0(k)) / dq(k);
        if (s > 0.0 && s < 1.0) cuts[static_cast<std::size_t>(count++)] = s;
      }
    }
    for (int i = 1; i < count; ++i) {  // insertion sort of at most 8
      for (int j = i; j > 0 && cuts[static_cast<std::size_t>(j)] < cuts[static_cast<std::size_t>(j - 1)]; --j)
        std::swap(cuts[static_cast<std::size_t>(j)], cuts[static_cast<std::size_t>(j - 1)]);
    }
    const auto outside2 = [&](double s) {
      double g = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double e = std::abs(q0(k) + s * dq(k)) - h(k);
        if (e > 0.0) g += e * e;
      }
      return g;
    };
    double best_g = outside2(0.0);
    for (int c = 0; c + 1 < count; ++c) {
      const double a = cuts[static_cast<std::size_t>(c)], b = cuts[static_cast<std::size_t>(c + 1)];
      if (!(b > a)) continue;
      // The piece's quadratic sum_k (c_k + s dq_k)^2 over the axes outside the box at its middle.
      const double mid = 0.5 * (a + b);
      double a2 = 0.0, a1 = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double x = q0(k) + mid * dq(k);
        if (x > h(k) || x < -h(k)) {
          const double ck = q0(k) - (x > 0.0 ? h(k) : -h(k));
          a2 += dq(k) * dq(k);
          a1 += ck * dq(k);
        }
      }
      const double s = a2 > 0.0 ? std::clamp(-a1 / a2, a, b) : b;
      for (const double t : {s, b}) {
        const double g = outside2(t);
        if (g < best_g) {
          best_g = g;
          best_s = t;
        }
      }
    }
    // Where the axis enters the box, g is zero only in exact arithmetic (a rounding residue of 1e-34 was seen): the
    // axis reaches the box when g is below the square of a rounding-sized distance.
    const double touch = 1e-12 * (h.maxCoeff() + dq.norm());
    if (!(best_g > touch * touch)) {
      // The axis reaches the box: the deepest point, among the ends and the crossings of the six lines.
      std::array<double, 6> slope{}, offset{};  // line j: slope s + offset = +-q_k(s) - h_k
      for (int k = 0; k < 3; ++k) {
        slope[static_cast<std::size_t>(2 * k)] = dq(k);
        offset[static_cast<std::size_t>(2 * k)] = q0(k) - h(k);
        slope[static_cast<std::size_t>(2 * k + 1)] = -dq(k);
        offset[static_cast<std::size_t>(2 * k + 1)] = -q0(k) - h(k);
      }
      const auto inside = [&](double s) {
        double f = -std::numeric_limits<double>::infinity();
        for (std::size_t j = 0; j < 6; ++j) f = std::max(f, slope[j] * s + offset[j]);
        return f;
      };
      double best_f = inside(best_s);
      const auto consider = [&](double s) {
        if (!(s >= 0.0 && s <= 1.0)) return;
        const double f = inside(s);
        if (f < best_f) {
          best_f = f;
          best_s = s;
        }
      };
      consider(0.0);
      consider(1.0);
      for (std::size_t i = 0; i < 6; ++i) {
        for (std::size_t j = i + 1; j < 6; ++j) {
          if (slope[i] != slope[j]) consider((offset[j] - offset[i]) / (slope[i] - slope[j]));
        }
      }
    }
  }
  Eigen::Vector3d c, u;
  const Eigen::Vector3d q = q0 + best_s * dq;
  d = box_point(q, h, c, u) - r;
  const Eigen::Vector3d u_world = Tb.linear() * u;
  on_box = Tb * c;
  on_round = Tb * q - r * u_world;
  if (normal != nullptr) *normal = u_world;
}

double RoundMetric::bound(const Eigen::Vector3d& c, double h, double best) const {
  // First the ball's distance to the cube (a few flops); only a cube that ball does not rule out gets the exact
  // distance, which bounds the cells inside it.
  const double ball = ((mid - c).cwiseAbs().array() - h).max(0.0).matrix().norm() - reach;
  if (!(ball < best)) return ball;
  Eigen::Vector3d a, b;
  return cell(c, h, a, b);
}

double RoundMetric::cell(const Eigen::Vector3d& c, double h, Eigen::Vector3d& on_query,
                         Eigen::Vector3d& on_cloud) const {
  Eigen::Isometry3d Tc = Eigen::Isometry3d::Identity();
  Tc.translation() = c;
  double d = 0.0;
  Eigen::Vector3d u;
  round_box(p0, p1, r, Tc, Eigen::Vector3d::Constant(h), d, on_query, on_cloud, &u);
  // on_query - on_cloud = d u, with u the cube's outward unit normal at the witness: the grown cube's point is g
  // further along it (u from round_box itself, so a near-zero d does not turn it into noise).
  on_cloud += g * u;
  return d - g;
}

}  // namespace redres

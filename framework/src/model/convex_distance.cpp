// GJK distance with a fixed-size simplex and libccd's MPR for overlapping cores (model/convex_distance.hpp).

#include "model/convex_distance.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <ccd/ccd.h>

namespace redres::convex {

int Core::support(const Eigen::Vector3d& d, Eigen::Vector3d& out) const {
  const Eigen::Vector3d local = R.transpose() * d;
  if (vertices == nullptr) {  // a cylinder about local z
    Eigen::Vector3d p(0.0, 0.0, local.z() < 0.0 ? -cylinder_half : cylinder_half);
    const double radial = std::hypot(local.x(), local.y());
    if (radial > 0.0) {
      p.x() = cylinder_radius * local.x() / radial;
      p.y() = cylinder_radius * local.y() / radial;
    }
    out = R * p + t;
    return -1;
  }
  if (first_neighbour != nullptr) {
    int at = last;
    double most = local.dot(vertices[at]);
    for (;;) {
      int next = -1;
      for (int j = first_neighbour[at]; j < first_neighbour[at + 1]; ++j) {
        const double h = local.dot(vertices[neighbours[j]]);
        if (h > most) {
          most = h;
          next = neighbours[j];
        }
      }
      if (next < 0) break;
      at = next;
    }
    last = at;
    out = R * vertices[at] + t;
    return at;
  }
  int best = 0;
  double most = local.dot(vertices[0]);
  for (int k = 1; k < count; ++k) {
    const double h = local.dot(vertices[k]);
    if (h > most) {
      most = h;
      best = k;
    }
  }
  out = R * vertices[best] + t;
  return best;
}

namespace {

// A point of the Minkowski difference a - b: w = pa - pb, with the vertices it came from (-1: a smooth support).
struct Point {
  Eigen::Vector3d w, pa, pb;
  int ia = -1, ib = -1;
};

// The simplex and the barycentric weights of its closest point to the origin.
struct Simplex {
  std::array<Point, 4> p{};
  std::array<double, 4> weight{};
  int n = 0;
};

// Closest point of the segment [A, B] to the origin: weights of A and B; returns its squared distance.
double segment(const Eigen::Vector3d& A, const Eigen::Vector3d& B, double& la, double& lb) {
  const Eigen::Vector3d ab = B - A;
  const double len2 = ab.squaredNorm();
  double t = len2 > 0.0 ? -A.dot(ab) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  la = 1.0 - t;
  lb = t;
  return (la * A + lb * B).squaredNorm();
}

// Closest point of the triangle ABC to the origin by its Voronoi regions (vertices, edges, face): weights l; returns
// its squared distance. A triangle too thin for its face weights is measured by its three edges.
double triangle(const Eigen::Vector3d& A, const Eigen::Vector3d& B, const Eigen::Vector3d& C,
                std::array<double, 3>& l) {
  const Eigen::Vector3d ab = B - A, ac = C - A;
  const double d1 = -ab.dot(A), d2 = -ac.dot(A);
  if (d1 <= 0.0 && d2 <= 0.0) {
    l = {1.0, 0.0, 0.0};
    return A.squaredNorm();
  }
  const double d3 = -ab.dot(B), d4 = -ac.dot(B);
  if (d3 >= 0.0 && d4 <= d3) {
    l = {0.0, 1.0, 0.0};
    return B.squaredNorm();
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double t = d1 / (d1 - d3);
    l = {1.0 - t, t, 0.0};
    return (A + t * ab).squaredNorm();
  }
  const double d5 = -ab.dot(C), d6 = -ac.dot(C);
  if (d6 >= 0.0 && d5 <= d6) {
    l = {0.0, 0.0, 1.0};
    return C.squaredNorm();
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double t = d2 / (d2 - d6);
    l = {1.0 - t, 0.0, t};
    return (A + t * ac).squaredNorm();
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    l = {0.0, 1.0 - t, t};
    return (B + t * (C - B)).squaredNorm();
  }
  const double sum = va + vb + vc;  // = |ab x ac|^2
  if (!(sum > 1e-18 * ab.squaredNorm() * ac.squaredNorm())) {
    // (Almost) collinear: the nearest of the three edges.
    double best = std::numeric_limits<double>::infinity();
    double x = 0.0, y = 0.0;
    const std::array<std::array<int, 2>, 3> edges{{{0, 1}, {0, 2}, {1, 2}}};
    const std::array<const Eigen::Vector3d*, 3> v{&A, &B, &C};
    for (const auto& e : edges) {
      const double d = segment(*v[static_cast<std::size_t>(e[0])], *v[static_cast<std::size_t>(e[1])], x, y);
      if (d < best) {
        best = d;
        l = {0.0, 0.0, 0.0};
        l[static_cast<std::size_t>(e[0])] = x;
        l[static_cast<std::size_t>(e[1])] = y;
      }
    }
    return best;
  }
  l = {va / sum, vb / sum, vc / sum};
  return (l[0] * A + l[1] * B + l[2] * C).squaredNorm();
}

// The closest point of the simplex to the origin: sets the weights, drops the vertices of weight 0 and returns the
// point (sets `inside` when a tetrahedron holds the origin).
Eigen::Vector3d closest(Simplex& s, bool& inside) {
  inside = false;
  std::array<double, 4> w{};
  switch (s.n) {
    case 1: w[0] = 1.0; break;
    case 2: segment(s.p[0].w, s.p[1].w, w[0], w[1]); break;
    case 3: {
      std::array<double, 3> l{};
      triangle(s.p[0].w, s.p[1].w, s.p[2].w, l);
      w = {l[0], l[1], l[2], 0.0};
      break;
    }
    default: {
      // The faces (i, j, k) with the fourth vertex m: the origin is outside a face when it and m are on opposite sides
      // of its plane. A flat tetrahedron has no inside: every face is measured.
      static constexpr std::array<std::array<int, 4>, 4> faces{
          {{0, 1, 2, 3}, {0, 3, 1, 2}, {0, 2, 3, 1}, {1, 3, 2, 0}}};
      double longest = 0.0;
      for (int i = 0; i < 4; ++i) {
        for (int j = i + 1; j < 4; ++j) {
          longest = std::max(longest,
                             (s.p[static_cast<std::size_t>(i)].w - s.p[static_cast<std::size_t>(j)].w).squaredNorm());
        }
      }
      const auto P = [&](int k) -> const Eigen::Vector3d& { return s.p[static_cast<std::size_t>(k)].w; };
      const double volume = (P(1) - P(0)).cross(P(2) - P(0)).dot(P(3) - P(0));
      const bool flat = !(std::abs(volume) > 1e-13 * longest * std::sqrt(longest));
      double best = std::numeric_limits<double>::infinity();
      for (const auto& f : faces) {
        const Eigen::Vector3d& A = P(f[0]);
        const Eigen::Vector3d normal = (P(f[1]) - A).cross(P(f[2]) - A);
        const double origin_side = -normal.dot(A), other_side = normal.dot(P(f[3]) - A);
        if (!flat && !(origin_side * other_side < 0.0)) continue;
        std::array<double, 3> l{};
        const double d = triangle(A, P(f[1]), P(f[2]), l);
        if (d < best) {
          best = d;
          w = {0.0, 0.0, 0.0, 0.0};
          for (int k = 0; k < 3; ++k)
            w[static_cast<std::size_t>(f[static_cast<std::size_t>(k)])] = l[static_cast<std::size_t>(k)];
        }
      }
      if (!std::isfinite(best)) {  // outside no face: the origin is inside
        inside = true;
        return Eigen::Vector3d::Zero();
      }
      break;
    }
  }
  // Keep the vertices that carry weight.
  int kept = 0;
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (int k = 0; k < s.n; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    if (!(w[ks] > 0.0)) continue;
    v += w[ks] * s.p[ks].w;
    s.p[static_cast<std::size_t>(kept)] = s.p[ks];
    s.weight[static_cast<std::size_t>(kept)] = w[ks];
    ++kept;
  }
  s.n = kept;
  return v;
}

Point support(const Core& a, const Core& b, const Eigen::Vector3d& d) {
  // The point of a - b farthest along d: a's along d, b's along -d.
  Point p;
  p.ia = a.support(d, p.pa);
  p.ib = b.support(-d, p.pb);
  p.w = p.pa - p.pb;
  return p;
}

Eigen::Vector3d world_centre(const Core& c) { return c.R * c.centre + c.t; }

// GJK on the cores: their distance (0 when they overlap) and closest points.
double gjk(const Core& a, const Core& b, Eigen::Vector3d& on_a, Eigen::Vector3d& on_b) {
  Eigen::Vector3d d = world_centre(b) - world_centre(a);  // towards b: a's support there, b's the other way
  if (!(d.squaredNorm() > 0.0)) d = Eigen::Vector3d::UnitX();
  Simplex s;
  s.p[0] = support(a, b, d);
  s.weight[0] = 1.0;
  s.n = 1;
  Eigen::Vector3d v = s.p[0].w;
  on_a = s.p[0].pa;
  on_b = s.p[0].pb;
  // The scale of the problem, for the test of touching cores.
  const double scale = std::max({1.0, d.norm(), v.norm()});
  const double touching = 1e-12 * scale;
  for (int iteration = 0; iteration < 128; ++iteration) {
    const double vv = v.squaredNorm();
    if (!(vv > touching * touching)) return 0.0;
    const Point w = support(a, b, -v);
    // Stop when the support point is already in the simplex (exact for polytopes) or no longer improves on v by more
    // than rounding (|v| - distance <= (v.v - v.w) / |v|).
    bool repeated = false;
    for (int k = 0; k < s.n && w.ia >= 0 && w.ib >= 0; ++k) {
      repeated =
          repeated || (s.p[static_cast<std::size_t>(k)].ia == w.ia && s.p[static_cast<std::size_t>(k)].ib == w.ib);
    }
    if (repeated || vv - v.dot(w.w) <= 1e-13 * vv) break;
    Simplex next = s;
    next.p[static_cast<std::size_t>(next.n++)] = w;
    bool inside = false;
    const Eigen::Vector3d v_next = closest(next, inside);
    if (inside) return 0.0;
    if (!(v_next.squaredNorm() < vv)) break;  // no progress (rounding): keep the last simplex
    s = next;
    v = v_next;
    on_a.setZero();
    on_b.setZero();
    for (int k = 0; k < s.n; ++k) {
      const auto ks = static_cast<std::size_t>(k);
      on_a += s.weight[ks] * s.p[ks].pa;
      on_b += s.weight[ks] * s.p[ks].pb;
    }
  }
  if (!(v.squaredNorm() > touching * touching)) return 0.0;
  return v.norm();
}

// libccd's callbacks: a Core's support point and centre.
void ccd_support(const void* object, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const Core& c = *static_cast<const Core*>(object);
  Eigen::Vector3d p;
  c.support(Eigen::Vector3d(dir->v[0], dir->v[1], dir->v[2]), p);
  for (int k = 0; k < 3; ++k) out->v[k] = p(k);
}

void ccd_centre(const void* object, ccd_vec3_t* out) {
  const Eigen::Vector3d p = world_centre(*static_cast<const Core*>(object));
  for (int k = 0; k < 3; ++k) out->v[k] = p(k);
}

}  // namespace

double core_distance(const Core& a, const Core& b, Eigen::Vector3d& on_a, Eigen::Vector3d& on_b) {
  return gjk(a, b, on_a, on_b);
}

Result distance(const Core& a, const Core& b) {
  Result out;
  Eigen::Vector3d ca, cb;
  const double d = gjk(a, b, ca, cb);
  if (d > 0.0) {
    // The cores apart: the shapes' distance is theirs less the radii, exact whatever its sign.
    const Eigen::Vector3d u = (ca - cb) / d;
    out.distance = d - a.radius - b.radius;
    out.point_a = ca - a.radius * u;
    out.point_b = cb + b.radius * u;
    return out;
  }
  // The cores overlap: MPR's direction n (pointing from a into b), and the overlap of the extents along it.
  out.cores_overlap = true;
  ccd_t ccd{};
  ccd.first_dir = ccdFirstDirDefault;
  ccd.support1 = ccd_support;
  ccd.support2 = ccd_support;
  ccd.center1 = ccd_centre;
  ccd.center2 = ccd_centre;
  ccd.max_iterations = 64;
  ccd.epa_tolerance = 1e-4;  // unused: EPA is never run
  ccd.mpr_tolerance = 1e-9;
  ccd.dist_tolerance = 1e-12;
  ccd_real_t mpr_depth = 0.0;
  ccd_vec3_t dir{}, pos{};
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  if (ccdMPRPenetration(&a, &b, &ccd, &mpr_depth, &dir, &pos) == 0) n = Eigen::Vector3d(dir.v[0], dir.v[1], dir.v[2]);
  if (!(n.allFinite() && n.norm() > 0.5)) {
    // MPR found no overlap (the cores touch) or no direction: the centres' direction.
    n = world_centre(b) - world_centre(a);
    if (!(n.squaredNorm() > 0.0)) n = Eigen::Vector3d::UnitZ();
  }
  n.normalize();
  Eigen::Vector3d sa, sb;
  a.support(n, sa);
  b.support(-n, sb);
  // The face normals: a's (n = its outward normal: b lies beyond that face) and b's (n = minus its outward normal).
  // A face whose depth cannot beat the best is skipped without its support loop: the other core's extent along the
  // face normal reaches at least its centre, so the depth is at least h - m.centre.
  double best = n.dot(sa - sb);
  const Eigen::Vector3d centre_a = world_centre(a), centre_b = world_centre(b);
  for (int k = 0; k < a.plane_count; ++k) {
    const Eigen::Vector3d m = a.R * a.planes[k].head<3>();
    const double h = a.planes[k](3) + m.dot(a.t);
    if (!(h - m.dot(centre_b) < best)) continue;
    b.support(-m, sb);
    const double depth = h - m.dot(sb);
    if (depth < best) {
      best = depth;
      n = m;
    }
  }
  for (int k = 0; k < b.plane_count; ++k) {
    const Eigen::Vector3d m = b.R * b.planes[k].head<3>();
    const double h = b.planes[k](3) + m.dot(b.t);
    if (!(h - m.dot(centre_a) < best)) continue;
    a.support(-m, sa);
    const double depth = h - m.dot(sa);
    if (depth < best) {
      best = depth;
      n = -m;
    }
  }
  a.support(n, sa);
  b.support(-n, sb);
  const double overlap = std::max(0.0, n.dot(sa - sb)) + a.radius + b.radius;
  out.distance = -overlap;
  out.point_a = sa + a.radius * n;
  out.point_b = out.point_a - overlap * n;
  return out;
}

}  // namespace redres::convex

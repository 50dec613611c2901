// Convex hulls of mesh pieces, through Debian's qhull (the reentrant libqhull_r).

#include "redres/model/convex.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

namespace redres {

namespace {

// One qhull run, its memory freed however it ends, its messages caught in memory (qhull prints its errors to a FILE).
class Qhull {
 public:
  Qhull() : err_(open_memstream(&text_, &size_)) { qh_zero(&qh_, err_); }
  ~Qhull() {
    qh_freeqhull(&qh_, !qh_ALL);
    int curlong = 0, totlong = 0;
    qh_memfreeshort(&qh_, &curlong, &totlong);
    if (err_ != nullptr) std::fclose(err_);
    std::free(text_);
  }
  Qhull(const Qhull&) = delete;
  Qhull& operator=(const Qhull&) = delete;
  qhT* get() { return &qh_; }
  FILE* err() { return err_; }
  // qhull's first message line (e.g. "QH6154 qhull precision error: initial simplex is flat ...").
  std::string message() {
    if (err_ == nullptr) return {};
    std::fflush(err_);
    std::string all(text_ != nullptr ? text_ : "", size_);
    const auto start = all.find("QH");
    if (start != std::string::npos) all.erase(0, start);
    const auto end = all.find('\n');
    return all.substr(0, end);
  }

 private:
  qhT qh_{};
  char* text_ = nullptr;
  std::size_t size_ = 0;
  FILE* err_ = nullptr;
};

}  // namespace

std::shared_ptr<const ConvexHull> convex_hull(const std::vector<Eigen::Vector3d>& points, const std::string& what,
                                              Eigen::Vector3d& centre) {
  std::vector<Eigen::Vector3d> distinct;
  distinct.reserve(points.size());
  for (const auto& p : points) {
    if (!p.allFinite()) throw std::invalid_argument(what + ": a vertex is not finite");
    distinct.push_back(p);
  }
  std::sort(distinct.begin(), distinct.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  });
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  const std::string remedy = " (a convex hull needs a solid; give this link `collision_model = \"capsule\"`)";
  if (distinct.size() < 4) {
    throw std::invalid_argument(what + ": " + std::to_string(distinct.size()) +
                                " distinct vertices, too few for a convex hull" + remedy);
  }
  // Flat or straight input, by its spread across its principal directions (qhull would say the same, less plainly).
  Eigen::Vector3d lo = distinct.front(), hi = distinct.front();
  for (const auto& p : distinct) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double extent = (hi - lo).norm();
  std::vector<double> coords;
  coords.reserve(3 * distinct.size());
  for (const auto& p : distinct) coords.insert(coords.end(), {p.x(), p.y(), p.z()});
  Qhull q;
  char options[] = "qhull Qt";  // triangulated facets
  const int code =
      qh_new_qhull(q.get(), 3, static_cast<int>(distinct.size()), coords.data(), False, options, nullptr, q.err());
  if (code != 0) {
    const std::string message = q.message();
    const bool flat = message.find("flat") != std::string::npos || message.find("QH6154") != std::string::npos;
    throw std::invalid_argument(what + ": " +
                                (flat ? "its vertices lie on a plane or a line (" + std::to_string(distinct.size()) +
                                            " vertices across " + std::to_string(extent) + " m)"
                                      : "qhull could not make its convex hull") +
                                (message.empty() ? "" : ": qhull: " + message) + remedy);
  }
  qhT* qh = q.get();
  auto hull = std::make_shared<ConvexHull>();
  std::map<int, int> index;  // qhull's point id -> our vertex index
  for (facetT* facet = qh->facet_list; facet != nullptr && facet->next != nullptr; facet = facet->next) {
    if (facet->upperdelaunay) continue;
    std::array<int, 3> tri{};
    int n = 0;
    for (void** v = &facet->vertices->e[0].p; *v != nullptr; ++v) {
      auto* vertex = static_cast<vertexT*>(*v);
      const int id = qh_pointid(qh, vertex->point);
      const auto [it, fresh] = index.emplace(id, static_cast<int>(hull->vertices.size()));
      if (fresh) hull->vertices.push_back(distinct[static_cast<std::size_t>(id)]);
      if (n < 3) tri[static_cast<std::size_t>(n)] = it->second;
      ++n;
    }
    if (n != 3) throw std::invalid_argument(what + ": qhull returned a facet that is not a triangle");
    // Counter-clockwise seen from outside: the triangle's normal along the facet's outward normal.
    const Eigen::Vector3d& a = hull->vertices[static_cast<std::size_t>(tri[0])];
    const Eigen::Vector3d& b = hull->vertices[static_cast<std::size_t>(tri[1])];
    const Eigen::Vector3d& c = hull->vertices[static_cast<std::size_t>(tri[2])];
    const Eigen::Vector3d normal(facet->normal[0], facet->normal[1], facet->normal[2]);
    if ((b - a).cross(c - a).dot(normal) < 0.0) std::swap(tri[1], tri[2]);
    hull->faces.push_back(tri);
  }
  if (hull->vertices.size() < 4 || hull->faces.size() < 4) {
    throw std::invalid_argument(what + ": its vertices lie on a plane or a line" + remedy);
  }
  lo = hull->vertices.front();
  hi = lo;
  for (const auto& p : hull->vertices) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  centre = 0.5 * (lo + hi);
  for (auto& p : hull->vertices) {
    p -= centre;
    hull->bound = std::max(hull->bound, p.norm());
  }
  hull->half_extent = 0.5 * (hi - lo);
  // Each vertex's neighbours along the triangles' edges.
  std::vector<std::vector<int>> adjacent(hull->vertices.size());
  for (const auto& f : hull->faces) {
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = f[k], b = f[(k + 1) % 3];
      adjacent[static_cast<std::size_t>(a)].push_back(b);
      adjacent[static_cast<std::size_t>(b)].push_back(a);
    }
  }
  hull->first_neighbour.push_back(0);
  for (auto& list : adjacent) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    hull->neighbours.insert(hull->neighbours.end(), list.begin(), list.end());
    hull->first_neighbour.push_back(static_cast<int>(hull->neighbours.size()));
  }
  return hull;
}

ShapeSpec convex_shape(const std::vector<Eigen::Vector3d>& points, const std::filesystem::path& file, int piece,
                       int pieces) {
  const std::string what =
      "mesh '" + file.string() + "'" +
      (pieces > 1 ? " piece " + std::to_string(piece + 1) + " of " + std::to_string(pieces) : std::string());
  Eigen::Vector3d centre;
  std::shared_ptr<const ConvexHull> made = convex_hull(points, what, centre);
  auto hull = std::make_shared<ConvexHull>(*made);
  hull->source = file;
  hull->piece = piece;
  hull->pieces = pieces;
  ShapeSpec s;
  s.shape = ShapeSpec::Kind::kConvex;
  s.hull = std::move(hull);
  s.file = file;
  s.xyz = {centre.x(), centre.y(), centre.z()};
  return s;
}

}  // namespace redres

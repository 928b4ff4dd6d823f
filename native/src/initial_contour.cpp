// Initial contour by plane sections (Section 7.1, Figure 5), shortest-edge-path
// fallback, arc-length resampling and extension of open contours to the boundary.
#include "relief_snake/initial_contour.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <utility>

#include "relief_snake/error.hpp"

namespace relief_snake {
namespace {

constexpr double kWeightEps = 1e-12;  // barycentric weights below this are zero (point on an edge/vertex)

// Corners of p's face that carry weight; returns how many (1: at a vertex, 2: on an edge, 3: inside).
int support(const Mesh& mesh, const SurfacePoint& p, int corners[3]) {
  int n = 0;
  for (int k = 0; k < 3; ++k)
    if (p.bary[k] > kWeightEps) corners[n++] = k;
  if (n == 0) corners[n++] = 0;  // malformed weights: treat as the first corner
  (void)mesh;
  return n;
}

// Every face that contains p (its own face, the two faces of its edge, or its vertex's ring).
void faces_containing(const Mesh& mesh, const SurfacePoint& p, std::vector<int>* faces) {
  faces->clear();
  int c[3];
  const int n = support(mesh, p, c);
  if (n == 1) {
    const int v = mesh.face_vertex(p.face, c[0]);
    faces->assign(mesh.faces_begin(v), mesh.faces_end(v));
  } else if (n == 2) {
    faces->push_back(p.face);
    const int zero = 3 - c[0] - c[1];  // the corner opposite the edge p lies on
    const int g = mesh.face_neighbor(p.face, zero);
    if (g >= 0) faces->push_back(g);
  } else {
    faces->push_back(p.face);
  }
}

int corner_of(const Mesh& mesh, int f, int v) {
  for (int k = 0; k < 3; ++k)
    if (mesh.face_vertex(f, k) == v) return k;
  return -1;
}

// Vertex u as a point of a face that also contains vertex w (so the edge u-w is a path segment).
SurfacePoint vertex_point_towards(const Mesh& mesh, int u, int w) {
  for (const int* f = mesh.faces_begin(u); f != mesh.faces_end(u); ++f) {
    if (corner_of(mesh, *f, w) >= 0) {
      SurfacePoint p;
      p.face = *f;
      p.bary = Vec3::Zero();
      p.bary[corner_of(mesh, *f, u)] = 1.0;
      return p;
    }
  }
  return vertex_point(mesh, u);
}

// The section plane: signed distance s(v) = (x_v - origin) . m, with s == 0 counted as
// positive (a consistent perturbation: the plane never passes exactly through a vertex).
struct SectionPlane {
  Vec3 origin, m;
  double s(const Mesh& mesh, int v) const { return (mesh.position(v) - origin).dot(m); }
  bool positive(const Mesh& mesh, int v) const { return s(mesh, v) >= 0.0; }
};

// Where the plane crosses edge (u, v) of face f (signs must differ): the point as
// barycentrics of f and as a position. Computed in a canonical vertex order so both
// faces of the edge get the very same point.
void crossing(const Mesh& mesh, const SectionPlane& plane, int f, int u, int v, Vec3* bary, Vec3* x) {
  const int lo = std::min(u, v), hi = std::max(u, v);
  const double slo = plane.s(mesh, lo), shi = plane.s(mesh, hi);
  double t = slo / (slo - shi);
  if (!(t >= 0.0)) t = 0.0;
  if (t > 1.0) t = 1.0;
  *x = mesh.position(lo) + t * (mesh.position(hi) - mesh.position(lo));
  *bary = Vec3::Zero();
  (*bary)[corner_of(mesh, f, lo)] = 1.0 - t;
  (*bary)[corner_of(mesh, f, hi)] = t;
}

// One attempt: march from a along the section, leaving a in the direction closest to
// `forward`, until a face containing b. See plane_section_path for the failure cases.
bool march(const Mesh& mesh, const SurfacePoint& a, const SurfacePoint& b, const SectionPlane& plane,
           const Vec3& forward, double max_length, SurfacePath* out) {
  const Vec3 pa = position(mesh, a);
  const double tol = 1e-9 * std::max(mesh.average_edge_length(), 1e-300);
  std::vector<int> start_faces;
  faces_containing(mesh, a, &start_faces);

  // Leave a through the crossing (over all faces containing a) that best heads forward.
  int g0 = -1, exit_k = -1;
  double best = -std::numeric_limits<double>::infinity();
  Vec3 exit_x = Vec3::Zero();
  for (int g : start_faces) {
    for (int k = 0; k < 3; ++k) {
      const int u = mesh.face_vertex(g, (k + 1) % 3), v = mesh.face_vertex(g, (k + 2) % 3);
      if (plane.positive(mesh, u) == plane.positive(mesh, v)) continue;
      Vec3 bary, x;
      crossing(mesh, plane, g, u, v, &bary, &x);
      const Vec3 step = x - pa;
      const double len = step.norm();
      if (len <= tol) continue;  // the crossing at a itself (a on an edge or vertex)
      const double score = step.dot(forward) / len;
      if (score > best) {
        best = score;
        g0 = g;
        exit_k = k;
        exit_x = x;
      }
    }
  }
  if (g0 < 0) return false;

  SurfacePath path;
  SurfacePoint start;
  start.face = g0;
  if (!in_face(mesh, a, g0, &start.bary)) return false;
  path.push_back(start);

  int g = g0;
  Vec3 x = exit_x;
  double length = (x - pa).norm();
  const int max_steps = mesh.n_faces() + 1;
  for (int step = 0; step < max_steps; ++step) {
    if (length > max_length) return false;
    const int u = mesh.face_vertex(g, (exit_k + 1) % 3), v = mesh.face_vertex(g, (exit_k + 2) % 3);
    const int next = mesh.face_neighbor(g, exit_k);
    if (next < 0 || next == g0) return false;  // mesh boundary, or the section closed on itself
    SurfacePoint c;
    c.face = next;
    Vec3 xc;
    crossing(mesh, plane, next, u, v, &c.bary, &xc);
    path.push_back(c);
    SurfacePoint end;
    if (in_face(mesh, b, next, &end.bary)) {
      end.face = next;
      path.push_back(end);
      *out = std::move(path);
      return true;
    }
    // The other edge of `next` that the plane crosses (there is exactly one more).
    const int entry_k = 3 - corner_of(mesh, next, u) - corner_of(mesh, next, v);
    int k_out = -1;
    for (int k = 0; k < 3; ++k) {
      if (k == entry_k) continue;
      const int p = mesh.face_vertex(next, (k + 1) % 3), q = mesh.face_vertex(next, (k + 2) % 3);
      if (plane.positive(mesh, p) != plane.positive(mesh, q)) {
        k_out = k;
        break;
      }
    }
    if (k_out < 0) return false;  // cannot happen with consistent signs; be safe
    Vec3 bary_unused, xn;
    crossing(mesh, plane, next, mesh.face_vertex(next, (k_out + 1) % 3), mesh.face_vertex(next, (k_out + 2) % 3),
             &bary_unused, &xn);
    length += (xn - x).norm();
    x = xn;
    g = next;
    exit_k = k_out;
  }
  return false;
}

// Dijkstra over mesh edges from `source` until a vertex with is_target(v); the vertex
// sequence source..target in *vertices. False if no target is reachable.
bool dijkstra(const Mesh& mesh, int source, const std::function<bool(int)>& is_target, std::vector<int>* vertices) {
  const int nv = mesh.n_vertices();
  std::vector<double> dist(nv, std::numeric_limits<double>::infinity());
  std::vector<int> prev(nv, -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  dist[source] = 0;
  queue.push({0.0, source});
  while (!queue.empty()) {
    const auto [d, u] = queue.top();
    queue.pop();
    if (d > dist[u]) continue;
    if (is_target(u)) {
      vertices->clear();
      for (int v = u; v >= 0; v = prev[v]) vertices->push_back(v);
      std::reverse(vertices->begin(), vertices->end());
      return true;
    }
    for (const int* w = mesh.neighbors_begin(u); w != mesh.neighbors_end(u); ++w) {
      const double nd = d + (mesh.position(*w) - mesh.position(u)).norm();
      if (nd < dist[*w]) {
        dist[*w] = nd;
        prev[*w] = u;
        queue.push({nd, *w});
      }
    }
  }
  return false;
}

// Vertex sequence as a SurfacePath keeping "path[i].face contains path[i+1]".
SurfacePath vertex_path(const Mesh& mesh, const std::vector<int>& vertices) {
  SurfacePath out;
  out.reserve(vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i)
    out.push_back(i + 1 < vertices.size() ? vertex_point_towards(mesh, vertices[i], vertices[i + 1])
                                          : vertex_point(mesh, vertices[i]));
  return out;
}

// The face that holds the segment p-q, with both expressed in it.
void segment_face(const Mesh& mesh, const SurfacePoint& p, const SurfacePoint& q, int* f, Vec3* bp, Vec3* bq) {
  if (in_face(mesh, q, p.face, bq)) {
    *f = p.face;
    *bp = p.bary;
    return;
  }
  if (in_face(mesh, p, q.face, bp)) {
    *f = q.face;
    *bq = q.bary;
    return;
  }
  if (common_face(mesh, p, q, f, bp, bq)) return;
  throw Error("resample_path: two consecutive path points share no face; build paths with plane_section_path or "
              "shortest_edge_path");
}

}  // namespace

bool on_boundary(const Mesh& mesh, const SurfacePoint& p) {
  int c[3];
  const int n = support(mesh, p, c);
  if (n == 1) return mesh.is_boundary_vertex(mesh.face_vertex(p.face, c[0]));
  if (n == 2) return mesh.face_neighbor(p.face, 3 - c[0] - c[1]) < 0;
  return false;
}

bool plane_section_path(const Mesh& mesh, const SurfacePoint& a, const SurfacePoint& b, SurfacePath* out) {
  if (!a.valid() || !b.valid()) return false;
  // a and b on one face: the straight segment is the section.
  std::vector<int> faces;
  faces_containing(mesh, a, &faces);
  for (int g : faces) {
    SurfacePoint pa, pb;
    if (in_face(mesh, a, g, &pa.bary) && in_face(mesh, b, g, &pb.bary)) {
      pa.face = pb.face = g;
      *out = {pa, pb};
      return true;
    }
  }
  const Vec3 xa = position(mesh, a), xb = position(mesh, b);
  const Vec3 d = xb - xa;
  const Vec3 n_avg = normal(mesh, a) + normal(mesh, b);
  const double dn = d.norm(), nn = n_avg.norm();
  if (!(dn > 0) || nn < 1e-6) return false;  // same place, or opposite normals: no defined plane
  Vec3 m = d.cross(n_avg);
  if (m.norm() < 1e-9 * dn * nn) return false;  // b straight along the normal from a
  SectionPlane plane{xa, m.normalized()};

  // Along the section at a (tangent = plane normal x surface normal), towards b.
  Vec3 forward = plane.m.cross(normal(mesh, a));
  if (forward.norm() < 1e-12) forward = d;
  if (forward.dot(d) < 0) forward = -forward;
  forward.normalize();
  const double max_length = 3.0 * dn + 6.0 * mesh.average_edge_length();
  return march(mesh, a, b, plane, forward, max_length, out) || march(mesh, a, b, plane, -forward, max_length, out);
}

bool shortest_edge_path(const Mesh& mesh, int va, int vb, SurfacePath* out) {
  if (va < 0 || vb < 0 || va >= mesh.n_vertices() || vb >= mesh.n_vertices()) return false;
  if (mesh.component(va) != mesh.component(vb)) return false;
  std::vector<int> vertices;
  if (!dijkstra(mesh, va, [vb](int v) { return v == vb; }, &vertices)) return false;
  *out = vertex_path(mesh, vertices);
  return true;
}

namespace {

// --- picks that cannot enclose anything ---------------------------------------------
// A closed contour's picks, seen along their average normal, must go round once: a pick
// polygon that crosses itself (figure-eight order) or encloses almost no area (collinear
// picks) converges to nothing useful, so it is refused with the order that would work.

/// Pick k's 2D position in the plane across the picks' average normal.
std::vector<Eigen::Vector2d> project_picks(const Mesh& mesh, const std::vector<int>& picks) {
  Vec3 normal = Vec3::Zero(), centre = Vec3::Zero();
  for (int v : picks) {
    normal += mesh.vertex_normal(v);
    centre += mesh.position(v);
  }
  centre /= static_cast<double>(picks.size());
  if (normal.norm() < 1e-9) normal = Vec3::UnitZ();  // normals cancel: any projection (the tests below then decide)
  normal.normalize();
  const Vec3 u = normal.unitOrthogonal(), w = normal.cross(u);
  std::vector<Eigen::Vector2d> out;
  out.reserve(picks.size());
  for (int v : picks) {
    const Vec3 d = mesh.position(v) - centre;
    out.emplace_back(d.dot(u), d.dot(w));
  }
  return out;
}

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Whether segments pq and rs cross at a point inside both (touching ends do not count).
bool segments_cross(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r,
                    const Eigen::Vector2d& s, double tolerance) {
  const double d1 = cross2(q - p, r - p), d2 = cross2(q - p, s - p);
  const double d3 = cross2(s - r, p - r), d4 = cross2(s - r, q - r);
  return ((d1 > tolerance && d2 < -tolerance) || (d1 < -tolerance && d2 > tolerance)) &&
         ((d3 > tolerance && d4 < -tolerance) || (d3 < -tolerance && d4 > tolerance));
}

/// "1, 2, 4, 3": the picks' 1-based positions sorted by angle around their centre.
std::string order_by_angle(const std::vector<Eigen::Vector2d>& points) {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const auto& p : points) centre += p;
  centre /= static_cast<double>(points.size());
  std::vector<std::size_t> order(points.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  const auto angle = [&](std::size_t i) { return std::atan2(points[i].y() - centre.y(), points[i].x() - centre.x()); };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return angle(a) < angle(b); });
  // Start at the first pick, keep the user's direction if the sorted ring allows it.
  std::rotate(order.begin(), std::find(order.begin(), order.end(), std::size_t(0)), order.end());
  if (order.size() > 2 && order[1] > order.back()) std::reverse(order.begin() + 1, order.end());
  std::string text;
  for (std::size_t i = 0; i < order.size(); ++i) text += (i ? ", " : "") + std::to_string(order[i] + 1);
  return text;
}

}  // namespace

void check_pick_polygon(const Mesh& mesh, const std::vector<int>& picks) {
  const std::size_t n = picks.size();
  if (n < 3) return;
  const std::vector<Eigen::Vector2d> p = project_picks(mesh, picks);
  double perimeter = 0, twice_area = 0, extent = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& a = p[i];
    const auto& b = p[(i + 1) % n];
    perimeter += (b - a).norm();
    twice_area += cross2(a, b);
    extent = std::max(extent, a.norm());
  }
  const double tolerance = 1e-12 * extent * extent;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      if (segments_cross(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n], tolerance))
        throw Error("the picks' order crosses itself (the line from pick " + std::to_string(i + 1) + " to " +
                    std::to_string((i + 1) % n + 1) + " crosses the one from pick " + std::to_string(j + 1) + " to " +
                    std::to_string((j + 1) % n + 1) + "), so the contour cannot go round the relief; pick in order "
                    "around it, e.g. as " + order_by_angle(p));
    }
  // Isoperimetric ratio 4 pi A / P^2: 1 for a circle, 0.6 for a square, 0.03 for a 1:100 rectangle, ~0
  // for points on a line (0.02: a triangle whose height is 1.3% of its base).
  const double roundness = perimeter > 0 ? 4 * M_PI * 0.5 * std::abs(twice_area) / (perimeter * perimeter) : 0;
  if (roundness < 0.02)
    throw Error("the picks enclose almost no area (they lie nearly on one line, seen across the surface), so the "
                "contour cannot go round the relief; pick points all around the relief");
}


InitialContour initial_contour(const Mesh& mesh, const std::vector<int>& picks, bool closed) {
  const std::size_t n = picks.size();
  if (closed && n < 3) throw Error("a closed contour needs at least 3 picked points around the relief");
  if (!closed && n < 2) throw Error("an open contour needs at least 2 picked points");
  for (int v : picks)
    if (v < 0 || v >= mesh.n_vertices())
      throw Error("picked vertex " + std::to_string(v) + " is not a mesh vertex; pick points on the mesh");
  for (std::size_t i = 0; i < n; ++i) {
    if (mesh.component(picks[i]) != mesh.component(picks[0]))
      throw Error("the picked points lie on different connected parts of the mesh; pick them all on one surface");
    if ((i + 1 < n || closed) && picks[i] == picks[(i + 1) % n])
      throw Error("the same point is picked twice in a row; remove the repeated pick");
  }
  if (closed) check_pick_polygon(mesh, picks);

  InitialContour result;
  const std::size_t legs = closed ? n : n - 1;
  for (std::size_t i = 0; i < legs; ++i) {
    const int va = picks[i], vb = picks[(i + 1) % n];
    SurfacePath leg;
    if (!plane_section_path(mesh, vertex_point(mesh, va), vertex_point(mesh, vb), &leg)) {
      if (!shortest_edge_path(mesh, va, vb, &leg))
        throw Error("cannot join the picked points across the mesh; pick them on one connected surface");
      ++result.fallback_legs;
    }
    result.pick_index.push_back(result.path.size());
    // Drop the leg's end: the next leg starts there (expressed in its own first face).
    result.path.insert(result.path.end(), leg.begin(), leg.end() - 1);
    if (!closed && i + 1 == legs) {
      result.pick_index.push_back(result.path.size());
      result.path.push_back(leg.back());
    }
  }
  return result;
}

double path_length(const Mesh& mesh, const SurfacePath& path, bool closed) {
  double length = 0;
  const std::size_t m = path.size();
  if (m < 2) return 0;
  for (std::size_t i = 0; i + 1 < m; ++i) length += (position(mesh, path[i + 1]) - position(mesh, path[i])).norm();
  if (closed) length += (position(mesh, path[0]) - position(mesh, path[m - 1])).norm();
  return length;
}

std::vector<SurfacePoint> resample_path(const Mesh& mesh, const SurfacePath& path, double spacing, bool closed) {
  if (!(spacing > 0)) throw Error("resample_path: the spacing must be positive");
  const std::size_t m = path.size();
  if (m == 0) return {};
  if (m == 1) return {path[0]};
  const std::size_t segments = closed ? m : m - 1;
  std::vector<double> cumulative(segments + 1, 0.0);
  for (std::size_t i = 0; i < segments; ++i)
    cumulative[i + 1] =
        cumulative[i] + (position(mesh, path[(i + 1) % m]) - position(mesh, path[i])).norm();
  const double total = cumulative.back();
  if (!(total > 0)) return {path[0]};

  const long rounded = std::lround(total / spacing);
  const long steps = closed ? std::max(3L, rounded) : std::max(1L, rounded);
  const long count = closed ? steps : steps + 1;
  std::vector<SurfacePoint> out;
  out.reserve(count);
  std::size_t seg = 0;
  for (long k = 0; k < count; ++k) {
    if (!closed && k == steps) {  // keep the far end exactly
      out.push_back(path[m - 1]);
      break;
    }
    const double target = total * static_cast<double>(k) / static_cast<double>(steps);
    while (seg + 1 < segments && cumulative[seg + 1] <= target) ++seg;
    const double len = cumulative[seg + 1] - cumulative[seg];
    double t = len > 0 ? (target - cumulative[seg]) / len : 0.0;
    t = std::min(1.0, std::max(0.0, t));
    int f;
    Vec3 bp, bq;
    segment_face(mesh, path[seg], path[(seg + 1) % m], &f, &bp, &bq);
    SurfacePoint p;
    p.face = f;
    p.bary = (1.0 - t) * bp + t * bq;
    out.push_back(p);
  }
  return out;
}

bool extend_to_boundary(const Mesh& mesh, SurfacePath* path) {
  if (path->empty()) return false;
  // The extension from end point p: its nearest corner, then the shortest edge path to the boundary.
  auto extension = [&](const SurfacePoint& p, std::vector<int>* vertices) {
    vertices->clear();
    if (on_boundary(mesh, p)) return true;
    const int v0 = nearest_corner(mesh, p);
    return dijkstra(mesh, v0, [&mesh](int v) { return mesh.is_boundary_vertex(v); }, vertices);
  };
  auto at_vertex = [&mesh](const SurfacePoint& p) {
    int c[3];
    return support(mesh, p, c) == 1;
  };
  std::vector<int> front, back;
  if (!extension(path->front(), &front) || !extension(path->back(), &back)) return false;

  SurfacePath result;
  if (!front.empty()) {
    // Boundary first: reversed vertex sequence, its last vertex (v0) in the face of the path's start.
    std::reverse(front.begin(), front.end());
    SurfacePath ext = vertex_path(mesh, front);
    if (at_vertex(path->front())) {
      ext.pop_back();  // the path starts at v0 already; v1 is expressed towards it
    } else {
      SurfacePoint& v0 = ext.back();
      v0.face = path->front().face;
      v0.bary = Vec3::Zero();
      v0.bary[corner_of(mesh, v0.face, front.back())] = 1.0;
    }
    result.insert(result.end(), ext.begin(), ext.end());
  }
  result.insert(result.end(), path->begin(), path->end());
  if (!back.empty()) {
    // path.back()'s face contains v0 (its nearest corner), so the join is a segment on that face;
    // if the path ends at v0 itself, v0 replaces it, expressed towards v1.
    if (at_vertex(path->back())) result.pop_back();
    SurfacePath ext = vertex_path(mesh, back);
    result.insert(result.end(), ext.begin(), ext.end());
  }
  *path = std::move(result);
  return true;
}

}  // namespace relief_snake

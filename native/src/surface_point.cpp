#include "relief_snake/surface_point.hpp"

#include <algorithm>
#include <unordered_set>
#include <cmath>
#include <limits>

namespace relief_snake {

namespace {

// Barycentric velocity of a unit 3D direction d inside face f: the db with
// sum(db) = 0 and sum(db_k * P_k) = projection of d onto the face plane.
Vec3 barycentric_velocity(const Mesh& mesh, int f, const Vec3& d) {
  const Vec3& a = mesh.position(mesh.face_vertex(f, 0));
  const Vec3 e1 = mesh.position(mesh.face_vertex(f, 1)) - a;
  const Vec3 e2 = mesh.position(mesh.face_vertex(f, 2)) - a;
  const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2);
  const double r1 = d.dot(e1), r2 = d.dot(e2);
  const double det = g11 * g22 - g12 * g12;
  if (!(det > 0)) return Vec3::Zero();
  const double s = (g22 * r1 - g12 * r2) / det;
  const double t = (g11 * r2 - g12 * r1) / det;
  return Vec3(-s - t, s, t);
}

// Unit projection of d onto the plane of face f (zero if d is normal to it).
Vec3 project_to_face(const Mesh& mesh, int f, const Vec3& d) {
  const Vec3& n = mesh.face_normal(f);
  Vec3 p = d - d.dot(n) * n;
  const double len = p.norm();
  return len > 0 ? Vec3(p / len) : Vec3::Zero();
}

// Unfolds direction d from face f into face g about their shared edge (a, b):
// the component along the edge is kept, the in-plane perpendicular is rotated.
Vec3 unfold(const Mesh& mesh, int f, int g, const Vec3& edge_a, const Vec3& edge_b, const Vec3& d) {
  Vec3 e = edge_b - edge_a;
  const double len = e.norm();
  if (!(len > 0)) return project_to_face(mesh, g, d);
  e /= len;
  const Vec3 mf = mesh.face_normal(f).cross(e);
  const Vec3 mg = mesh.face_normal(g).cross(e);
  Vec3 out = d.dot(e) * e + d.dot(mf) * mg;
  return project_to_face(mesh, g, out);
}

}  // namespace

SurfacePoint vertex_point(const Mesh& mesh, int v) {
  SurfacePoint p;
  const int* f = mesh.faces_begin(v);
  if (f == mesh.faces_end(v)) return p;  // isolated vertex: invalid point
  p.face = *f;
  for (int k = 0; k < 3; ++k) p.bary[k] = mesh.face_vertex(p.face, k) == v ? 1.0 : 0.0;
  return p;
}

std::vector<SurfacePoint> vertex_points(const Mesh& mesh, const std::vector<int>& path) {
  std::vector<SurfacePoint> points;
  points.reserve(path.size());
  for (const int v : path) points.push_back(vertex_point(mesh, v));
  return points;
}

Vec3 position(const Mesh& mesh, const SurfacePoint& p) {
  return p.bary[0] * mesh.position(mesh.face_vertex(p.face, 0)) +
         p.bary[1] * mesh.position(mesh.face_vertex(p.face, 1)) +
         p.bary[2] * mesh.position(mesh.face_vertex(p.face, 2));
}

Vec3 normal(const Mesh& mesh, const SurfacePoint& p) {
  Vec3 n = p.bary[0] * mesh.vertex_normal(mesh.face_vertex(p.face, 0)) +
           p.bary[1] * mesh.vertex_normal(mesh.face_vertex(p.face, 1)) +
           p.bary[2] * mesh.vertex_normal(mesh.face_vertex(p.face, 2));
  const double len = n.norm();
  return len > 1e-12 ? Vec3(n / len) : mesh.face_normal(p.face);
}

bool in_face(const Mesh& mesh, const SurfacePoint& p, int g, Vec3* bary_in_g, double tolerance) {
  if (p.face == g) {
    *bary_in_g = p.bary;
    return true;
  }
  Vec3 out = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    const double w = p.bary[k];
    if (w <= tolerance) continue;
    const int v = mesh.face_vertex(p.face, k);
    int j = 0;
    while (j < 3 && mesh.face_vertex(g, j) != v) ++j;
    if (j == 3) return false;  // a corner with weight is not on g
    out[j] += w;
  }
  const double sum = out.sum();
  if (!(sum > 0)) return false;
  *bary_in_g = out / sum;
  return true;
}

bool common_face(const Mesh& mesh, const SurfacePoint& a, const SurfacePoint& b, int* face, Vec3* bary_a,
                 Vec3* bary_b) {
  // Candidate faces: a's own face, and the faces around a's corners that carry weight.
  auto try_face = [&](int g) {
    if (g < 0) return false;
    if (in_face(mesh, a, g, bary_a) && in_face(mesh, b, g, bary_b)) {
      *face = g;
      return true;
    }
    return false;
  };
  if (try_face(a.face) || try_face(b.face)) return true;
  for (int k = 0; k < 3; ++k) {
    if (a.bary[k] <= 1e-9) continue;
    const int v = mesh.face_vertex(a.face, k);
    for (const int* g = mesh.faces_begin(v); g != mesh.faces_end(v); ++g)
      if (try_face(*g)) return true;
  }
  return false;
}

int nearest_corner(const Mesh& mesh, const SurfacePoint& p) {
  int k = 0;
  if (p.bary[1] > p.bary[k]) k = 1;
  if (p.bary[2] > p.bary[k]) k = 2;
  return mesh.face_vertex(p.face, k);
}

WalkResult walk(const Mesh& mesh, const SurfacePoint& start, const Vec3& direction, const WalkOptions& options) {
  WalkResult result;
  result.end = start;
  if (!start.valid()) return result;
  const double total = options.distance;
  const double* sample_distances = options.samples;
  const std::size_t n_samples = sample_distances ? options.n_samples : 0;
  const bool record = n_samples > 0 || options.record_crossings;
  std::vector<WalkPoint>* out = record ? &result.points : nullptr;
  if (out) out->reserve(n_samples + 8);
  // No crossing is recorded unless asked for (an empty range otherwise).
  const double crossings_from = options.record_crossings ? options.crossings_from : 0;
  const double crossings_to = options.record_crossings ? options.crossings_to : -1;

  int f = start.face;
  Vec3 b = start.bary;
  Vec3 d = project_to_face(mesh, f, direction);
  result.direction = d;
  if (d.isZero() || !(total > 0)) {
    if (out)
      for (std::size_t k = 0; k < n_samples; ++k)
        if (sample_distances[k] <= 0) out->push_back({start, 0.0, static_cast<int>(k)});
    return result;
  }

  std::size_t next_sample = 0;
  double travelled = 0;
  int previous_face = -1;
  // Each face crossing consumes at least a tiny distance or changes face; the cap
  // guards against pathological ping-pong on degenerate geometry.
  for (int step = 0; step < options.max_face_steps; ++step) {
    const Vec3 db = barycentric_velocity(mesh, f, d);
    // Distance to the first corner weight reaching zero.
    double t_exit = std::numeric_limits<double>::infinity();
    int exit_k = -1;
    for (int k = 0; k < 3; ++k) {
      if (db[k] < -1e-15) {
        const double t = std::max(0.0, b[k]) / -db[k];
        if (t < t_exit) {
          t_exit = t;
          exit_k = k;
        }
      }
    }
    // Emit samples that fall inside this face.
    while (next_sample < n_samples && sample_distances[next_sample] - travelled <= t_exit) {
      const double t = std::max(0.0, sample_distances[next_sample] - travelled);
      SurfacePoint s{f, b + t * db};
      s.bary = s.bary.cwiseMax(0.0);
      s.bary /= s.bary.sum();
      out->push_back({s, sample_distances[next_sample], static_cast<int>(next_sample)});
      ++next_sample;
    }
    if (total - travelled <= t_exit) {
      const double t = total - travelled;
      result.end.face = f;
      result.end.bary = (b + t * db).cwiseMax(0.0);
      result.end.bary /= result.end.bary.sum();
      result.travelled = total;
      result.direction = d;
      return result;
    }
    if (exit_k < 0) break;  // direction degenerate in this face

    // Move to the exit edge (opposite corner exit_k).
    Vec3 e = b + t_exit * db;
    e[exit_k] = 0;
    e = e.cwiseMax(0.0);
    double s = e.sum();
    if (!(s > 0)) break;
    e /= s;
    travelled += t_exit;
    if (out && travelled >= crossings_from && travelled <= crossings_to) out->push_back({SurfacePoint{f, e}, travelled, -1});

    const int g = mesh.face_neighbor(f, exit_k);
    const int ka = (exit_k + 1) % 3, kb = (exit_k + 2) % 3;
    if (g < 0) {
      result.end = SurfacePoint{f, e};
      result.travelled = travelled;
      result.hit_boundary = true;
      result.boundary_face = f;
      result.boundary_edge = exit_k;
      result.direction = d;
      return result;
    }
    // Keep the crossing point strictly inside the edge, so a path through a
    // vertex continues into a definite face instead of stalling on the corner.
    const double nudge = 1e-9;
    if (e[ka] < nudge) {
      e[ka] = nudge;
      e[kb] = 1 - nudge;
    } else if (e[kb] < nudge) {
      e[kb] = nudge;
      e[ka] = 1 - nudge;
    }
    const int va = mesh.face_vertex(f, ka), vb = mesh.face_vertex(f, kb);
    Vec3 bg = Vec3::Zero();
    for (int j = 0; j < 3; ++j) {
      const int v = mesh.face_vertex(g, j);
      if (v == va) bg[j] = e[ka];
      else if (v == vb) bg[j] = e[kb];
    }
    d = unfold(mesh, f, g, mesh.position(va), mesh.position(vb), d);
    if (d.isZero()) break;
    // A zero-length step back into the face we came from means the direction runs
    // along the shared edge; step a hair into the new face to break the tie.
    if (g == previous_face && t_exit <= 0) {
      const Vec3 c(1.0 / 3, 1.0 / 3, 1.0 / 3);
      bg = (1 - 1e-9) * bg + 1e-9 * c;
    }
    previous_face = f;
    f = g;
    b = bg;
  }
  result.end = SurfacePoint{f, b.cwiseMax(0.0) / b.cwiseMax(0.0).sum()};
  result.travelled = travelled;
  result.direction = d;
  return result;
}

std::vector<SurfacePoint> walk_points(const WalkResult& walk) {
  std::vector<SurfacePoint> out;
  out.reserve(walk.points.size());
  for (const WalkPoint& p : walk.points) out.push_back(p.point);
  return out;
}

namespace {

// Closest point to p on triangle (a, b, c), as barycentric weights (Ericson,
// Real-Time Collision Detection, 5.1.5: Voronoi regions of the corners and edges).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return Vec3(1, 0, 0);
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return Vec3(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double t = d1 / (d1 - d3);
    return Vec3(1 - t, t, 0);
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return Vec3(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double t = d2 / (d2 - d6);
    return Vec3(1 - t, 0, t);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return Vec3(0, 1 - t, t);
  }
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0)) return Vec3(1, 0, 0);  // degenerate triangle: its first corner
  const double v = vb / denom, w = vc / denom;
  return Vec3(1 - v - w, v, w);
}

}  // namespace

SurfacePoint closest_point_near(const Mesh& mesh, const SurfacePoint& start, const Vec3& target, double radius,
                                std::vector<int>* scratch) {
  if (!start.valid()) return start;
  std::vector<int> local;
  std::vector<int>& visited = scratch ? *scratch : local;
  visited.clear();
  SurfacePoint best = start;
  double best_d2 = (position(mesh, start) - target).squaredNorm();
  const double r2 = radius * radius;
  // Breadth-first over faces sharing a corner, through faces that come within
  // `radius` of the target; the visited list doubles as the queue. It is usually
  // small, and searched linearly; past kLinear faces (a radius of many edges: a
  // coarse snake on a fine mesh) membership goes through a hash set instead, so the
  // search stays linear in the faces it visits.
  constexpr std::size_t kLinear = 48;
  std::unordered_set<int> member;
  auto seen = [&](int g) {
    if (visited.size() <= kLinear) return std::find(visited.begin(), visited.end(), g) != visited.end();
    if (member.empty()) member.insert(visited.begin(), visited.end());
    return member.count(g) != 0;
  };
  auto add = [&](int g) {
    visited.push_back(g);
    if (!member.empty()) member.insert(g);
  };
  visited.push_back(start.face);
  for (std::size_t k = 0; k < visited.size(); ++k) {
    const int f = visited[k];
    const Vec3 &a = mesh.position(mesh.face_vertex(f, 0)), &b = mesh.position(mesh.face_vertex(f, 1)),
               &c = mesh.position(mesh.face_vertex(f, 2));
    const Vec3 w = closest_on_triangle(target, a, b, c);
    const double d2 = (w[0] * a + w[1] * b + w[2] * c - target).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = SurfacePoint{f, w};
    }
    if (d2 > r2 && k > 0) continue;  // too far: do not grow the search through it
    for (int j = 0; j < 3; ++j) {
      const int v = mesh.face_vertex(f, j);
      for (const int* g = mesh.faces_begin(v); g != mesh.faces_end(v); ++g)
        if (!seen(*g)) add(*g);
    }
    if (visited.size() > 4096) break;  // a guard for absurd radii; the search is meant to be local
  }
  return best;
}

}  // namespace relief_snake

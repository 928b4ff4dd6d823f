#include "relief_snake/snake.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <Eigen/Geometry>

namespace relief_snake {

namespace {

constexpr double kDegrees = 180.0 / M_PI;

// Boundary edge of face g leaving (forward) or entering (backward) vertex v, in
// the face's counter-clockwise orientation; returns the opposite corner or -1.
int boundary_edge_at(const Mesh& mesh, int g, int v, bool leaving) {
  for (int j = 0; j < 3; ++j) {
    if (mesh.face_neighbor(g, j) >= 0) continue;
    const int from = mesh.face_vertex(g, (j + 1) % 3), to = mesh.face_vertex(g, (j + 2) % 3);
    if ((leaving && from == v) || (!leaving && to == v)) return j;
  }
  return -1;
}

}  // namespace

std::vector<SurfacePoint> surface_between(const Mesh& mesh, const SurfacePoint& a, const SurfacePoint& b,
                                          const std::vector<double>& fractions, bool nearest) {
  const Vec3 pa = position(mesh, a), pb = position(mesh, b);
  const double d = (pb - pa).norm();
  std::vector<double> distances;
  distances.reserve(fractions.size());
  for (double t : fractions) distances.push_back(t * d);
  std::vector<SurfacePoint> out;
  if (d <= 0) return std::vector<SurfacePoint>(fractions.size(), a);
  walk_sampled(mesh, a, pb - pa, distances, &out);
  // A boundary can cut the walk short: fill the rest with the last point reached.
  while (out.size() < fractions.size()) out.push_back(out.empty() ? a : out.back());
  if (nearest) {
    // The walk's end can drift off the chord where the surface folds (a steep,
    // sparsely sampled step wall): take the surface point nearest the chord point,
    // searched from where the walk got to.
    std::vector<int> scratch;
    for (std::size_t k = 0; k < out.size(); ++k) {
      const Vec3 target = pa + fractions[k] * (pb - pa);
      const double r = (position(mesh, out[k]) - target).norm();
      out[k] = closest_point_near(mesh, out[k], target, r * (1 + 1e-9) + 1e-12 * d, &scratch);
    }
  }
  return out;
}

SurfacePoint surface_midpoint(const Mesh& mesh, const SurfacePoint& a, const SurfacePoint& b, bool nearest) {
  return surface_between(mesh, a, b, {0.5}, nearest).front();
}

bool boundary_edge_of(const Mesh& mesh, const SurfacePoint& p, int* face, int* edge) {
  const double tol = 1e-7;
  for (int k = 0; k < 3; ++k) {
    if (p.bary[k] <= tol && mesh.face_neighbor(p.face, k) < 0) {
      *face = p.face;
      *edge = k;
      return true;
    }
  }
  // At a corner: look at the faces around it.
  for (int k = 0; k < 3; ++k) {
    if (p.bary[k] < 1 - tol) continue;
    const int v = mesh.face_vertex(p.face, k);
    for (const int* g = mesh.faces_begin(v); g != mesh.faces_end(v); ++g) {
      const int j = boundary_edge_at(mesh, *g, v, true);
      if (j >= 0) {
        *face = *g;
        *edge = j;
        return true;
      }
    }
  }
  return false;
}

SurfacePoint slide_along_boundary(const Mesh& mesh, const SurfacePoint& p, double distance) {
  int f, k;
  if (!boundary_edge_of(mesh, p, &f, &k)) return p;
  Vec3 b = Vec3::Zero();
  if (!in_face(mesh, p, f, &b, 1e-7)) return p;
  const bool forward = distance > 0;
  double remaining = std::abs(distance);
  for (int guard = 0; guard < 100000; ++guard) {
    const int ka = (k + 1) % 3, kb = (k + 2) % 3;
    const int va = mesh.face_vertex(f, ka), vb = mesh.face_vertex(f, kb);
    const double len = (mesh.position(vb) - mesh.position(va)).norm();
    // Fraction of the edge still ahead of the point in the walking direction.
    const double ahead = forward ? b[ka] / std::max(1e-300, b[ka] + b[kb]) : b[kb] / std::max(1e-300, b[ka] + b[kb]);
    if (remaining <= ahead * len || len <= 0) {
      const double t = len > 0 ? remaining / len : 0;
      double wa = b[ka] / (b[ka] + b[kb]), wb = 1 - wa;
      if (forward) {
        wa -= t;
        wb += t;
      } else {
        wa += t;
        wb -= t;
      }
      SurfacePoint out;
      out.face = f;
      out.bary = Vec3::Zero();
      out.bary[ka] = std::clamp(wa, 0.0, 1.0);
      out.bary[kb] = 1 - out.bary[ka];
      return out;
    }
    remaining -= ahead * len;
    const int v = forward ? vb : va;
    int next_face = -1, next_edge = -1;
    for (const int* g = mesh.faces_begin(v); g != mesh.faces_end(v); ++g) {
      if (*g == f) continue;
      const int j = boundary_edge_at(mesh, *g, v, forward);
      if (j >= 0) {
        next_face = *g;
        next_edge = j;
        break;
      }
    }
    if (next_face < 0) {
      // A single boundary face can hold two boundary edges meeting at v.
      const int j = boundary_edge_at(mesh, f, v, forward);
      if (j >= 0 && j != k) next_face = f, next_edge = j;
    }
    if (next_face < 0) return vertex_point(mesh, v);  // boundary ends (non-manifold): stop here
    f = next_face;
    k = next_edge;
    b = Vec3::Zero();
    for (int j = 0; j < 3; ++j)
      if (mesh.face_vertex(f, j) == v) b[j] = 1;
  }
  return p;
}

Snake::Snake(const Mesh& mesh, const std::vector<SurfacePoint>& points, bool closed, bool inside_left)
    : mesh_(mesh), closed_(closed), inside_left_(inside_left) {
  snaxels_.reserve(points.size());
  for (const SurfacePoint& p : points) snaxels_.push_back(make(p));
}

Snaxel Snake::make(const SurfacePoint& p) const {
  Snaxel s;
  s.point = p;
  s.position = relief_snake::position(mesh_, p);
  s.anchor = s.position;
  return s;
}

void Snake::move(int i, const SurfacePoint& p) {
  snaxels_[i].point = p;
  snaxels_[i].position = relief_snake::position(mesh_, p);
}

Vec3 Snake::inward(int i) const {
  const Vec3& x = snaxels_[i].position;
  const Vec3 n = normal(mesh_, snaxels_[i].point);
  const int ip = prev(i), in = next(i);
  Vec3 t;
  if (ip < 0) {
    t = snaxels_[in].position - x;
  } else if (in < 0) {
    t = x - snaxels_[ip].position;
  } else {
    // Bisector of the two segments is perpendicular to u_next - u_prev.
    Vec3 up = snaxels_[ip].position - x, un = snaxels_[in].position - x;
    const double lp = up.norm(), ln = un.norm();
    if (lp > 0) up /= lp;
    if (ln > 0) un /= ln;
    t = un - up;
    if (t.squaredNorm() < 1e-20) t = snaxels_[in].position - snaxels_[ip].position;
  }
  t -= t.dot(n) * n;
  const double len = t.norm();
  if (!(len > 0)) return Vec3::Zero();
  t /= len;
  Vec3 m = n.cross(t);
  return inside_left_ ? m : Vec3(-m);
}

double Snake::local_length(int i) const {
  const int ip = prev(i), in = next(i);
  const Vec3& x = snaxels_[i].position;
  if (ip < 0) return (snaxels_[in].position - x).norm();
  if (in < 0) return (x - snaxels_[ip].position).norm();
  return 0.5 * ((x - snaxels_[ip].position).norm() + (snaxels_[in].position - x).norm());
}

double Snake::turn_degrees(int i) const {
  const int ip = prev(i), in = next(i);
  if (ip < 0 || in < 0) return 0;
  const Vec3 a = snaxels_[i].position - snaxels_[ip].position;
  const Vec3 b = snaxels_[in].position - snaxels_[i].position;
  const double na = a.norm(), nb = b.norm();
  if (!(na > 0) || !(nb > 0)) return 0;
  return std::acos(std::clamp(a.dot(b) / (na * nb), -1.0, 1.0)) * kDegrees;
}

double Snake::length() const {
  double total = 0;
  for (int i = 0; i + 1 < size(); ++i) total += (snaxels_[i + 1].position - snaxels_[i].position).norm();
  if (closed_ && size() > 1) total += (snaxels_.front().position - snaxels_.back().position).norm();
  return total;
}

int Snake::remove_sharp_turns(double max_degrees) {
  int removed = 0;
  for (int i = 0; i < size() && size() > 3;) {
    if (!is_end(i) && turn_degrees(i) > max_degrees) {
      snaxels_.erase(snaxels_.begin() + i);
      ++removed;
      // The neighbours' turning angles changed: re-check from the previous one.
      if (i > 0) --i;
      const int ip = prev(i);
      if (ip >= 0) snaxels_[ip].moved = true;
      if (i < size()) snaxels_[i].moved = true;
    } else {
      ++i;
    }
  }
  return removed;
}

int Snake::append_between(int i, int j, int pieces, std::vector<Snaxel>* out) const {
  if (pieces < 2) return 0;
  std::vector<double> fractions;
  for (int k = 1; k < pieces; ++k) fractions.push_back(static_cast<double>(k) / pieces);
  for (const SurfacePoint& p : surface_between(mesh_, snaxels_[i].point, snaxels_[j].point, fractions, nearest_resampling_))
    out->push_back(make(p));  // new snaxels start as moved
  return pieces - 1;
}

int Snake::resample(double l) {
  const double lmin = 0.5 * l, lmax = 1.5 * l;
  int changes = 0;
  std::vector<Snaxel> out;
  out.reserve(snaxels_.size() + 16);
  // Split pass: insert midpoints into long segments (as many as needed).
  const int n = size();
  for (int i = 0; i < n; ++i) {
    out.push_back(snaxels_[i]);
    const int j = next(i);
    if (j < 0) continue;
    const double d = (snaxels_[j].position - snaxels_[i].position).norm();
    if (d > lmax) changes += append_between(i, j, static_cast<int>(std::ceil(d / l)), &out);
  }
  snaxels_.swap(out);
  // Merge pass: replace a too-short pair by its midpoint (open ends stay put).
  for (int i = 0; i < size() && size() > 3;) {
    const int j = next(i);
    if (j < 0) break;
    const double d = (snaxels_[j].position - snaxels_[i].position).norm();
    if (d >= lmin) {
      ++i;
      continue;
    }
    if (is_end(i)) {
      snaxels_.erase(snaxels_.begin() + j);
    } else if (is_end(j)) {
      snaxels_.erase(snaxels_.begin() + i);
    } else {
      Snaxel merged = make(surface_midpoint(mesh_, snaxels_[i].point, snaxels_[j].point, nearest_resampling_));
      merged.moved = true;
      snaxels_[i] = merged;
      snaxels_.erase(snaxels_.begin() + j);
      if (j < i) --i;  // wrapped around a closed snake
    }
    ++changes;
  }
  return changes;
}

namespace {

// Do segments p0p1 and q0q1 cross, seen along the normal n?
bool segments_cross(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, const Vec3& n) {
  Vec3 e1 = (p1 - p0);
  e1 -= e1.dot(n) * n;
  if (e1.squaredNorm() <= 0) return false;
  e1.normalize();
  const Vec3 e2 = n.cross(e1);
  auto flat = [&](const Vec3& x) { return Eigen::Vector2d((x - p0).dot(e1), (x - p0).dot(e2)); };
  const Eigen::Vector2d a = flat(p0), b = flat(p1), c = flat(q0), d = flat(q1);
  auto orient = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v, const Eigen::Vector2d& w) {
    return (v.x() - u.x()) * (w.y() - u.y()) - (v.y() - u.y()) * (w.x() - u.x());
  };
  const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  return ((o1 > 0) != (o2 > 0)) && ((o3 > 0) != (o4 > 0)) && o1 != 0 && o2 != 0 && o3 != 0 && o4 != 0;
}

}  // namespace

int Snake::remove_loops() {
  int removed = 0;
  std::vector<int> order;
  std::vector<Eigen::AlignedBox3d> boxes;
  std::vector<char> dirty;
  for (int pass = 0; pass < 64; ++pass) {
    const int n = size();
    const int segments = closed_ ? n : n - 1;
    if (segments < 4) break;
    // Sweep and prune: segment boxes, grown by half the longest segment so
    // that crossings seen along a tilted normal are not missed, sorted along
    // the snake's longest axis; only boxes overlapping on all three axes are
    // tested. O(n log n) per pass, no allocation after the first.
    // A crossing needs a segment that changed since the last check (every
    // change to the snake marks the snaxels it touches as moved).
    dirty.resize(segments);
    bool any_dirty = false;
    for (int i = 0; i < segments; ++i) {
      dirty[i] = snaxels_[i].moved || snaxels_[next(i)].moved;
      any_dirty = any_dirty || dirty[i];
    }
    if (!any_dirty) break;
    double longest = 0;
    Eigen::AlignedBox3d extent;
    boxes.resize(segments);
    for (int i = 0; i < segments; ++i) {
      const Vec3 &p0 = snaxels_[i].position, &p1 = snaxels_[next(i)].position;
      longest = std::max(longest, (p1 - p0).norm());
      boxes[i] = Eigen::AlignedBox3d(p0.cwiseMin(p1), p0.cwiseMax(p1));
      extent.extend(boxes[i]);
    }
    if (!(longest > 0)) break;
    const Vec3 margin = Vec3::Constant(0.5 * longest);
    for (Eigen::AlignedBox3d& box : boxes) box = Eigen::AlignedBox3d(box.min() - margin, box.max() + margin);
    int axis = 0;
    extent.sizes().maxCoeff(&axis);
    order.resize(segments);
    for (int i = 0; i < segments; ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return boxes[a].min()(axis) < boxes[b].min()(axis); });
    // The crossing with the smallest first segment (then second), as a scan along the snake would find.
    int cut_a = -1, cut_b = -1;
    for (int k = 0; k < segments; ++k) {
      const int i = order[k];
      for (int m = k + 1; m < segments && boxes[order[m]].min()(axis) <= boxes[i].max()(axis); ++m) {
        const int a = std::min(i, order[m]), b = std::max(i, order[m]);
        if (b <= a + 1 || (closed_ && a == 0 && b == segments - 1)) continue;  // neighbours share a snaxel
        if (cut_a >= 0 && (a > cut_a || (a == cut_a && b >= cut_b))) continue;
        if (!dirty[a] && !dirty[b]) continue;
        if (!boxes[a].intersects(boxes[b])) continue;
        if (segments_cross(snaxels_[a].position, snaxels_[next(a)].position, snaxels_[b].position,
                           snaxels_[next(b)].position, normal(mesh_, snaxels_[a].point))) {
          cut_a = a;
          cut_b = b;
        }
      }
    }
    if (cut_a < 0) break;
    // Segments a and b cross: the loop is snaxels a+1 .. b (inner arc) or the
    // rest (outer arc). Keep the arc enclosing the larger area (a wrinkled
    // sliver can hold more snaxels than the real outline); open snakes keep
    // their ends.
    auto arc_area = [&](int first, int count) {
      // |vector area| of the arc closed by a straight chord.
      Vec3 twice_area = Vec3::Zero();
      for (int k = 0; k < count; ++k)
        twice_area += snaxels_[(first + k) % n].position.cross(snaxels_[(first + (k + 1) % count) % n].position);
      return twice_area.norm();
    };
    const int inner_count = cut_b - cut_a;
    const bool keep_outer = !closed_ || arc_area(cut_a + 1, inner_count) <= arc_area(cut_b + 1, n - inner_count);
    std::vector<Snaxel> kept;
    if (keep_outer) {
      for (int i = 0; i <= cut_a; ++i) kept.push_back(snaxels_[i]);
      for (int i = cut_b + 1; i < n; ++i) kept.push_back(snaxels_[i]);
    } else {
      for (int i = cut_a + 1; i <= cut_b; ++i) kept.push_back(snaxels_[i]);
    }
    removed += n - static_cast<int>(kept.size());
    snaxels_.swap(kept);
    for (Snaxel& s : snaxels_) s.moved = true;
  }
  return removed;
}

void Snake::subdivide(double l) {
  std::vector<Snaxel> out;
  const int n = size();
  for (int i = 0; i < n; ++i) {
    out.push_back(snaxels_[i]);
    const int j = next(i);
    if (j < 0) continue;
    const double d = (snaxels_[j].position - snaxels_[i].position).norm();
    append_between(i, j, static_cast<int>(std::lround(d / l)), &out);
  }
  snaxels_.swap(out);
}

void Snake::reset_state() {
  for (Snaxel& s : snaxels_) {
    s.moved = true;
    s.locked = false;
    s.anchor = s.position;
    s.age = 0;
  }
}

bool Snake::within(const std::vector<Vec3>& old, double tolerance) const {
  const int m = static_cast<int>(old.size());
  if (m == 0) return snaxels_.empty();
  const int segments = closed_ ? m : m - 1;
  if (segments <= 0) {
    for (const Snaxel& s : snaxels_)
      if ((s.position - old[0]).norm() > tolerance) return false;
    return true;
  }
  // A hash grid of the old segments, each entered in every cell its box (grown by
  // the tolerance) touches; a point then only looks at its own cell.
  double longest = 0;
  for (int k = 0; k < segments; ++k) longest = std::max(longest, (old[(k + 1) % m] - old[k]).norm());
  const double cell = std::max(longest, tolerance) + tolerance;
  auto key = [cell](long long x, long long y, long long z) { return (x * 73856093LL) ^ (y * 19349663LL) ^ (z * 83492791LL); };
  std::unordered_map<long long, std::vector<int>> grid;
  grid.reserve(static_cast<std::size_t>(segments) * 2);
  for (int k = 0; k < segments; ++k) {
    const Vec3 &a = old[k], &b = old[(k + 1) % m];
    const Vec3 lo = a.cwiseMin(b) - Vec3::Constant(tolerance), hi = a.cwiseMax(b) + Vec3::Constant(tolerance);
    for (long long x = std::floor(lo.x() / cell); x <= std::floor(hi.x() / cell); ++x)
      for (long long y = std::floor(lo.y() / cell); y <= std::floor(hi.y() / cell); ++y)
        for (long long z = std::floor(lo.z() / cell); z <= std::floor(hi.z() / cell); ++z) grid[key(x, y, z)].push_back(k);
  }
  const double t2 = tolerance * tolerance;
  for (const Snaxel& s : snaxels_) {
    const Vec3& p = s.position;
    const auto it = grid.find(key(std::floor(p.x() / cell), std::floor(p.y() / cell), std::floor(p.z() / cell)));
    bool near = false;
    if (it != grid.end()) {
      for (int k : it->second) {
        const Vec3 &a = old[k], &b = old[(k + 1) % m];
        const Vec3 ab = b - a;
        const double len2 = ab.squaredNorm();
        const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
        if ((a + t * ab - p).squaredNorm() <= t2) {
          near = true;
          break;
        }
      }
    }
    if (!near) return false;
  }
  return true;
}

std::vector<Vec3> Snake::polyline() const {
  std::vector<Vec3> out;
  out.reserve(snaxels_.size());
  for (const Snaxel& s : snaxels_) out.push_back(s.position);
  return out;
}

std::vector<SurfacePoint> Snake::points() const {
  std::vector<SurfacePoint> out;
  out.reserve(snaxels_.size());
  for (const Snaxel& s : snaxels_) out.push_back(s.point);
  return out;
}

}  // namespace relief_snake

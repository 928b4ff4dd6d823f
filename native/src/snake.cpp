#include "relief_snake/snake.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "grid.hpp"

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
  WalkOptions walk_options;
  walk_options.distance = distances.empty() ? 0 : distances.back();
  walk_options.samples = distances.data();
  walk_options.n_samples = distances.size();
  out = walk_points(walk(mesh, a, pb - pa, walk_options));
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
      // ka's weight along the edge after moving t of it (kb's is the rest).
      const double wa = b[ka] / (b[ka] + b[kb]) + (forward ? -t : t);
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

Snaxel Snake::make(const SurfacePoint& p) {
  Snaxel s;
  s.point = p;
  s.position = relief_snake::position(mesh_, p);
  s.anchor = s.position;
  s.stamp = ++version_;
  return s;
}

void Snake::touch(int i) {
  snaxels_[i].stamp = ++version_;
  snaxels_[i].moved = true;
}

void Snake::move(int i, const SurfacePoint& p) {
  snaxels_[i].point = p;
  snaxels_[i].position = relief_snake::position(mesh_, p);
  snaxels_[i].stamp = ++version_;
}

bool Snake::take_moved_flags(std::vector<char>* moved_before) {
  moved_before->resize(snaxels_.size());
  for (std::size_t i = 0; i < snaxels_.size(); ++i) {
    (*moved_before)[i] = snaxels_[i].moved;
    snaxels_[i].moved = false;
  }
  const bool revisit = revisit_all_;
  revisit_all_ = false;
  return revisit;
}

void Snake::step(int i, const SurfacePoint& p) {
  move(i, p);
  snaxels_[i].moved = true;
}

void Snake::update_locks(int interval, double distance) {
  for (Snaxel& s : snaxels_) {
    if (++s.age < interval || s.locked) continue;
    if ((s.position - s.anchor).norm() < distance) s.locked = true;
    s.anchor = s.position;
    s.age = 0;
  }
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

double Snake::turn_degrees(int i) const { return std::acos(turn_cos(i)) * kDegrees; }

double Snake::length() const {
  double total = 0;
  for (int i = 0; i + 1 < size(); ++i) total += (snaxels_[i + 1].position - snaxels_[i].position).norm();
  if (closed_ && size() > 1) total += (snaxels_.front().position - snaxels_.back().position).norm();
  return total;
}

double Snake::turn_cos(int i) const {
  const int ip = prev(i), in = next(i);
  if (ip < 0 || in < 0) return 1;
  const Vec3 a = snaxels_[i].position - snaxels_[ip].position;
  const Vec3 b = snaxels_[in].position - snaxels_[i].position;
  const double na = a.norm(), nb = b.norm();
  if (!(na > 0) || !(nb > 0)) return 1;
  return std::clamp(a.dot(b) / (na * nb), -1.0, 1.0);
}

int Snake::remove_sharp_turns(double max_degrees) {
  // A turn depends on a snaxel and its two neighbours: unchanged triples passed last time.
  const std::uint64_t since = turns_checked_;
  turns_checked_ = version_;
  const double cos_max = std::cos(max_degrees / kDegrees);  // turning more than max_degrees <=> cos below
  int removed = 0;
  for (int i = 0; i < size() && size() > 3;) {
    const int ip = prev(i), in = next(i);
    const bool changed = changed_since(i, since) || (ip >= 0 && changed_since(ip, since)) ||
                         (in >= 0 && changed_since(in, since));
    if (changed && !is_end(i) && turn_cos(i) < cos_max) {
      snaxels_.erase(snaxels_.begin() + i);
      ++removed;
      // The neighbours' turning angles changed: mark them, re-check from the previous one.
      const int before = i > 0 ? i - 1 : (closed_ ? size() - 1 : -1);
      if (before >= 0) touch(before);
      if (i < size()) touch(i);
      else if (closed_) touch(0);
      if (i > 0) --i;
    } else {
      ++i;
    }
  }
  return removed;
}

int Snake::append_between(int i, int j, int pieces, std::vector<Snaxel>* out) {
  if (pieces < 2) return 0;
  std::vector<double> fractions;
  for (int k = 1; k < pieces; ++k) fractions.push_back(static_cast<double>(k) / pieces);
  for (const SurfacePoint& p : surface_between(mesh_, snaxels_[i].point, snaxels_[j].point, fractions, nearest_resampling_))
    out->push_back(make(p));  // new snaxels start as moved
  return pieces - 1;
}

int Snake::resample(double l) {
  const double lmin = 0.5 * l, lmax = 1.5 * l;
  // A segment whose ends did not change since the last call (with this l) was in range.
  const std::uint64_t since = l == spacing_l_ ? spacing_checked_ : 0;
  spacing_checked_ = version_;
  spacing_l_ = l;
  auto dirty = [&](int i, int j) { return changed_since(i, since) || changed_since(j, since); };
  int changes = 0;
  // Split pass: insert points into long segments (as many as needed); the snake is
  // rebuilt only when some segment is too long.
  const int n = size();
  int first_long = -1;
  for (int i = 0; i < n && first_long < 0; ++i) {
    const int j = next(i);
    if (j >= 0 && dirty(i, j) && (snaxels_[j].position - snaxels_[i].position).norm() > lmax) first_long = i;
  }
  if (first_long >= 0) {
    std::vector<Snaxel> out;
    out.reserve(snaxels_.size() + 16);
    for (int i = 0; i < n; ++i) {
      out.push_back(snaxels_[i]);
      const int j = next(i);
      if (j < 0 || i < first_long || !dirty(i, j)) continue;
      const double d = (snaxels_[j].position - snaxels_[i].position).norm();
      if (d > lmax) changes += append_between(i, j, static_cast<int>(std::ceil(d / l)), &out);
    }
    snaxels_.swap(out);
  }
  // Merge pass: replace a too-short pair by its midpoint (open ends stay put).
  for (int i = 0; i < size() && size() > 3;) {
    const int j = next(i);
    if (j < 0) break;
    if (!dirty(i, j) || (snaxels_[j].position - snaxels_[i].position).norm() >= lmin) {
      ++i;
      continue;
    }
    if (is_end(i)) {
      snaxels_.erase(snaxels_.begin() + j);
      touch(i);
    } else if (is_end(j)) {
      snaxels_.erase(snaxels_.begin() + i);
      touch(i < size() ? i : i - 1);
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

int Snake::trim_boundary_ends() {
  if (closed_) return 0;
  auto on_boundary = [&](int i) {
    int f, k;
    return boundary_edge_of(mesh_, snaxels_[i].point, &f, &k);
  };
  int front = 0;
  while (size() - front > 3 && on_boundary(front) && on_boundary(front + 1)) ++front;
  int back = size();
  while (back - front > 3 && on_boundary(back - 1) && on_boundary(back - 2)) --back;
  const int removed = front + (size() - back);
  if (removed == 0) return 0;
  snaxels_.erase(snaxels_.begin() + back, snaxels_.end());
  snaxels_.erase(snaxels_.begin(), snaxels_.begin() + front);
  // The new ends may slide again.
  for (const int i : {0, size() - 1}) {
    snaxels_[i].locked = false;
    touch(i);
  }
  return removed;
}

int Snake::remove_loops() {
  // Untouched segments did not cross at the last call and have not moved since: only
  // pairs with a changed segment can cross now.
  const std::uint64_t since = loops_checked_;
  loops_checked_ = version_;
  int removed = 0;
  std::vector<int> dirty, near;
  std::vector<std::pair<std::uint64_t, int>> keyed;
  std::vector<Vec3> lo, hi, normals;
  std::vector<char> has_normal;
  HashGrid grid;
  for (int pass = 0; pass < 64; ++pass) {
    const int n = size();
    const int segments = closed_ ? n : n - 1;
    if (segments < 4) break;
    dirty.clear();
    for (int i = 0; i < segments; ++i)
      if (changed_since(i, since) || changed_since(next(i), since)) dirty.push_back(i);
    if (dirty.empty()) break;
    double longest = 0;
    for (int i = 0; i < segments; ++i)
      longest = std::max(longest, (snaxels_[next(i)].position - snaxels_[i].position).norm());
    if (!(longest > 0)) break;
    // Segment boxes, grown by half the longest segment so that crossings seen along a
    // tilted normal are not missed. Two boxes that meet have midpoints at most twice
    // the longest segment apart: in a hash grid of that cell size, each segment goes
    // into its midpoint's cell and a changed one looks at the 27 cells around its own.
    const double margin = 0.5 * longest, cell = 2 * longest;
    // Every segment's box (tested many times) and, on first use, the normal at its first snaxel.
    lo.resize(segments);
    hi.resize(segments);
    for (int i = 0; i < segments; ++i) {
      const Vec3 &p0 = snaxels_[i].position, &p1 = snaxels_[next(i)].position;
      lo[i] = p0.cwiseMin(p1) - Vec3::Constant(margin);
      hi[i] = p0.cwiseMax(p1) + Vec3::Constant(margin);
    }
    normals.resize(segments);
    has_normal.assign(segments, 0);
    auto normal_at = [&](int i) -> const Vec3& {
      if (!has_normal[i]) {
        normals[i] = normal(mesh_, snaxels_[i].point);
        has_normal[i] = 1;
      }
      return normals[i];
    };
    grid.reset(snaxels_[0].position, cell);
    auto cell_of = [&](int i) { return grid.cell_of(0.5 * (snaxels_[i].position + snaxels_[next(i)].position)); };
    for (int i = 0; i < segments; ++i) grid.add(cell_of(i), i);
    grid.build();
    // The changed segments grouped by their cell's key (neighbours along the snake share cells):
    // each group gathers the segments of its 27 cells once. (Cells whose keys agree have
    // neighbourhoods whose keys agree, so each changed segment sees what it would alone.)
    keyed.clear();
    for (const int d : dirty) keyed.emplace_back(HashGrid::key(cell_of(d)), d);
    std::sort(keyed.begin(), keyed.end());
    // The crossing with the smallest first segment (then second), as a scan along the snake would
    // find: the smallest crossing pair among those tested, in whatever order they are tested.
    int cut_a = -1, cut_b = -1;
    for (std::size_t g = 0; g < keyed.size();) {
      std::size_t g_end = g;
      while (g_end < keyed.size() && keyed[g_end].first == keyed[g].first) ++g_end;
      near.clear();
      const HashGrid::Cell c = cell_of(keyed[g].second);
      for (int x = -1; x <= 1; ++x)
        for (int y = -1; y <= 1; ++y)
          for (int z = -1; z <= 1; ++z) grid.for_each(c + HashGrid::Cell(x, y, z), [&](int o) { near.push_back(o); });
      for (; g < g_end; ++g) {
        const int d = keyed[g].second;
        const Vec3 &dlo = lo[d], &dhi = hi[d];
        for (const int other : near) {
          const int a = std::min(d, other), b = std::max(d, other);
          if (b <= a + 1 || (closed_ && a == 0 && b == segments - 1)) continue;  // neighbours share a snaxel
          if (cut_a >= 0 && (a > cut_a || (a == cut_a && b >= cut_b))) continue;
          if ((lo[other].array() > dhi.array()).any() || (dlo.array() > hi[other].array()).any()) continue;
          if (segments_cross(snaxels_[a].position, snaxels_[next(a)].position, snaxels_[b].position,
                             snaxels_[next(b)].position, normal_at(a))) {
            cut_a = a;
            cut_b = b;
          }
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
    // The new segment (across the cut) changed; the greedy step looks at every snaxel again.
    const int joint = keep_outer ? cut_a : static_cast<int>(snaxels_.size()) - 1;
    touch(joint);
    if (next(joint) >= 0) touch(next(joint));
    revisit_all_ = true;
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
  revisit_all_ = false;  // every snaxel is flagged anyway
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
  HashGrid grid(old[0], cell);
  for (int k = 0; k < segments; ++k) {
    const Vec3 &a = old[k], &b = old[(k + 1) % m];
    const Vec3 lo = a.cwiseMin(b) - Vec3::Constant(tolerance), hi = a.cwiseMax(b) + Vec3::Constant(tolerance);
    const HashGrid::Cell c0 = grid.cell_of(lo), c1 = grid.cell_of(hi);
    for (int x = c0.x(); x <= c1.x(); ++x)
      for (int y = c0.y(); y <= c1.y(); ++y)
        for (int z = c0.z(); z <= c1.z(); ++z) grid.add(HashGrid::Cell(x, y, z), k);
  }
  grid.build();
  const double t2 = tolerance * tolerance;
  for (const Snaxel& s : snaxels_) {
    const Vec3& p = s.position;
    bool near = false;
    grid.for_each(grid.cell_of(p), [&](int k) {
      if (near) return;
      const Vec3 &a = old[k], &b = old[(k + 1) % m];
      const Vec3 ab = b - a;
      const double len2 = ab.squaredNorm();
      const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
      if ((a + t * ab - p).squaredNorm() <= t2) near = true;
    });
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

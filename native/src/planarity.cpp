// Planarity over geodesic-h neighbourhoods (Section 5.3.1, 7.2.1) and its
// bilateral filter (Eqn. 6), computed lazily per vertex and cached.
#include "relief_snake/planarity.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>


#include "relief_snake/error.hpp"
#include "relief_snake/plane_fit.hpp"
#include "worker_pool.hpp"

namespace relief_snake {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Neighbourhood::Sphere leaves out surface whose normal turns more than 120 degrees
// from v's: the far side of a thin shell, not the walls of a step.
constexpr double kSphereMinFacing = -0.5;
// ... and counts parts of the tree smaller than h / 2 whole or not at all, by their
// centroid, as it does faces: the cost per vertex stops growing with the resolution
// (measured: the same accuracy on the benchmark's suite as an exact sum).
constexpr double kSphereGrain = 0.5;

// Kimmel-Sethian first-order update of the distance at C from the known
// distances dA, dB at A and B of the triangle (A, B, C): the planar wavefront
// d(x) = d_C + g.(x - C) with |g| = 1 through (A, dA) and (B, dB). Returns +inf
// when the update is not valid (no real solution, or the front reaches C from
// outside the triangle's angle at C, as happens at obtuse corners); the caller
// then falls back to the Dijkstra edge updates.
double triangle_update(const Vec3& A, const Vec3& B, const Vec3& C, double dA, double dB) {
  const Vec3 e1 = A - C, e2 = B - C;
  const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2);
  const double det = g11 * g22 - g12 * g12;
  if (!(det > 1e-12 * g11 * g22)) return kInf;  // degenerate (needle) triangle
  // Q = G^-1 with G = X^T X, X = [e1 e2]
  const double q11 = g22 / det, q12 = -g12 / det, q22 = g11 / det;
  // |X Q (t - d 1)|^2 = 1 with t = (dA, dB):  a d^2 - 2 b d + c = 0
  const double a = q11 + 2 * q12 + q22;
  const double b = (q11 + q12) * dA + (q12 + q22) * dB;
  const double c = q11 * dA * dA + 2 * q12 * dA * dB + q22 * dB * dB - 1.0;
  const double disc = b * b - a * c;
  if (disc < 0 || !(a > 0)) return kInf;
  const double d = (b + std::sqrt(disc)) / a;
  if (d < std::max(dA, dB)) return kInf;
  // Upwind: g = X lambda with lambda = Q (t - d 1); the characteristic reaching
  // C comes from inside the triangle iff -g lies in the cone of e1, e2.
  const double l1 = q11 * (dA - d) + q12 * (dB - d);
  const double l2 = q12 * (dA - d) + q22 * (dB - d);
  if (l1 > 0 || l2 > 0) return kInf;
  return d;
}

// Point-source update (Novotni and Klein 2002): unfold the triangle into its
// plane, place the virtual source S on the far side of AB with |S - A| = dA and
// |S - B| = dB, and take |S - C| if the straight ray S -> C crosses AB. Exact on
// flat regions, where the planar-front update above overestimates near the
// source by up to ~20% (its front is straight, the true one circular). Returns
// +inf when not applicable; the caller then uses the planar-front update.
double point_source_update(const Vec3& A, const Vec3& B, const Vec3& C, double dA, double dB) {
  const Vec3 ab = B - A, ac = C - A;
  const double c = ab.norm();
  if (!(c > 0)) return kInf;
  const Vec3 ex = ab / c;
  const double cx = ac.dot(ex);
  const double cy = (ac - cx * ex).norm();  // C at (cx, cy), cy > 0
  if (!(cy > 1e-12 * c)) return kInf;
  const double sx = (dA * dA - dB * dB + c * c) / (2 * c);
  const double sy2 = dA * dA - sx * sx;
  if (sy2 < 0) return kInf;  // |dA - dB| > |AB|: no such source
  const double sy = std::sqrt(sy2);  // S = (sx, -sy)
  const double t = sy / (cy + sy);    // where S -> C meets the line AB
  const double xt = sx + t * (cx - sx);
  if (xt < 0 || xt > c) return kInf;  // the ray passes outside the edge
  const double d = std::sqrt((cx - sx) * (cx - sx) + (cy + sy) * (cy + sy));  // no overflow risk: mesh-sized values
  if (d < std::max(dA, dB)) return kInf;
  return d;
}

}  // namespace

MomentTree::Elements PlanarityField::tree_elements(PlaneFit fit) {
  switch (fit) {
    case PlaneFit::Area: return MomentTree::Elements::Faces;
    case PlaneFit::VertexAreas: return MomentTree::Elements::WeightedVertices;
    case PlaneFit::Vertices: break;
  }
  return MomentTree::Elements::Vertices;
}

PlanarityField::PlanarityField(const Mesh& mesh, const PlanarityOptions& options,
                               std::shared_ptr<const MomentTree> tree)
    : mesh_(mesh), options_(options), tree_(std::move(tree)) {
  if (!std::isfinite(options.radius) || options.radius <= 0)
    throw Error("planarity radius (the step height h) must be a positive finite number, got " +
                std::to_string(options.radius));
  if (std::isnan(options.sigma_s) || std::isinf(options.sigma_s))
    throw Error("planarity sigma_s must be finite (or <= 0 to estimate it from the data)");
  if (options.sigma_s > 0) sigma_s_ = options.sigma_s;
  if (options.neighbourhood == Neighbourhood::Sphere) {
    const MomentTree::Elements wanted = tree_elements(options.fit);
    if (!tree_ || &tree_->mesh() != &mesh || tree_->elements() != wanted)
      tree_ = std::make_shared<const MomentTree>(mesh, wanted);
  }
  const std::size_t n = static_cast<std::size_t>(mesh.n_vertices());
  raw_.assign(n, kNaN);
  filtered_.assign(n, kNaN);
  scratch(0);
}

PlanarityField::~PlanarityField() = default;

PlanarityField::Scratch& PlanarityField::scratch(int worker) {
  if (static_cast<int>(scratch_.size()) <= worker) scratch_.resize(worker + 1);
  Scratch& s = scratch_[worker];
  if (s.distance.empty() && mesh_.n_vertices() > 0) {
    s.distance.assign(mesh_.n_vertices(), kInf);
    s.accepted.assign(mesh_.n_vertices(), 0);
  }
  return s;
}

void PlanarityField::check_vertex(int v) const {
  if (v < 0 || v >= mesh_.n_vertices())
    throw Error("vertex index " + std::to_string(v) + " is out of range: the mesh has " +
                std::to_string(mesh_.n_vertices()) + " vertices");
}

double PlanarityField::raw(int v) {
  check_vertex(v);
  double& value = raw_[v];
  if (std::isnan(value)) {
    value = compute_raw(v, scratch_[0]);
    ++raw_count_;
  }
  return value;
}

double PlanarityField::filtered(int v) {
  check_vertex(v);
  double& value = filtered_[v];
  if (std::isnan(value)) {
    const double computed = compute_filtered(v);  // may throw: leave the cache untouched then
    value = computed;
    ++filtered_count_;
  }
  return value;
}

double PlanarityField::filtered(const SurfacePoint& p) {
  if (!p.valid() || p.face >= mesh_.n_faces())
    throw Error("filtered planarity asked at an invalid surface point (face " + std::to_string(p.face) +
                "); pass a point on the mesh");
  return interpolate(mesh_, p, [this](int v) { return filtered(v); });
}

double PlanarityField::cached_filtered(const SurfacePoint& p) const {
  if (!p.valid() || p.face >= mesh_.n_faces())
    throw Error("filtered planarity asked at an invalid surface point (face " + std::to_string(p.face) +
                "); pass a point on the mesh");
  return interpolate(mesh_, p, [this](int v) { return filtered_[v]; });  // NaN if a corner is missing
}

void PlanarityField::reset(Scratch& s) {
  // Only the entries this call touched: O(ball), never O(#V).
  for (int u : s.touched) {
    s.distance[u] = kInf;
    s.accepted[u] = 0;
  }
  s.touched.clear();
  s.heap.clear();
}

void PlanarityField::march(int v, Scratch& s) const {
  const double h = options_.radius;
  using Entry = std::pair<double, int>;
  const auto later = std::greater<Entry>();  // min-heap on distance
  std::vector<double>& distance = s.distance;
  std::vector<char>& accepted = s.accepted;
  std::vector<std::pair<double, int>>& heap = s.heap;
  s.ball.clear();
  heap.clear();
  s.touched.clear();

  distance[v] = 0;
  s.touched.push_back(v);
  heap.emplace_back(0.0, v);

  // Geodesic distance is at least the straight one: vertices outside the
  // Euclidean h-ball can never enter the ball nor serve as upwind values.
  const Vec3 pv = mesh_.position(v);
  const double h2 = h * h;
  // Raw pointers: the compiler cannot tell that pushing onto the heap leaves
  // these arrays alone, and would reload them at every access otherwise.
  double* const dist = distance.data();
  char* const done = accepted.data();
  const Vec3* const position = &mesh_.position(0);
  const int* const corners = mesh_.face_vertices();
  auto reachable = [&](int u) { return (position[u] - pv).squaredNorm() <= h2; };
  auto offer = [&](int u, double d) {
    if (!(d <= h) || !(d < dist[u])) return;
    if (dist[u] == kInf) s.touched.push_back(u);
    dist[u] = d;
    heap.emplace_back(d, u);
    std::push_heap(heap.begin(), heap.end(), later);
  };

  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), later);
    const Entry top = heap.back();
    heap.pop_back();
    const int u = top.second;
    if (done[u] || top.first > dist[u]) continue;  // stale entry
    done[u] = 1;
    s.ball.push_back(u);
    const double du = dist[u];
    const Vec3 pu = position[u];

    // Dijkstra edge updates: always available, exact along edges.
    for (const int *it = mesh_.neighbors_begin(u), *end = mesh_.neighbors_end(u); it != end; ++it) {
      const int w = *it;
      if (!done[w] && reachable(w)) offer(w, du + (position[w] - pu).norm());
    }
    // Triangle updates through every face with u and one other accepted corner.
    for (const int *it = mesh_.faces_begin(u), *end = mesh_.faces_end(u); it != end; ++it) {
      const int* corner = corners + 3 * *it;
      // The two corners other than u, in face order.
      int a, b;
      if (corner[0] == u) {
        a = corner[1];
        b = corner[2];
      } else if (corner[1] == u) {
        a = corner[2];
        b = corner[0];
      } else {
        a = corner[0];
        b = corner[1];
      }
      if (done[a] == done[b]) continue;  // need exactly one known corner besides u
      if (done[a]) std::swap(a, b);      // now a is the target, b is known
      if (!reachable(a)) continue;
      const Vec3 &pa = position[a], &pb = position[b];
      double d = point_source_update(pu, pb, pa, du, dist[b]);
      if (d == kInf) d = triangle_update(pu, pb, pa, du, dist[b]);
      offer(a, d);
    }
  }
}

void PlanarityField::geodesic_ball(int v, std::vector<int>* vertices, std::vector<double>* distances) {
  check_vertex(v);
  Scratch& s = scratch_[0];
  march(v, s);
  if (vertices) vertices->assign(s.ball.begin() + 1, s.ball.end());
  if (distances) {
    distances->clear();
    for (std::size_t i = 1; i < s.ball.size(); ++i) distances->push_back(s.distance[s.ball[i]]);
  }
  reset(s);
}

void PlanarityField::euclidean_ball(int v, Scratch& s) const {
  const Vec3 pv = mesh_.position(v);
  const double h2 = options_.radius * options_.radius;
  s.ball.clear();
  s.touched.clear();
  s.ball.push_back(v);
  s.accepted[v] = 1;
  s.touched.push_back(v);
  for (std::size_t i = 0; i < s.ball.size(); ++i) {
    const int u = s.ball[i];
    for (const int* it = mesh_.neighbors_begin(u); it != mesh_.neighbors_end(u); ++it) {
      const int w = *it;
      if (s.accepted[w]) continue;
      if ((mesh_.position(w) - pv).squaredNorm() > h2) continue;
      s.accepted[w] = 1;
      s.touched.push_back(w);
      s.ball.push_back(w);
    }
  }
}

double PlanarityField::compute_raw(int v, Scratch& s) const {
  const Vec3& pv = mesh_.position(v);
  const Vec3& vn = mesh_.vertex_normal(v);
  if (options_.neighbourhood == Neighbourhood::Sphere) {
    MomentTree::Query q;
    q.center = pv;
    q.radius = options_.radius;
    q.component = mesh_.component(v);
    q.facing = vn;
    q.min_facing = kSphereMinFacing;
    q.grain = kSphereGrain * options_.radius;
    PlaneMoments m = tree_->sphere(q);
    const double r2 = options_.radius * options_.radius;
    if (options_.fit != PlaneFit::Area) {
      // v itself is in the sphere; about v its first and second moments are zero.
      m.weight -= vertex_weight(v);
      if (options_.include_one_ring)
        for (const int* it = mesh_.neighbors_begin(v); it != mesh_.neighbors_end(v); ++it)
          if ((mesh_.position(*it) - pv).squaredNorm() > r2) m.add_point(mesh_.position(*it) - pv, vertex_weight(*it));
      // Fewer than three neighbours (h smaller than the edges): fall back to the one-ring.
      if (!(m.weight > 0) || (options_.fit == PlaneFit::Vertices && m.weight < 2.5)) return one_ring_planarity(v);
    } else if (options_.include_one_ring) {
      // v's own faces count whole, like the one-ring of a vertex fit.
      for (const int* f = mesh_.faces_begin(v); f != mesh_.faces_end(v); ++f) {
        const Vec3 a = mesh_.position(mesh_.face_vertex(*f, 0)) - pv, b = mesh_.position(mesh_.face_vertex(*f, 1)) - pv,
                   c = mesh_.position(mesh_.face_vertex(*f, 2)) - pv;
        if (((a + b + c) / 3.0).squaredNorm() > r2) m.add_triangle(a, b, c);
      }
    }
    return planarity_about_vertex(m, vn);
  }

  if (options_.neighbourhood == Neighbourhood::Euclidean)
    euclidean_ball(v, s);
  else
    march(v, s);
  if (options_.include_one_ring) {
    for (const int* it = mesh_.neighbors_begin(v); it != mesh_.neighbors_end(v); ++it) {
      const int w = *it;
      if (s.accepted[w]) continue;
      s.ball.push_back(w);  // beyond h, but adjacent
      s.accepted[w] = 1;    // marked for the area fit below; reset() clears it
      s.touched.push_back(w);
    }
  }
  PlaneMoments m;
  if (options_.fit == PlaneFit::Area) {
    // The faces with every corner in the neighbourhood (ball[0] is v), each once:
    // from its lowest-numbered corner.
    const int* corners = mesh_.face_vertices();
    for (int u : s.ball)
      for (const int* f = mesh_.faces_begin(u); f != mesh_.faces_end(u); ++f) {
        const int* c = corners + 3 * *f;
        if (!s.accepted[c[0]] || !s.accepted[c[1]] || !s.accepted[c[2]] || u != std::min({c[0], c[1], c[2]}))
          continue;
        m.add_triangle(mesh_.position(c[0]) - pv, mesh_.position(c[1]) - pv, mesh_.position(c[2]) - pv,
                       mesh_.face_area(*f));
      }
    reset(s);
    return planarity_about_vertex(m, vn);
  }
  reset(s);
  // ball[0] is v itself; the neighbours are the rest.
  if (s.ball.size() < 4) return one_ring_planarity(v);  // h smaller than the edges
  for (std::size_t k = 1; k < s.ball.size(); ++k) m.add_point(mesh_.position(s.ball[k]) - pv, vertex_weight(s.ball[k]));
  return planarity_about_vertex(m, vn);
}

double PlanarityField::vertex_weight(int v) const {
  return options_.fit == PlaneFit::VertexAreas ? mesh_.vertex_area(v) : 1.0;
}

double PlanarityField::one_ring_planarity(int v) const {
  const Vec3& pv = mesh_.position(v);
  PlaneMoments m;
  for (const int* it = mesh_.neighbors_begin(v); it != mesh_.neighbors_end(v); ++it)
    m.add_point(mesh_.position(*it) - pv);
  if (m.weight < 3) return 0.0;  // a plane through v and <= 2 neighbours contains v
  return planarity_about_vertex(m, mesh_.vertex_normal(v));
}

void PlanarityField::two_ring(int v, Scratch& s, std::vector<int>* out) const {
  // accepted is all zero between marches, so it serves as the visited mark.
  std::vector<char>& seen = s.accepted;
  out->clear();
  seen[v] = 1;
  for (const int* it = mesh_.neighbors_begin(v); it != mesh_.neighbors_end(v); ++it) {
    if (!seen[*it]) {
      seen[*it] = 1;
      out->push_back(*it);
    }
  }
  const std::size_t one_ring = out->size();
  for (std::size_t i = 0; i < one_ring; ++i) {
    const int w = (*out)[i];
    for (const int* it = mesh_.neighbors_begin(w); it != mesh_.neighbors_end(w); ++it) {
      if (!seen[*it]) {
        seen[*it] = 1;
        out->push_back(*it);
      }
    }
  }
  seen[v] = 0;
  for (int w : *out) seen[w] = 0;
}

WorkerPool* PlanarityField::pool() {
  if (options_.threads == 1) return nullptr;
  if (!pool_) pool_ = std::make_unique<WorkerPool>(options_.threads);
  for (int w = 0; w < pool_->size(); ++w) scratch(w);  // allocate before any thread starts
  return pool_.get();
}

void PlanarityField::prefetch_raw(const std::vector<int>& vertices) {
  // The batch: distinct vertices whose P is missing (NaN marks "queued" too).
  batch_.clear();
  std::vector<char>& queued = scratch_[0].accepted;
  for (int v : vertices) {
    check_vertex(v);
    if (std::isnan(raw_[v]) && !queued[v]) {
      queued[v] = 1;
      batch_.push_back(v);
    }
  }
  for (int v : batch_) queued[v] = 0;
  if (batch_.empty()) return;
  WorkerPool* workers = batch_.size() >= 2 ? pool() : nullptr;
  if (!workers || workers->size() == 1) {
    for (int v : batch_) raw(v);
    return;
  }
  // Each item writes only its own raw_ entry; compute_raw reads nothing shared but the mesh.
  workers->run(static_cast<int>(batch_.size()),
             [this](int item, int worker) { raw_[batch_[item]] = compute_raw(batch_[item], scratch_[worker]); });
  raw_count_ += batch_.size();
}

void PlanarityField::prefetch_filtered(const std::vector<int>& vertices) {
  needed_.clear();
  for (int v : vertices) {
    check_vertex(v);
    if (!std::isnan(filtered_[v])) continue;
    needed_.push_back(v);
    two_ring(v, scratch_[0], &ring_);
    needed_.insert(needed_.end(), ring_.begin(), ring_.end());
  }
  prefetch_raw(needed_);
  for (int v : vertices) filtered(v);
}

double PlanarityField::compute_filtered(int v) {
  if (!(sigma_s_ > 0))
    throw Error("programming error: filtered planarity needs sigma_s; call estimate_sigma_s() first or set "
                "PlanarityOptions::sigma_s > 0");
  // N(v) = v and its two-ring (edge-hop distance 1 and 2).
  two_ring(v, scratch_[0], &ring_);

  const Vec3& pv = mesh_.position(v);
  double max_dist2 = 0;
  for (int w : ring_) max_dist2 = std::max(max_dist2, (mesh_.position(w) - pv).squaredNorm());
  const double pv_raw = raw(v);
  if (!(max_dist2 > 0)) return pv_raw;
  // sigma_c = half the largest two-ring distance (Fleishman et al. 2003).
  const double inv_2sc2 = 1.0 / (2.0 * 0.25 * max_dist2);
  const double inv_2ss2 = 1.0 / (2.0 * sigma_s_ * sigma_s_);

  double num = pv_raw, den = 1.0;  // v itself: W_c(0) W_s(0) = 1
  for (int w : ring_) {
    const double pw = raw(w);
    const double dp = pv_raw - pw;
    const double weight =
        std::exp(-(mesh_.position(w) - pv).squaredNorm() * inv_2sc2 - dp * dp * inv_2ss2);
    num += weight * pw;  // P(v') in the numerator: Eqn. 6 as printed would be the identity
    den += weight;
  }
  return num / den;
}

void PlanarityField::estimate_sigma_s(const std::vector<int>& sample_vertices) {
  if (sample_vertices.empty())
    throw Error("estimate_sigma_s needs at least one sample vertex (e.g. the vertices along the initial contour)");
  prefetch_raw(sample_vertices);  // checks the indices
  // Two passes over the cached values: numerically safer than sum of squares.
  double mean = 0;
  for (int v : sample_vertices) mean += raw(v);
  mean /= static_cast<double>(sample_vertices.size());
  double var = 0;
  for (int v : sample_vertices) {
    const double d = raw(v) - mean;
    var += d * d;
  }
  var /= static_cast<double>(sample_vertices.size());
  double sd = std::sqrt(var);
  // A perfectly planar sample would give sigma_s = 0 and W_s = exp(-x^2/0):
  // keep W_s finite with a small fraction of h instead.
  const double floor = 1e-2 * options_.radius;
  if (!(sd > 1e-6 * options_.radius)) sd = floor;
  if (sd != sigma_s_ && filtered_count_ > 0) {
    // The cached P^ were computed with another sigma_s: drop them.
    std::fill(filtered_.begin(), filtered_.end(), kNaN);
    filtered_count_ = 0;
  }
  sigma_s_ = sd;
}

}  // namespace relief_snake

#pragma once
// Planarity (Section 5.3.1) over geodesic-h neighbourhoods and its bilateral
// filtering (Eqn. 6, Section 7.2.1), computed lazily: only at the vertices the
// snake actually reaches, and cached for reuse by later segmentations.
#include <memory>
#include <utility>
#include <vector>

#include "relief_snake/mesh.hpp"
#include "relief_snake/moment_tree.hpp"
#include "relief_snake/surface_point.hpp"

namespace relief_snake {

/// Which part of the surface around v the plane of P(v) is fitted to.
enum class Neighbourhood {
  Geodesic,   ///< within geodesic distance h (the paper): local fast marching
  Euclidean,  ///< within straight distance h and connected to v inside that ball (not in the paper; ~10x cheaper)
  /// Within straight distance h, on v's component, facing v's side (normals within 120
  /// degrees of v's), summed through a MomentTree: the cost grows with the sphere's
  /// boundary, not its content (not in the paper).
  Sphere,
};

/// What the plane is fitted to.
enum class PlaneFit {
  Vertices,  ///< the neighbouring vertices, one unit weight each (the paper; v itself excluded)
  /// The neighbouring vertices, each weighted by its area (a third of its faces'): the
  /// vertex fit without the bias towards densely sampled parts (not in the paper).
  VertexAreas,
  /// The neighbourhood's surface, weighted by area: faces whose corners are all in the
  /// neighbourhood (Geodesic, Euclidean) or the surface inside the sphere (Sphere). Does not
  /// depend on how densely each part was sampled, e.g. a step wall with no vertices on it
  /// (not in the paper).
  Area,
};

struct PlanarityOptions {
  double radius = 0;          ///< geodesic neighbourhood radius: the step height h
  double sigma_s = 0;         ///< bilateral similarity sigma; <= 0: estimate (see PlanarityField::estimate_sigma_s)
  /// Always count the one-ring among the neighbours (with PlaneFit::Area: v's own
  /// faces), even beyond distance h: a scanned vertical step of height ~h has no
  /// vertices on its wall, so the ball alone would never see the top from the foot
  /// (not in the paper).
  bool include_one_ring = true;
  Neighbourhood neighbourhood = Neighbourhood::Geodesic;
  PlaneFit fit = PlaneFit::Vertices;
  /// Threads for prefetch_*(): 0 = one per hardware thread, 1 = the caller only.
  /// Results do not depend on it.
  int threads = 0;
};

class WorkerPool;

/// Planarity P(v) and filtered planarity P^(v) of a mesh for one radius h.
///
/// P(v) = (c - v) . n for the least-squares plane (c, n) of v's neighbourhood
/// (options: by default the vertices within geodesic distance h of v, v itself
/// excluded, at least the one-ring), with n oriented like the vertex normal.
/// P > 0 where v lies below the plane of its neighbours (a concave crease such as
/// the foot of a relief step), P < 0 at convex creases (the top edge of the step).
/// Geodesic distances come from a local fast-marching front limited to radius h.
///
/// P^(v) (Eqn. 6 with P(v') in the numerator) averages P over v and its
/// two-ring with weights W_c(|v - v'|) W_s(P(v) - P(v')), sigma_c = half the
/// largest distance to a two-ring vertex, sigma_s global (see options).
///
/// Values are computed on first use and cached. prefetch_*() computes a batch
/// of missing values on several threads; the object itself must be used from
/// one thread at a time.
class PlanarityField {
 public:
  /// tree: a MomentTree of this mesh to reuse for Neighbourhood::Sphere (it does not
  /// depend on h); built here when missing or of the wrong kind.
  PlanarityField(const Mesh& mesh, const PlanarityOptions& options, std::shared_ptr<const MomentTree> tree = nullptr);
  ~PlanarityField();

  double raw(int v);        ///< P(v)
  double filtered(int v);   ///< P^(v)
  /// P^ interpolated linearly inside the face of p.
  double filtered(const SurfacePoint& p);
  /// The same from the cache only, for threads: NaN if a corner's P^ has not been
  /// computed yet (prefetch_filtered() computes it).
  double cached_filtered(const SurfacePoint& p) const;

  /// Computes and caches P at the given vertices, in parallel.
  void prefetch_raw(const std::vector<int>& vertices);
  /// Computes and caches P^ at the given vertices; the P they need (over their
  /// two-rings) is computed in parallel first.
  void prefetch_filtered(const std::vector<int>& vertices);

  /// The geodesic ball used by raw(v): the vertices within geodesic distance
  /// radius() of v (v excluded; fast-marching distances, not the one-ring
  /// fallback), in the order the front reached them, with their distances.
  /// Either output may be null.
  void geodesic_ball(int v, std::vector<int>* vertices, std::vector<double>* distances);

  /// Sets sigma_s to the standard deviation of P over the given vertices
  /// (the paper says "variance"; a Gaussian needs the standard deviation).
  /// Must be called before the first filtered() if options.sigma_s <= 0.
  /// If that deviation is ~0 (a perfectly planar sample), uses 0.01 h so W_s
  /// stays finite. A changed sigma_s drops the cached P^ values.
  void estimate_sigma_s(const std::vector<int>& sample_vertices);
  double sigma_s() const { return sigma_s_; }
  double radius() const { return options_.radius; }
  const Mesh& mesh() const { return mesh_; }
  const PlanarityOptions& options() const { return options_; }
  /// The MomentTree in use (Neighbourhood::Sphere), or null.
  const std::shared_ptr<const MomentTree>& tree() const { return tree_; }
  /// The kind of MomentTree elements a fit needs.
  static MomentTree::Elements tree_elements(PlaneFit fit);

  /// The threads of prefetch_*() (created on first use; null with options.threads = 1),
  /// lent to other parallel loops of the same segmentation.
  WorkerPool* pool();

  /// Number of vertices whose P (resp. P^) has been computed so far.
  std::size_t raw_count() const { return raw_count_; }
  std::size_t filtered_count() const { return filtered_count_; }

 private:
  /// Per-thread scratch of the local fast marching, reused between calls.
  struct Scratch {
    std::vector<double> distance;            // +inf = untouched
    std::vector<char> accepted;              // also the visited mark of two_ring()
    std::vector<int> touched;                // entries of distance/accepted to reset
    std::vector<std::pair<double, int>> heap;
    std::vector<int> ball;                   // accepted vertices, v first
  };
  Scratch& scratch(int worker);  // allocates on first use
  double compute_raw(int v, Scratch& scratch) const;
  /// P(v) against the plane of its one-ring (h smaller than the edges).
  double one_ring_planarity(int v) const;
  /// A vertex's weight in a vertex fit: 1, or its area (PlaneFit::VertexAreas).
  double vertex_weight(int v) const;
  double compute_filtered(int v);
  void check_vertex(int v) const;
  /// Fast marching from v up to radius(); fills scratch.ball.
  void march(int v, Scratch& scratch) const;
  /// Breadth-first search from v through vertices within straight distance radius(); fills scratch.ball.
  void euclidean_ball(int v, Scratch& scratch) const;
  static void reset(Scratch& scratch);
  /// v's two-ring (edge-hop distance 1 and 2, v excluded) into *out.
  void two_ring(int v, Scratch& scratch, std::vector<int>* out) const;

  const Mesh& mesh_;
  PlanarityOptions options_;
  double sigma_s_ = 0;
  std::vector<double> raw_, filtered_;  // NaN = not computed yet
  std::size_t raw_count_ = 0, filtered_count_ = 0;
  std::vector<Scratch> scratch_;        // one per worker
  std::unique_ptr<WorkerPool> pool_;    // created by the first prefetch that needs it
  std::shared_ptr<const MomentTree> tree_;  // Neighbourhood::Sphere
  std::vector<int> ring_, needed_, batch_;  // scratch for filtered() and prefetch_*()
};

}  // namespace relief_snake

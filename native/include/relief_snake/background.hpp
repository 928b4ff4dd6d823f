#pragma once
// The background under a relief: the smooth surface the scan would have without it,
// continued from the background around the relief region (Liu et al. 2007, "Background
// surface estimation for reverse engineering of reliefs", by a thin-plate fill).
//
// A ring of background ring_width h wide around the region is fitted by a smooth surface that
// continues into the region, the minimiser of
//     sum_v A_v |L x|_v^2  +  sum_{band} A_v / s^4 |x_v - x0_v|^2
// over the region's values x and those of the ring's inner band (L: cotangent or uniform
// Laplacian with vertex areas A; s: the smoothing length); the rest of the ring stays fixed, so
// value and tangent continue across the contour. x is either the offset from a quadric fitted
// to the ring over its best-fit plane (HeightField, exact for quadrics) or the vertex position
// itself (Surface, for backgrounds that fold over any plane). With s = 0 the ring is fixed exactly
// (a biharmonic fill). One sparse SPD solve (Eigen SimplicialLDLT). How far the band lies from
// the fitted surface is the fit residual: how well a smooth surface explains the background
// around the relief.
//
// Used by extraction (extract.hpp) and meant for the snake's robustness checks: fit the
// background outside a contour, then ask for heights above it (height_above()).
#include <string>
#include <vector>

#include "relief_snake/mesh.hpp"
#include "relief_snake/surface_point.hpp"

namespace relief_snake {

enum class BackgroundLaplacian {
  Cotangent,  ///< cotangent weights of the scan's own triangles (linear precision: planes stay planes exactly)
  Uniform,    ///< one per edge (robust on degenerate triangles; lets vertices drift along the surface)
};

enum class BackgroundModel {
  Auto,         ///< HeightField where the surface around the region is one over its ring's plane, else Surface
  HeightField,  ///< a quadric fitted to the ring over its best-fit plane, plus a thin-plate fill of the
                ///< ring's offsets from it (exact for quadrics; each vertex keeps its place over the plane)
  Surface,      ///< a thin-plate fill of the vertex positions themselves (any shape, e.g. around a tube)
};

struct BackgroundOptions {
  BackgroundModel model = BackgroundModel::Auto;
  double ring_width = 3;   ///< width of the background ring fitted around the region, in units of h
  double smoothing = 0.5;  ///< smoothing length s, in units of h; 0: the ring is fixed exactly
  /// The ring's inner band this wide (in h) is fitted softly, the rest of the ring stays fixed
  /// (the quadric is fitted to the whole ring). A narrower band is a smaller solve.
  double smoothing_band = 1;
  BackgroundLaplacian laplacian = BackgroundLaplacian::Cotangent;
};

enum class BackgroundStatus {
  Ok,
  EmptyRegion,   ///< no vertex in the region
  NoRing,        ///< the region covers a whole connected component: no background around it
  SizeMismatch,  ///< the region mask or an index does not fit the mesh
  BadParameter,  ///< h or an option out of range
};
const char* to_string(BackgroundStatus status);

/// Where solve() spends its wall time, by stage (seconds; for benchmarks).
struct BackgroundTimings {
  double ring = 0;           ///< region checks and the ring (distances along edges)
  double assembly = 0;       ///< unknowns, the model's frame, Laplacian weights, the normal equations
  double ordering = 0;       ///< the sparse solve's fill-reducing ordering and symbolic analysis
  double factorisation = 0;  ///< its numeric factorisation
  double solve = 0;          ///< its triangular solves (all coordinates with one factorisation)
  double height = 0;         ///< base positions, normals, heights and the ring residual
};

struct BackgroundResult {
  BackgroundStatus status = BackgroundStatus::Ok;
  std::string message;  ///< one line for the user when status != Ok

  BackgroundModel model = BackgroundModel::Surface;  ///< the model used (Auto resolved)
  std::vector<char> region;  ///< #V: 1 for the region's vertices
  std::vector<int> region_vertices;  ///< the region's mesh vertices, ascending
  std::vector<int> ring_vertices;    ///< the fitted background ring's mesh vertices, ascending
  /// #V: the base surface, in the mesh's coordinates (like Mesh::position; Mesh::to_file gives the
  /// file's). Region and ring vertices: the fitted smooth surface; every other vertex: its own
  /// position (bit-identical).
  std::vector<Vec3> base_positions;
  /// #V: unit normals of the base surface (area-weighted over its faces), oriented like the mesh.
  std::vector<Vec3> base_normals;
  /// #V: signed height of each vertex above the base along the base normal,
  /// (position - base) . normal; region and ring vertices, 0 elsewhere.
  std::vector<double> height;
  /// The fitted band's heights above the fitted surface: root mean square, and the largest
  /// magnitude (0 when smoothing = 0: the ring is fixed).
  double ring_rms_residual = 0, ring_max_residual = 0;
  double seconds = 0;  ///< time of solve()
  BackgroundTimings timings;

  bool ok() const { return status == BackgroundStatus::Ok; }
};

/// The fill for one mesh, for several regions (a snake's successive contours): each solve()
/// computes the Laplacian weights of the faces around its region and ring only.
class BackgroundSolver {
 public:
  explicit BackgroundSolver(const Mesh& mesh, const BackgroundOptions& options = {});

  /// region: #V flags (1 = relief). h: the relief's step height (sets the ring width and
  /// smoothing length). Errors come back in the result's status and message.
  BackgroundResult solve(const std::vector<char>& region, double h) const;
  /// The same from mesh vertex indices (any order, repeats allowed).
  BackgroundResult solve_vertices(const std::vector<int>& region_vertices, double h) const;

  const Mesh& mesh() const { return mesh_; }
  const BackgroundOptions& options() const { return options_; }

 private:
  const Mesh& mesh_;
  BackgroundOptions options_;
  /// Where each vertex's one-ring entries start in a flat per-entry array (#V + 1).
  std::vector<std::size_t> ring_offset_;
};

/// One fill with `options` and, where that fails, with uniform weights instead (cotangent weights
/// over a sharp wall's projection can be singular; uniform ones are not). A new solver each call:
/// for one-off fills (BackgroundSolver keeps its precomputation for several).
BackgroundResult fill_background(const Mesh& mesh, const std::vector<char>& region, double h,
                                 const BackgroundOptions& options = {});

/// Heights above the base at surface points: (position(p) - base(p)) . n_base(p) with the base
/// position and normal interpolated linearly in p's face. 0 for points on faces the fit left
/// untouched (far from the region). result must be an ok() result for this mesh.
std::vector<double> height_above(const Mesh& mesh, const BackgroundResult& result,
                                 const std::vector<SurfacePoint>& points);

}  // namespace relief_snake

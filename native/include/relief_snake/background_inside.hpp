#pragma once
// Background inside a region: does a segmentation's region take in a piece of background? (Not
// in the paper.) A snake that bridges a concavity's mouth, or wraps a lobe around a texture dot,
// can sit on a step almost everywhere along its contour: the contour-wise step evidence
// (evidence.hpp) sees walls on both sides of the bridge and calls it a step. The heights tell: the
// piece behind the bridge lies at the background's height, as the ring outside the contour does.
//
// 1-2. The background: the thin-plate fill of background.hpp (a ring of background around the
//    region, continued smoothly under it), or a robust quadric over that ring (Tukey's biweight,
//    height_statistics.hpp: cheaper, but a wavy or vase-like background is not a quadric); each
//    region vertex's height above it.
// 3. Low pieces: connected sets of region vertices lower than low_share of the step found, that
//    touch the outside (the contour). Each piece's depth is its inradius: the largest distance
//    from one of its vertices to the nearest vertex that is not in it (relief, or outside).
//    A blended step's foot, a groove or the gap between the contour and the foot is a thin strip;
//    a bridged concavity or a lobe holds a disk of background.
#include <memory>
#include <vector>

#include "relief_snake/background.hpp"
#include "relief_snake/mesh.hpp"

namespace relief_snake {

enum class BackgroundInsideModel { ThinPlate, RingQuadric };

struct BackgroundInsideOptions {
  BackgroundInsideModel model = BackgroundInsideModel::ThinPlate;
  double ring_width = 2.5;     ///< RingQuadric: the ring, in h (and at least ring_width_edges average edges)
  double ring_width_edges = 6;
  double low_share = 0.5;      ///< a region vertex lower than this share of the step is background-like
};

struct BackgroundInside {
  bool measured = false;       ///< false: no ring (the region covers its component) or too few vertices
  /// BackgroundInsideCheck: the region could be checked (its screen or a fill measured it), even if
  /// nothing deep was seen and `measured` stays false.
  bool checked = false;
  double seconds = 0;          ///< time taken
  /// The largest low piece touching the outside, by depth: its depth (inradius) and area, and a
  /// vertex at its deepest point (-1: none).
  double depth = 0, area = 0;
  int deepest_vertex = -1;
  /// #V: the low piece each region vertex belongs to (-1: none), and per piece its depth, or -1
  /// for a piece that does not touch the outside (a hollow inside the relief).
  std::vector<int> piece;
  std::vector<double> piece_depth;
  /// The region without the low pieces touching the outside deeper than `depth` (mesh units).
  std::vector<char> region_without(const std::vector<char>& region, double depth) const;
};

/// region: #V flags (1 = relief side). h: the segmentation's step height; step: the step found along
/// the contour (the low threshold is low_share x step). solver: the thin-plate fill for this mesh
/// (reused across calls; required for the ThinPlate model, else unused).
BackgroundInside measure_background_inside(const Mesh& mesh, const std::vector<char>& region, double h, double step,
                                           const BackgroundSolver* solver,
                                           const BackgroundInsideOptions& options = {});

/// A piece deep enough to be background taken in: deeper than `limit` and holding at least half the
/// area of a disk that deep (edge distances overstate a small piece's depth on a coarse mesh). In any
/// consistent units: mesh units and squared mesh units, or h and h^2.
bool deep_background_piece(double depth, double area, double limit);

/// The check as the segmenter runs it, owning the fills' precomputation for one mesh. A robust ring
/// quadric screens (a pass over the ring; each fill is a sparse solve, as much as the snake on a large
/// relief); only if it sees a piece deeper than `limit` (mesh units), or cannot measure, is the region
/// measured under the height-field fill (cotangent weights, uniform ones where those are singular). A
/// piece deep there must also show under the fill of the positions (BackgroundModel::Surface, which
/// follows a vase the height field misses): the shallower depth and its area are kept, with the height
/// field's pieces and deepest vertex. measured is false when the screen saw nothing deep; checked is
/// true whenever the screen or a fill could measure the region.
///
/// A second opinion where the screen saw a deep piece and the fill did not, on a textured ring
/// (TexturedOpinion): a fill held to a textured ring continues the texture's slopes under a wide
/// region and can sag or lift by half a step over a bridged C's inside (random scan 5018: the inside
/// read 0.4 h above it). The same two fills again, fitted softly over the whole ring with a longer
/// smoothing length (as relief_mask.hpp's fill is); a piece deep under both is kept as above. On a
/// smooth ring the soft fill has no texture to ride over and only loses the curvature the exact fill
/// follows (a vase, waves, an edge groove): there it is not asked.
struct TexturedOpinion {
  double smoothing = 0;  ///< the soft fill's smoothing length, in h (0: no second opinion)
  /// Asked only where the ring's roughness (its residual from local quadrics, as the step evidence
  /// measures it: StepEvidence::background_quadric_residual) is at least this share of the step.
  double min_roughness = 0.1;
  bool operator==(const TexturedOpinion& o) const { return smoothing == o.smoothing && min_roughness == o.min_roughness; }
};

class BackgroundInsideCheck {
 public:
  /// fill: the fills' common options (their smoothing and soft band); each fill sets its own
  /// Laplacian and model on top.
  explicit BackgroundInsideCheck(const Mesh& mesh, const BackgroundOptions& fill = {}, const TexturedOpinion& textured = {})
      : mesh_(mesh), fill_(fill), textured_(textured) {}
  /// roughness: the ring's roughness, in mesh units (for the textured opinion; 0: smooth).
  BackgroundInside measure(const std::vector<char>& region, double h, double step, double limit, double roughness = 0);
  const BackgroundOptions& fill_options() const { return fill_; }
  const TexturedOpinion& textured_opinion() const { return textured_; }

 private:
  // One opinion's solvers, each built when first needed: the height field with cotangent and with
  // uniform weights, and the positions' fill.
  struct Fills {
    std::unique_ptr<BackgroundSolver> cotangent, uniform, surface;
  };
  const BackgroundSolver& solver(std::unique_ptr<BackgroundSolver>& slot, const BackgroundOptions& options);
  const Mesh& mesh_;
  BackgroundOptions fill_;
  TexturedOpinion textured_;
  Fills fills_, textured_fills_;
};

}  // namespace relief_snake

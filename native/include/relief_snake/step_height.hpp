#pragma once
// Estimating the step height h (and, for open contours, the relief's side) from the
// picks and the surface (not in the paper, which asks the user to measure h).
//
// The picks are on the background around the relief, so the surface along the
// initial contour samples the background. A smooth background (a quadratic height
// field over the contour's best-fitting plane) is fitted to it and continued under
// the relief; the heights of the vertices the contour encloses above it fall into
// two groups, background near zero and relief, split at Otsu's threshold. The
// relief group's median height is the estimate. This is a first guess: segment()
// measures the step along the contour it finds and refits h from that (evidence.hpp).
//
// When the segmentation at the first guess fails its self-check (or finds no step), segment()
// tries further guesses (alternative_step_heights()): a quadric over a plane cannot follow a
// vase's swell or a wave across a large contour, and the heights then do not split at the step.
// The background is the thin-plate fill (background.hpp) of the surface outside the contour,
// continued under it (closed contours), or of the picks' side continued under the whole relief side
// (open ones, whose heights are then taken over a strip along the picks three times as wide as the
// first estimate's); for open contours the quadric over that wider strip follows.
#include <string>
#include <vector>

#include "relief_snake/initial_contour.hpp"
#include "relief_snake/mesh.hpp"

namespace relief_snake {

struct StepHeightOptions {
  int band_rings = 2;              ///< background samples: the path's faces' corners and this many rings around
  int histogram_bins = 128;
  double min_separation = 0.5;     ///< Otsu's between-class share of the variance below which the estimate is unsure
  double strip_share = 0.1;        ///< open contours: the strip compared on each side, as a share of the contour's length
  double fill_scale_edges = 3;     ///< further guesses, closed: the fill's length scale (ring 3x, smoothing 0.5x), in edges
  double wide_strip_share = 0.3;   ///< further guesses, open: the wider strip
  /// Open contours: decide the relief side (the side that rises) and measure h on it; false: the
  /// side is the caller's (inside_left, the user's --relief-side) and h is measured on that side.
  bool decide_side = true;
};

struct StepHeightEstimate {
  double value = 0;         ///< the estimated h (0: no relief found inside)
  double confidence = 0;    ///< 0..1: how clearly the heights split into background and relief
  double background_residual = 0;  ///< RMS residual of the background fit along the contour
  bool relief_left = true;  ///< open contours: the side that rises (closed: as given)
  double left_rise = 0, right_rise = 0;  ///< open contours: the 90% height on each side
};

/// The background samples along a path: the corners of its faces and `rings` rings of vertices around them.
std::vector<int> contour_band_vertices(const Mesh& mesh, const SurfacePath& path, int rings);

/// path: the initial contour (picks joined, open ones extended to the boundary).
/// inside_left: closed contours' enclosed side (contour_orientation_left()); for open contours the
/// relief side when options.decide_side is false, else ignored and decided here (the side that rises).
StepHeightEstimate estimate_step_height(const Mesh& mesh, const SurfacePath& path, bool closed, bool inside_left,
                                        const StepHeightOptions& options = {});

/// The largest step height a relief picked along `path` can plausibly have: a quarter of the
/// contour's size (its length / pi closed, / 2 open). A larger estimate is unsure, larger further
/// guesses are not tried, and segment() does not refit h above it: a step measured with a ball that
/// large reads the background's own curvature as a step, and each refit then measured a larger one
/// (random scan 28, a band on a vase: h 10.5 -> 17.9 -> 28.1 against a true 2.2).
double largest_plausible_step_height(const Mesh& mesh, const SurfacePath& path, bool closed);

/// A further guess of h, and where it came from (for the result's notes).
struct StepHeightGuess {
  double value = 0;
  std::string source;
};

/// Further guesses of h, in the order to try them (none <= 0, none over a quarter of the contour's
/// size: length / pi closed, / 2 open): the median and the 90% height of the relief group over the
/// thin-plate fill of the background (closed: the region the contour encloses; open: the relief
/// side, measured over the wider strip), and for open contours the same over the quadric of the
/// wider strip and the 90% height of the relief side the first estimate measured. relief_left: the
/// side decided or named (open) or enclosed (closed). Costs one sparse solve over the enclosed
/// region or the relief side (0.1 to 0.7 s on the randomized suite's scans), so segment() asks only
/// when the first guess failed.
std::vector<StepHeightGuess> alternative_step_heights(const Mesh& mesh, const SurfacePath& path, bool closed,
                                                      bool relief_left, const StepHeightEstimate& first,
                                                      const StepHeightOptions& options = {});

}  // namespace relief_snake

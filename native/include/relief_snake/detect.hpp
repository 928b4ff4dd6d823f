#pragma once
// Automatic detection: proposes the reliefs of a region without picks (issue 13, part 2b).
//
// 1. Background: a polynomial height field over the region's best-fit plane, fitted to all of
//    the region's vertices by iteratively reweighted least squares (Tukey's biweight,
//    height_statistics.hpp): reliefs stand clearly above it and end with weight 0.
// 2. Threshold: Otsu's split of the area-weighted height histogram; while the lower class itself
//    splits into background and a lower relief level standing clear of the noise, the threshold
//    moves down to that split (so a low relief beside a tall one is not lost). Candidates are
//    taken at half that level (a noisy low relief's top straddles it), never below
//    min_height_sigmas robust noise sigmas.
// 3. Candidates: connected components above the threshold of at least min_area. A component
//    whose heights fall into two clearly separate plateaus (reliefs of different heights that
//    touch) is split into them: the upper plateau's components, and the lower plateau's after an
//    opening that removes the thin band of the taller relief's wall.
// 4. Refinement: each candidate is segmented by the snake from its own outline (picks along the
//    boundary of the candidate grown by outline_offset h, not into other candidates), with h the
//    candidate's median height, through the normal Segmenter (self-check, h refit). Candidates
//    whose regions coincide (IoU > duplicate_iou) are kept once; other overlaps are reported.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "relief_snake/mesh.hpp"
#include "relief_snake/multi_segment.hpp"
#include "relief_snake/segment.hpp"

namespace relief_snake {

/// DetectOptions::background_degree: chosen by the fit.
constexpr int kAutoDegree = -1;

struct DetectOptions {
  /// Smallest relief area kept, in mesh units squared; 0 (the default): (12 average edges)^2, the
  /// smallest outline the snake resolves comfortably (a disk about 13 edges across).
  double min_area = 0;
  /// Total degree of the background polynomial (2: a quadric), or kAutoDegree: 2, 4 and 6 are
  /// fitted and the lowest degree whose robust noise sigma is within 10% of the best is kept.
  int background_degree = -1;
  int robust_iterations = 12;     ///< reweighting rounds at most
  int histogram_bins = 256;
  double min_height_sigmas = 5;   ///< the threshold is at least this many robust noise sigmas above the fit
  /// A component splits into plateaus when Otsu's split of its heights separates this share of
  /// their variance and the upper plateau's median is at least plateau_ratio times the lower's.
  double plateau_separation = 0.6;
  double plateau_ratio = 1.4;
  bool refine = true;             ///< run the snake on each candidate (false: the thresholded components only)
  double outline_offset = 3;      ///< the initial contour runs this far outside the candidate, in its h (>= 3 edges)
  double pick_spacing = 2;        ///< picks along that outline this far apart, in its h (>= 4 edges)
  /// h tried in turn (times the candidate's median height) until the self-check holds, keeping
  /// the best score; only when segment.step_height is kAuto.
  std::vector<double> retry_factors = {1.0, 1.3, 1.7};
  double retry_below = 0.6;       ///< ... and only while the score stays below this
  double duplicate_iou = 0.5;     ///< refined regions overlapping more than this are one relief
  /// The snake's options. step_height kAuto (default): each candidate's median height.
  Options segment;
  MultiSegmentOptions overlap;
};

/// The robust background fit over the region, and the threshold chosen.
struct DetectBackground {
  int degree = 0;
  double sigma = 0;           ///< robust noise level of the heights (1.4826 x median |height|)
  double threshold = 0;       ///< heights above it are candidate relief
  double otsu_threshold = 0;  ///< Otsu's first split of all the heights
  double separation = 0;      ///< its between-class share of the variance
  double inlier_share = 0;    ///< area share of the region fitted with weight > 0
  int iterations = 0;
  std::size_t region_vertices = 0;
};

struct DetectCandidate {
  std::vector<std::int64_t> component;  ///< input vertex indices above the threshold (sorted)
  double area = 0;                      ///< the component's area
  double height = 0;                    ///< its median height above the background (the h it is refined with)
  int plateau = 0;                      ///< 0: a whole component; 1 / 2: lower / upper plateau of a split one
  std::vector<std::int64_t> picks;      ///< the outline picks the snake started from (input indices)
  std::vector<Vec3> outline;            ///< the grown candidate's boundary the picks were taken from (file coordinates)
  GroupOutcome refined;                 ///< the snake's result (refined.ok false: refine off, or the error)
  /// 0..1: refined: the contour's step share x the area IoU of the refined region with the
  /// component (two independent views agreeing); not refined: 0.
  double score = 0;
};

struct DetectResult {
  DetectBackground background;
  std::vector<DetectCandidate> candidates;  ///< sorted by area, largest first
  std::vector<ReliefOverlap> overlaps;      ///< between refined regions (indices into candidates)
  std::vector<std::string> notes;
  double seconds = 0;
  bool cancelled = false;
};

/// region_vertices: input vertex indices to search (empty: the whole mesh). Throws Error on bad
/// options or indices; a region without relief gives no candidates. progress(candidate, p): first
/// p.phase "background" before each background fit (p.iteration: the fits done; candidate 0), then
/// "candidates" once the components are known (p.iteration: how many; candidate 0), then the
/// snake's progress while candidate `candidate` is refined. Returning false cancels (cancelled set).
DetectResult detect(Segmenter& segmenter, const Mesh& mesh, const std::vector<std::int64_t>& region_vertices,
                    const DetectOptions& options = {}, const GroupProgressCallback& progress = {});

}  // namespace relief_snake

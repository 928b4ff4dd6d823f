#pragma once
// Settling the final contour at the foot of the step (not in the paper). The
// relief-step feature energy holds the snake where the planarity of the concave
// crease peaks; on a blended step that is part of the way up the slope, and the
// smaller h is against the true step, the higher (the planarity ball sees less of
// the background). The foot itself is where the surface leaves the background:
// continue the background from outside the snake and move each snaxel out to
// where the surface meets it.
#include "relief_snake/snake.hpp"

namespace relief_snake {

struct FootOptions {
  double h = 0;              ///< the step height given by the user
  double band_from = 0.8;    ///< the background is fitted over [band_from, band_to] h outside each snaxel
  double band_to = 1.6;
  double max_residual = 0.1; ///< skip a snaxel whose background band deviates more than this (in h) from its fit
  int smoothing = 3;         ///< the moves are median-filtered over this many snaxels on each side
  /// No snap at all when the background's median residual (in h) exceeds this: noise then
  /// hides the foot (measured: the snap made the contour worse at noise 0.03 h).
  double max_noise = 0.005;
  /// No snap at all when more than this share of the snaxels has no clean background band outside:
  /// moving the rest alone makes the contour jagged (measured on the real eyebrow scan).
  double max_unclean_share = 1.0;
  /// Pool each snaxel's profile with those of the `pool` snaxels on each side along the snake (the
  /// median per sample) before fitting the band and finding the foot: noise and texture that differ
  /// from one profile to the next fall out, so the foot shows through them (0: each snaxel alone).
  int pool = 0;
  /// The toe (not in the paper): a blend tangent to the background (a smoothstep, a fillet) leaves it
  /// along a quadratic toe, so the surface only clears the threshold some way inside the true foot (on
  /// the randomized suite's blended steps, 1.5 to 2 edges of 10). With `toe`, the profile is also read
  /// up to `toe_inner` h inwards of the snaxel, and the square root of the rise above the background,
  /// over the samples from the threshold crossing inwards that rise less than `toe_cap` h, is fitted
  /// by a line against their distance across the background (not walked along the surface, which up
  /// the blend's slope stretches): where it meets zero is the foot (never inside the crossing, never
  /// into the band).
  /// A straight ramp's square root bends the other way, so the line stops short of its foot.
  bool toe = false;
  double toe_inner = 0.3;
  double toe_cap = 0.25;
  int toe_min_samples = 3;  ///< fewer samples in the toe: the crossing stands
};

struct FootResult {
  int moved = 0;             ///< snaxels moved out to the foot
  int skipped = 0;           ///< snaxels left alone (no clean background outside, mesh boundary, open ends)
  double mean_move = 0;      ///< mean distance moved (of the moved ones)
  double background_residual = 0;  ///< median residual of the background fits
  bool noisy = false;        ///< nothing moved: the background is too noisy
  bool unclean = false;      ///< nothing moved: too few snaxels have a clean background outside
  int toe_fitted = 0;        ///< snaxels whose foot the toe's fit placed (FootOptions::toe)
};

/// Down a sharp step's wall (not in the paper). A sharp step one triangle wide stands on faces that
/// rise the whole of h within one edge: with many edges per h the wall is tall, and the snake,
/// settled where the planarity's crease peaks, rests up to about an edge up it (measured on the
/// randomized suite: a median 0.9 to 1.1 edges above the base on the sharp steps, 10 to 12 edges per
/// h, that missed the one-edge mark). The foot is the wall's lower edge.
struct WallOptions {
  double max_cosine = 0.5;      ///< a wall face's normal is more than 60 degrees from the background's
  double min_height_edges = 1;  ///< and its relief corners stand at least this many average edges above the others
  /// Only a snaxel standing at least this many average edges above the wall's foot moves: lower down,
  /// the foot's horizontal offset from the true boundary (up to an edge on a wall one triangle wide)
  /// outweighs the height (measured: on seed 1166, a wall 3.2 edges tall, moving snaxels 0.1 edges
  /// up down to the foot took the mean distance from 0.98 to 1.00 edges).
  double min_snaxel_height_edges = 0.5;
  double keep = 0.1;            ///< the share of a snaxel's weight on relief corners kept (the rest moves down)
};

struct WallResult {
  int moved = 0;                ///< snaxels moved down a wall
};

/// Moves each snaxel of `contour` that lies on a wall face (a face with corners both in and out of
/// `region`, #V flags, steep against the background normal, taken from the faces round its outside
/// corners that lie wholly outside) down towards the face's outside corners: the weights of its
/// relief corners are scaled by `keep`. The snaxel stays in its face, so the region is unchanged.
WallResult settle_down_walls(const Mesh& mesh, std::vector<SurfacePoint>* contour, const std::vector<char>& region,
                             const WallOptions& options = {});

/// For each snaxel of `snake`, walks outwards along the surface, fits the background
/// (a quadratic profile over the band, a straight one where the band shows no significant
/// curvature) and finds the outermost point inside the band where the surface rises above
/// it by more than a threshold (4 times the standard deviation of the fit's prediction there:
/// the band's residual, grown by the fit's leverage where it is extrapolated; at least
/// 0.02 h): the foot. Moves the snaxel out to it (median-filtered
/// along the snake). Snaxels with no clean background band are left where they are.
FootResult settle_at_foot(Snake* snake, const FootOptions& options);

}  // namespace relief_snake

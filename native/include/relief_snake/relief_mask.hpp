#pragma once
// The relief as the background model sees it (not in the paper): the vertices that stand above the
// background filled in under a region from around it (background.hpp, Liu et al. 2007), and a start
// for the snake just outside them.
//
// A snake from the picks must cross the background and explore every concavity by deflation; on a
// textured background (striations, stamped dots) the planarity of the texture holds it short, and
// a gear's slots or a C's gap are bridged. The heights do not care: texture stands at most a few
// tenths of the step, the relief a whole step. So, from a region that roughly covers the relief (the
// coarse contour's, with the refined one's):
// 1. the region grown by `grow` h along edges, so that relief the region cut off lies under the fill,
//    not in the ring it is fitted to;
// 2. the background filled in under it, and each vertex's height above it;
// 3. the mask: vertices at least `level` x the step above it, the component that overlaps the seed
//    most (small islands of texture or noise dropped);
// 4. steps 1-3 again from the mask (the ring then lies right round the relief);
// 5. the start: the mask grown by `margin` h along edges, whose outer boundary loop the snake is
//    refined from (segment.cpp). It reaches into every concavity the heights show, a little outside
//    the step's foot, so refinement only has to settle on the step.
#include <string>
#include <vector>

#include "relief_snake/background.hpp"
#include "relief_snake/mesh.hpp"

namespace relief_snake {

struct ReliefMaskOptions {
  double level = 0.5;       ///< a vertex is relief when it stands this share of the step above the background
  double grow = 1.0;        ///< the region filled under: the seed (then the mask) grown by this, in h (>= grow_edges)
  double grow_edges = 3;
  int passes = 2;           ///< fills: from around the seed, then from around the mask
  double margin = 0.75;     ///< the start region: the mask grown by this, in h (>= margin_edges)
  double margin_edges = 2;
  /// The mask's component must cover at least this share of the seed's area (a closed contour's seed
  /// is about the relief; an open one's is the whole relief side, so 0 there) ...
  double min_share = 0.2;
  double min_area = 2;      ///< ... and at least this area, in h^2
  /// The fill: the whole ring fitted softly with a long smoothing length, so that a textured ring's
  /// slopes are not continued under the relief (a thin-plate fill held to them tilts by a step).
  BackgroundOptions background = [] {
    BackgroundOptions o;
    o.ring_width = 3;
    o.smoothing = 1.5;
    o.smoothing_band = 3;
    return o;
  }();
};

struct ReliefMask {
  bool ok = false;
  std::string failure;             ///< why not, when !ok (a fill failed, nothing stands above the level)
  std::vector<char> mask;          ///< #V: the relief as the heights see it (one connected component)
  std::vector<char> start_region;  ///< #V: the mask grown by the margin
  std::vector<double> height;      ///< #V: height above the last fill (its region and ring; 0 elsewhere)
  std::vector<Vec3> base_normals;  ///< #V: the last fill's base normals
  double level = 0;                ///< the height threshold used (mesh units)
  double ring_residual = 0;        ///< the last fill's ring residual (RMS, mesh units)
  double seconds = 0;
};

/// The start of a snake from a region (#V flags): the outer boundary loop of its faces (region.hpp,
/// region_outer_loop: the region on its left). closed = false: the longest stretch of that loop off
/// the mesh boundary, with a boundary vertex at each end (the open contour of a relief that runs off
/// the mesh). Empty when there is none (fewer than `min_vertices`).
std::vector<int> start_outline(const Mesh& mesh, const std::vector<char>& region, bool closed, int min_vertices = 8);

/// seed: #V flags roughly covering one relief. h: the step height the snake ran with (sets the ring,
/// the growth and the margin); step: the step to threshold at (level x step; the step found along
/// the contour, or h).
ReliefMask relief_mask(const Mesh& mesh, const std::vector<char>& seed, double h, double step,
                       const ReliefMaskOptions& options = {});

}  // namespace relief_snake

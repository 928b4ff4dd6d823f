#pragma once
// Inner holes of a closed relief (issue 13; not in the paper): background islands inside the
// outer contour, such as the counters of the letters A, B, D, O or the openings of a crest.
//
// After the outer contour settles, the heights of the region's vertices above the background
// are looked at. A cheap screen first (a quadric height field fitted to a ring of background
// outside the contour): a plain relief has no low vertex away from its own foot, and the search
// ends there. Otherwise the extraction's background (background.hpp, a thin-plate fill from the
// ring) gives the heights, and every connected set of region vertices near the background
// (below low_level h, median below island_median h) that does not reach the outer contour, covers at least min_hole_area h^2 and
// is surrounded by relief (the rim rises above rim_level h) is an island. Each island is
// segmented by its own snake, started on the island's outline (eroded by up to an h so it
// starts on the floor), facing outwards: the relief lies outside a hole's contour, so the
// snake's relief side is away from the island. Hole picks (Options::hole_picks) replace the
// search: each is joined like outer picks and evolved the same way.
//
// Each hole's contour gets its own evidence (evidence.hpp's measure_step, with the hole's
// floor as the outside) and verdict; a hole that fails it makes the result doubtful.
#include <string>
#include <vector>

#include "relief_snake/evidence.hpp"
#include "relief_snake/mesh.hpp"
#include "relief_snake/planarity.hpp"
#include "relief_snake/segment.hpp"
#include "relief_snake/surface_point.hpp"

namespace relief_snake {

struct HoleSearchOptions {
  double ring_width = 3;      ///< background ring outside the outer contour, in h (the screen's quadric fit)
  double screen_level = 0.45; ///< the screen: region vertices below this height (in h) may be holes ...
  double screen_median = 0.25;  ///< ... in sets whose median height is below this (in h; a relief whose top drops
                                ///< to 0.3 h inside its edge is no hole)
  double low_level = 0.2;     ///< an island: region vertices below this height (in h) above the fitted background ...
  double island_median = 0.1; ///< ... whose median height is below this (in h): the floor is background
  double rim_level = 0.5;     ///< the 75% height of the relief around an island must exceed this (in h)
  double rim_width = 2;       ///< ... measured over this distance (in h) around the island
  double min_area = 4;        ///< smaller islands are ignored, in h^2 (Options::min_hole_area)
  int max_holes = 64;         ///< at most this many islands are segmented (the largest)
};

/// One hole's outcome.
struct HoleOutcome {
  std::vector<SurfacePoint> contour;  ///< final snaxels; the relief lies outside (on the snake's relief side)
  std::vector<char> interior;         ///< #V: 1 for vertices inside the hole
  bool from_picks = false;
  ContourEvidence evidence;
  SelfCheck check;
  double area = 0;                    ///< area of the interior's vertices
  double island_area = 0;             ///< area of the island it started from (0 from picks)
  int attempts = 0;                   ///< refinements tried (W_int values)
  /// Its contour left the relief (it took in the background round the relief, or most of the
  /// relief): it is reported, with its check failing, but not cut out of the region.
  bool leaked = false;
};

struct HoleSearch {
  std::vector<HoleOutcome> holes;
  int screened = 0;                   ///< low sets the quadric screen found (0: no background fill was needed)
  int ignored_small = 0;              ///< low sets of 1 h^2 up to min_area (smaller ones are not counted)
  int ignored_no_rim = 0;             ///< low sets not down at the background or without relief around them
  bool cancelled = false;
  std::vector<std::string> notes;
  double seconds = 0;
};

/// Checks Options::hole_picks against the mesh (before any work); throws Error with advice.
void validate_hole_picks(const Mesh& mesh, const Options& options, int component);

/// Finds and segments the holes of a closed relief. region: #V flags of the outer contour's region
/// (holes are cleared from it). h: the step height used. The planarity field must be built for h.
HoleSearch segment_holes(const Mesh& mesh, PlanarityField& planarity, const Options& options, double h,
                         std::vector<char>* region, const ProgressCallback& progress = {},
                         const HoleSearchOptions& search = {});

/// Puts a search's holes into a result: contours, polylines and checks of the holes that have a
/// contour; a failed hole's reasons ("hole k: ...") go to check->reasons and clear check->holds.
void add_holes(const Mesh& mesh, const HoleSearch& search, Result* result, SelfCheck* check);

/// The outline of a vertex set as a closed surface path (the longest boundary loop of the faces
/// whose corners are all in the set), running counter-clockwise around the set seen from outside
/// (the set on the left). Empty if the set has no such face.
std::vector<SurfacePoint> vertex_set_outline(const Mesh& mesh, const std::vector<char>& set);

}  // namespace relief_snake

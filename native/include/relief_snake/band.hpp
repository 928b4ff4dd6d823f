#pragma once
// Cyclic reliefs (issue 13; not in the paper): a frieze that runs right round a surface of
// revolution, or an engraved band, bounded by two closed contours that do not enclose a disc.
//
// The user picks two rings (Options::picks the first, Options::band_picks the second): for a
// frieze on the background on each side of it, for an engraved band (a groove) on its floor near
// each wall. Each ring is joined like an open contour's picks (plane sections, last pick back to
// the first, no disc test) and evolved by its own snake (schedule.hpp) towards the step that rises
// beside it: towards the other ring for a frieze, away from it for a groove. Which it is, is
// measured at the rings (the step seen on each side, evidence.hpp's local planes); rings that
// cross are refused. The band is what lies towards the other ring from both final contours. Each
// contour has its own evidence and verdict; the result is doubtful when either fails.
//
// h: given, or the step measured beside the rings, then refitted from the step found along both
// final contours like a closed relief's (at most twice).
#include <functional>
#include <vector>

#include "relief_snake/initial_contour.hpp"
#include "relief_snake/mesh.hpp"
#include "relief_snake/planarity.hpp"
#include "relief_snake/segment.hpp"

namespace relief_snake {

/// The planarity field for a step height (built or reused by the Segmenter); start: the contour
/// its bilateral sigma is sampled along when it is built.
using PlanarityProvider = std::function<PlanarityField&(double h, const std::vector<SurfacePoint>& start)>;

/// A closed ring through the picks (mesh vertex indices, >= 3), each leg a plane section (shortest
/// edge path as fallback), the last pick joined back to the first. Unlike initial_contour() the
/// ring need not enclose a disc.
SurfacePath ring_path(const Mesh& mesh, const std::vector<int>& picks);

/// Segments the band between two pick rings (mesh vertex indices). Result::contour is the first
/// ring's final contour, Result::band_contour the second's; relief_vertices lie between them.
/// Throws Error when the rings cross, or a snake collapses without meeting a step.
Result segment_band(const Mesh& mesh, const std::vector<int>& first_ring, const std::vector<int>& second_ring,
                    const Options& options, const PlanarityProvider& planarity,
                    const ProgressCallback& progress = {});

}  // namespace relief_snake

#pragma once
// Cyclic reliefs (issue 13; not in the paper): a frieze that runs right round a surface of
// revolution, or an engraved band, bounded by two closed contours that do not enclose a disc.
//
// The user picks two rings, one on the background on each side of the band (Options::picks
// the first, Options::band_picks the second). Each ring is joined like an open contour's picks
// (plane sections, last pick back to the first, no disc test) and evolved by its own snake
// (schedule.hpp) towards the relief: its relief side is the side the other ring lies on (which
// ring is which tells it; rings that cross are refused). The relief region is what lies on the
// relief side of both final contours. Each contour has its own evidence and verdict
// (evidence.hpp); the result is doubtful when either fails.
//
// h: given, or estimated from the step measured at the first ring's picks (local planes,
// evidence.hpp), then refitted from the step found along both final contours like a closed
// relief's (at most twice).
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

#pragma once
// Several reliefs in one call: one snake per pick group on one Segmenter (so the planarity
// computed for one h is reused by every group with the same h), and the overlaps between the
// regions found. Overlaps are reported, never merged: each result keeps its own region, and a
// result that shares more than max_overlap_share of its area with another becomes doubtful,
// with a reason naming the other relief.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "relief_snake/mesh.hpp"
#include "relief_snake/segment.hpp"

namespace relief_snake {

struct MultiSegmentOptions {
  /// A result sharing more than this share of its region's area with another relief's region is doubtful.
  double max_overlap_share = 0.02;
};

/// Two reliefs whose regions share vertices.
struct ReliefOverlap {
  std::size_t a = 0, b = 0;          ///< indices of the two reliefs (a < b)
  std::size_t shared_vertices = 0;   ///< input vertices in both regions
  double shared_area = 0;            ///< their vertex area
  double share_of_a = 0, share_of_b = 0;  ///< shared_area over each region's area
};

/// One pick group's outcome: a result, or the error that stopped it (the other groups go on).
struct GroupOutcome {
  bool ok = false;
  Result result;           ///< when ok
  std::string error;       ///< when not ok: the engine's one-line message
  double seconds = 0;      ///< this group's engine time
};

struct MultiResult {
  std::vector<GroupOutcome> reliefs;     ///< one per group, in the groups' order
  std::vector<ReliefOverlap> overlaps;   ///< every pair of ok results that share a vertex
  bool cancelled = false;                ///< the progress callback stopped the run (reliefs hold what finished)
};

/// Progress of group `group` (0-based); return false to cancel.
using GroupProgressCallback = std::function<bool(std::size_t group, const Progress& progress)>;

/// The overlaps between regions (relief_vertices: sorted input indices, as Result holds them).
std::vector<ReliefOverlap> region_overlaps(const Mesh& mesh, const std::vector<const std::vector<std::int64_t>*>& regions);

/// Marks results whose overlap exceeds options.max_overlap_share as doubtful, with a reason.
void report_overlaps(std::vector<GroupOutcome>* reliefs, const std::vector<ReliefOverlap>& overlaps,
                     const MultiSegmentOptions& options = {}, const char* noun = "relief");

/// Segments each group of picks (input vertex indices, as Segmenter::segment takes) with the
/// same options. An Error from one group (bad picks, a collapsed snake) is recorded in its
/// outcome; the others still run. Throws Error only when groups is empty.
MultiResult segment_many(Segmenter& segmenter, const Mesh& mesh, const std::vector<std::vector<std::int64_t>>& groups,
                         const Options& options, const GroupProgressCallback& progress = {},
                         const MultiSegmentOptions& multi = {});

}  // namespace relief_snake

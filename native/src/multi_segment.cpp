// Several pick groups on one Segmenter, and the overlaps between their regions.
#include "report_text.hpp"
#include "relief_snake/multi_segment.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "relief_snake/error.hpp"

namespace relief_snake {

namespace {
std::string percent(double share) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f%%", 100 * share);
  return text;
}
}  // namespace

std::vector<ReliefOverlap> region_overlaps(const Mesh& mesh, const std::vector<const std::vector<std::int64_t>*>& regions) {
  auto area_of = [&](std::int64_t input) {
    const int v = mesh.input_to_mesh(static_cast<std::size_t>(input));
    return v >= 0 ? mesh.vertex_area(v) : 0.0;
  };
  std::vector<double> areas;
  for (const auto* r : regions) {
    double a = 0;
    for (const std::int64_t i : *r) a += area_of(i);
    areas.push_back(a);
  }
  std::vector<ReliefOverlap> out;
  for (std::size_t a = 0; a < regions.size(); ++a)
    for (std::size_t b = a + 1; b < regions.size(); ++b) {
      std::vector<std::int64_t> shared;
      std::set_intersection(regions[a]->begin(), regions[a]->end(), regions[b]->begin(), regions[b]->end(),
                            std::back_inserter(shared));
      if (shared.empty()) continue;
      ReliefOverlap o;
      o.a = a, o.b = b;
      o.shared_vertices = shared.size();
      for (const std::int64_t i : shared) o.shared_area += area_of(i);
      o.share_of_a = areas[a] > 0 ? o.shared_area / areas[a] : 0;
      o.share_of_b = areas[b] > 0 ? o.shared_area / areas[b] : 0;
      out.push_back(o);
    }
  return out;
}

void report_overlaps(std::vector<GroupOutcome>* reliefs, const std::vector<ReliefOverlap>& overlaps,
                     const MultiSegmentOptions& options, const char* noun) {
  auto mark = [&](std::size_t self, std::size_t other, double share, std::size_t vertices) {
    Result& r = (*reliefs)[self].result;
    const std::string sentence = "the region shares " + std::to_string(vertices) + " vertices (" + percent(share) +
                                 " of its area) with " + noun + " " + std::to_string(other) +
                                 "; the two outlines cross or one holds the other";
    if (share <= options.max_overlap_share) {
      r.notes.push_back(sentence + " (within the " + percent(options.max_overlap_share) + " allowed)");
      return;
    }
    r.reasons.push_back(sentence);
    if (r.status == Status::Converged) r.status = Status::Doubtful;
    r.message = "Check this result: ";
    for (std::size_t k = 0; k < r.reasons.size(); ++k) r.message += (k ? "; " : "") + r.reasons[k];
    r.message += ". Pick each relief's own surroundings, apart from the others.";
  };
  for (const ReliefOverlap& o : overlaps) {
    mark(o.a, o.b, o.share_of_a, o.shared_vertices);
    mark(o.b, o.a, o.share_of_b, o.shared_vertices);
  }
}

MultiResult segment_many(Segmenter& segmenter, const Mesh& mesh, const std::vector<std::vector<std::int64_t>>& groups,
                         const Options& options, const GroupProgressCallback& progress,
                         const MultiSegmentOptions& multi) {
  if (groups.empty()) throw Error("no pick groups given; pass at least one group of picks around a relief");
  if (!(multi.max_overlap_share >= 0 && multi.max_overlap_share <= 1))
    throw Error("max_overlap_share must be in [0, 1]");
  MultiResult out;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    GroupOutcome outcome;
    const auto start = std::chrono::steady_clock::now();
    ProgressCallback forward;
    if (progress) forward = [&progress, g](const Progress& p) { return progress(g, p); };
    try {
      outcome.result = segmenter.segment(groups[g], options, forward);
      outcome.ok = outcome.result.status != Status::Cancelled;
      if (!outcome.ok) out.cancelled = true;
    } catch (const Error& e) {
      outcome.error = e.what();
    }
    outcome.seconds = seconds_since(start);
    if (out.cancelled) break;
    out.reliefs.push_back(std::move(outcome));
  }
  std::vector<const std::vector<std::int64_t>*> regions;
  std::vector<std::size_t> index;
  for (std::size_t g = 0; g < out.reliefs.size(); ++g)
    if (out.reliefs[g].ok) regions.push_back(&out.reliefs[g].result.relief_vertices), index.push_back(g);
  out.overlaps = region_overlaps(mesh, regions);
  for (ReliefOverlap& o : out.overlaps) o.a = index[o.a], o.b = index[o.b];
  report_overlaps(&out.reliefs, out.overlaps, multi);
  return out;
}

}  // namespace relief_snake

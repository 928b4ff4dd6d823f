#pragma once
// The documents for several reliefs (docs/result-format.md): segment with several pick groups
// ("relief-snake-results/1", one result document per relief) and detect ("relief-snake-detect/1",
// one result document per candidate plus its detection record). Each relief's entry is the
// single-result document of result_json.hpp, so a reader of one result reads each entry.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "relief_snake/detect.hpp"
#include "relief_snake/multi_segment.hpp"
#include "relief_snake/result_json.hpp"

namespace relief_snake {

nlohmann::json overlaps_json(const std::vector<ReliefOverlap>& overlaps);

/// One group's entry: the result document, or (failed) a document with status "failed", the
/// error as message and reasons, and empty contour and relief_vertices.
nlohmann::json outcome_json(const GroupOutcome& outcome, const Options& options, const Mesh& mesh,
                            const ResultContext& context);

/// segment with several groups. groups: the picks as given; context: mesh path and times
/// (context.picks is ignored).
nlohmann::json multi_result_json(const MultiResult& result, const std::vector<std::vector<std::int64_t>>& groups,
                                 const Options& options, const Mesh& mesh, const ResultContext& context);

nlohmann::json detect_json(const DetectResult& result, const DetectOptions& options, const Mesh& mesh,
                           const ResultContext& context);

}  // namespace relief_snake

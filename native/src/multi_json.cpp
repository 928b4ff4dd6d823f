// Documents for several reliefs: segment with several pick groups, and detect.
#include "relief_snake/multi_json.hpp"

#include <cmath>

namespace relief_snake {

using nlohmann::json;

json overlaps_json(const std::vector<ReliefOverlap>& overlaps) {
  json out = json::array();
  for (const ReliefOverlap& o : overlaps)
    out.push_back({{"reliefs", {o.a, o.b}},
                   {"shared_vertices", o.shared_vertices},
                   {"shared_area", o.shared_area},
                   {"share", {o.share_of_a, o.share_of_b}}});
  return out;
}

namespace {
json points_json(const std::vector<Vec3>& points) {
  json out = json::array();
  for (const Vec3& p : points) out.push_back({p.x(), p.y(), p.z()});
  return out;
}

json unfinished_json(const std::string& status, const std::string& message, const std::vector<Vec3>& contour,
                     const std::vector<std::int64_t>& vertices, double h, const std::vector<std::int64_t>& picks,
                     const ResultContext& context) {
  return json{{"format", "relief-snake-result/1"},
              {"status", status},
              {"message", message},
              {"reasons", message.empty() ? json::array() : json::array({message})},
              {"closed", true},
              {"relief_side", nullptr},
              {"contour", points_json(contour)},
              {"relief_vertices", vertices},
              {"step_height", {{"used", h}, {"given", nullptr}, {"estimate", h > 0 ? json(h) : json(nullptr)}, {"confidence", 0}}},
              {"parameters", {{"picks", picks}}},
              {"notes", json::array()},
              {"timing", {{"load_seconds", context.load_seconds}, {"segment_seconds", context.segment_seconds}}}};
}
}  // namespace

json outcome_json(const GroupOutcome& outcome, const Options& options, const Mesh& mesh, const ResultContext& context) {
  if (outcome.ok) return to_json(outcome.result, options, mesh, context);
  return unfinished_json("failed", outcome.error, {}, {}, 0, context.picks, context);
}

json multi_result_json(const MultiResult& result, const std::vector<std::vector<std::int64_t>>& groups,
                       const Options& options, const Mesh& mesh, const ResultContext& context) {
  json reliefs = json::array();
  json counts = {{"converged", 0}, {"doubtful", 0}, {"iteration_cap", 0}, {"failed", 0}};
  for (std::size_t g = 0; g < result.reliefs.size(); ++g) {
    ResultContext c = context;
    c.picks = groups[g];
    c.segment_seconds = result.reliefs[g].seconds;
    json entry = outcome_json(result.reliefs[g], options, mesh, c);
    const std::string status = entry["status"];
    counts[status] = counts[status].get<int>() + 1;
    reliefs.push_back(std::move(entry));
  }
  const bool all_converged = counts["converged"].get<int>() == static_cast<int>(result.reliefs.size());
  return json{{"format", "relief-snake-results/1"},
              {"status", all_converged ? "converged" : "doubtful"},
              {"counts", counts},
              {"reliefs", reliefs},
              {"overlaps", overlaps_json(result.overlaps)},
              {"mesh", mesh_report_json(mesh, context.mesh_path)},
              {"timing", {{"load_seconds", context.load_seconds}, {"segment_seconds", context.segment_seconds}}}};
}

json detect_json(const DetectResult& result, const DetectOptions& options, const Mesh& mesh,
                 const ResultContext& context) {
  json candidates = json::array();
  for (const DetectCandidate& cand : result.candidates) {
    ResultContext c = context;
    c.picks = cand.picks;
    c.segment_seconds = cand.refined.seconds;
    json entry;
    if (cand.refined.ok) {
      entry = to_json(cand.refined.result, options.segment, mesh, c);
    } else {
      entry = unfinished_json(options.refine ? "failed" : "unrefined", options.refine ? cand.refined.error : "",
                              cand.outline, cand.component, cand.height, cand.picks, c);
    }
    entry["detection"] = {{"area", cand.area},
                          {"height", cand.height},
                          {"score", cand.score},
                          {"plateau", cand.plateau},
                          {"component_vertices", cand.component.size()},
                          {"outline", points_json(cand.outline)}};
    candidates.push_back(std::move(entry));
  }
  const DetectBackground& b = result.background;
  const double edge = mesh.average_edge_length();
  return json{{"format", "relief-snake-detect/1"},
              {"candidates", candidates},
              {"overlaps", overlaps_json(result.overlaps)},
              {"background",
               {{"degree", b.degree},
                {"sigma", b.sigma},
                {"threshold", b.threshold},
                {"otsu_threshold", b.otsu_threshold},
                {"separation", b.separation},
                {"inlier_share", b.inlier_share},
                {"iterations", b.iterations},
                {"region_vertices", b.region_vertices}}},
              {"parameters",
               {{"min_area", options.min_area > 0 ? options.min_area : std::pow(12 * edge, 2)},
                {"min_area_given", options.min_area > 0},
                {"background_degree", options.background_degree == kAutoDegree ? nlohmann::json("auto")
                                                                                 : nlohmann::json(options.background_degree)},
                {"min_height_sigmas", options.min_height_sigmas},
                {"refine", options.refine},
                {"outline_offset", options.outline_offset},
                {"pick_spacing", options.pick_spacing}}},
              {"notes", result.notes},
              {"mesh", mesh_report_json(mesh, context.mesh_path)},
              {"timing", {{"load_seconds", context.load_seconds}, {"detect_seconds", result.seconds}}}};
}

}  // namespace relief_snake

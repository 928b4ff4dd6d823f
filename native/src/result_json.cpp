// The result document shared by the CLI and the Python module.
#include "relief_snake/result_json.hpp"

#include "relief_snake/option_table.hpp"

namespace relief_snake {

using nlohmann::json;

json mesh_report_json(const Mesh& mesh, const std::string& path) {
  const MeshReport& r = mesh.report();
  return json{{"path", path},
              {"input_vertices", r.input_vertices},
              {"input_faces", r.input_faces},
              {"vertices", mesh.n_vertices()},
              {"triangles", r.triangles},
              {"polygons_triangulated", r.polygons_triangulated},
              {"duplicate_vertices_merged", r.duplicate_vertices_merged},
              {"unreferenced_vertices", r.unreferenced_vertices},
              {"degenerate_faces", r.degenerate_faces},
              {"nonmanifold_faces", r.nonmanifold_faces},
              {"invalid_faces", r.invalid_faces},
              {"invalid_vertices", r.invalid_vertices},
              {"partial_load_notes", r.notes},
              {"components", r.components},
              {"boundary_edges", r.boundary_edges},
              {"average_edge_length", mesh.average_edge_length()},
              {"bbox_diagonal", mesh.bbox_diagonal()},
              {"local_origin", {mesh.origin().x(), mesh.origin().y(), mesh.origin().z()}},
              {"summary", r.summary()}};
}

json to_json(const Result& result, const Options& options, const Mesh& mesh, const ResultContext& context) {
  json contour = json::array();
  for (const Vec3& p : result.polyline) contour.push_back({p.x(), p.y(), p.z()});
  // Whole reliefs (issue 13): the holes' contours and checks, the band's second contour.
  json holes = json::array(), hole_checks = json::array(), band_contour = json::array();
  for (const std::vector<Vec3>& hole : result.hole_polylines) {
    json line = json::array();
    for (const Vec3& p : hole) line.push_back({p.x(), p.y(), p.z()});
    holes.push_back(std::move(line));
  }
  for (const auto& named : result.hole_checks) {
    json c = json::object();
    for (const auto& [name, value] : named) c[name] = value;
    if (c.contains("holds")) c["holds"] = c["holds"].get<double>() != 0;
    if (c.contains("from_picks")) c["from_picks"] = c["from_picks"].get<double>() != 0;
    hole_checks.push_back(std::move(c));
  }
  for (const Vec3& p : result.band_polyline) band_contour.push_back({p.x(), p.y(), p.z()});
  json phases = json::array();
  for (const PhaseStats& s : result.phases)
    phases.push_back({{"name", s.name},
                      {"iterations", s.iterations},
                      {"snaxels", s.snaxels},
                      {"seconds", s.seconds},
                      {"converged", s.converged}});
  json parameters = {{"open", !options.closed},
                     {"relief_side", to_string(result.relief_side)},
                     {"picks", context.picks},
                     {"max_iterations", options.max_iterations},
                     {"holes", to_string(options.holes)},
                     {"hole_picks", options.hole_picks},
                     {"min_hole_area", options.min_hole_area},
                     {"band_picks", options.band_picks}};
  for (const OptionInfo& option : advanced_options())
    parameters[option.name] = json::parse(advanced_option_json(options, option.name));
  // The values used (h, W_int and what derives from them), whether given or chosen.
  for (const auto& [name, value] : result.parameters.named_values()) parameters[name] = value;
  json checks = json::object();
  for (const auto& [name, value] : result.checks) checks[name] = value;
  const bool h_given = options.step_height > 0;
  json step_height = {{"used", result.parameters.step_height},
                      {"given", h_given ? json(options.step_height) : json(nullptr)},
                      {"estimate", h_given ? json(nullptr) : json(result.step_height_estimate)},
                      {"confidence", result.step_height_confidence},
                      {"measured", result.step_height_measured > 0 ? json(result.step_height_measured) : json(nullptr)}};
  return json{{"format", "relief-snake-result/1"},
              {"status", to_string(result.status)},
              {"message", result.message},
              {"reasons", result.reasons},
              {"closed", result.closed},
              {"relief_side", result.closed ? json(nullptr) : json(to_string(result.relief_side))},
              {"contour", contour},
              {"relief_vertices", result.relief_vertices},
              {"holes", holes},
              {"hole_checks", hole_checks},
              {"band", !result.band_polyline.empty()},
              {"band_contour", band_contour},
              {"step_height", step_height},
              {"w_int", {{"used", result.parameters.w_int},
                         {"given", options.w_int > 0 ? json(options.w_int) : json(nullptr)}}},
              {"checks", checks},
              {"attempts", result.attempts},
              {"phases", phases},
              {"parameters", parameters},
              {"notes", result.notes},
              {"planarity_vertices", result.planarity_vertices},
              {"mesh", mesh_report_json(mesh, context.mesh_path)},
              {"timing", {{"load_seconds", context.load_seconds}, {"segment_seconds", context.segment_seconds}}}};
}

}  // namespace relief_snake

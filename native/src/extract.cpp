#include "report_text.hpp"
#include "relief_snake/extract.hpp"

#include <chrono>
#include <cstdio>

#include "relief_snake/error.hpp"

namespace relief_snake {

std::vector<char> region_from_input_indices(const Mesh& mesh, const std::vector<std::int64_t>& input_indices,
                                            std::int64_t expected_vertices, std::vector<std::string>* notes) {
  const std::int64_t n = static_cast<std::int64_t>(mesh.input_vertex_count());
  if (expected_vertices >= 0 && expected_vertices != n)
    throw Error("the segmentation result is for a mesh with " + std::to_string(expected_vertices) +
                " vertices but this mesh has " + std::to_string(n) + "; give the mesh the result was made from");
  std::vector<char> region(static_cast<std::size_t>(mesh.n_vertices()), 0);
  std::size_t dropped = 0;
  for (const std::int64_t i : input_indices) {
    if (i < 0 || i >= n)
      throw Error("relief vertex " + std::to_string(i) + " is out of range: the mesh has " + std::to_string(n) +
                  " vertices (indices are 0-based); give the mesh the result was made from");
    const int v = mesh.input_to_mesh(static_cast<std::size_t>(i));
    if (v < 0)
      ++dropped;
    else
      region[v] = 1;
  }
  if (dropped && notes)
    notes->push_back(std::to_string(dropped) + " relief vertices are in no face of the mesh and were skipped");
  bool any = false;
  for (const char c : region) any = any || c;
  if (!any) throw Error("the relief region is empty; segment the relief first");
  return region;
}

std::vector<Vec3> ExtractResult::background_positions(const Mesh& mesh) const {
  std::vector<Vec3> out(static_cast<std::size_t>(mesh.n_vertices()));
  for (int v = 0; v < mesh.n_vertices(); ++v)
    out[v] = mesh.to_file(background.region[v] ? background.base_positions[v] : mesh.position(v));
  return out;
}

std::string ExtractResult::summary() const {
  char text[480];
  std::snprintf(text, sizeof text,
                "extracted %zu relief vertices (%zu faces): heights %.4g to %.4g, ring residual %.3g rms; "
                "height map %d x %d pixels of %.4g (%s); %.2f s (background %.2f s, height map %.2f s)",
                background.region_vertices.size(), relief_triangles.size() / 3, height_map.min_height,
                height_map.max_height, background.ring_rms_residual, height_map.width, height_map.height,
                height_map.pixel_size, to_string(height_map.frame.method), background_seconds + height_map_seconds,
                background_seconds, height_map_seconds);
  return text;
}

std::string ExtractResult::timings_text() const {
  const BackgroundTimings& b = background.timings;
  const FlattenTimings& f = height_map.frame.timings;
  char text[640];
  std::snprintf(text, sizeof text,
                "weights %.3f s, ring %.3f s, assembly %.3f s, ordering %.3f s, factorisation %.3f s, solve %.3f s, "
                "height %.3f s, relief %.3f s, plane %.3f s, conformal assembly %.3f s, conformal ordering %.3f s, "
                "conformal factorisation %.3f s, conformal solve %.3f s, conformal distortion %.3f s, rasterise %.3f s",
                weights_seconds, b.ring, b.assembly, b.ordering, b.factorisation, b.solve, b.height, relief_seconds,
                f.plane, f.conformal_assembly, f.conformal_ordering, f.conformal_factorisation, f.conformal_solve,
                f.conformal_distortion, rasterise_seconds);
  return text;
}

ExtractResult extract(const BackgroundSolver& solver, const std::vector<char>& region, double step_height,
                      const HeightMapOptions& height_map) {
  const Mesh& mesh = solver.mesh();
  ExtractResult x;
  x.step_height = step_height;
  x.background = solver.solve(region, step_height);
  if (!x.background.ok()) throw Error(x.background.message);
  x.background_seconds = x.background.seconds;
  const auto start = std::chrono::steady_clock::now();

  const BackgroundResult& b = x.background;
  std::vector<int> local(static_cast<std::size_t>(mesh.n_vertices()), -1);
  std::vector<int> faces;
  for (int f = 0; f < mesh.n_faces(); ++f) {
    const int a = mesh.face_vertex(f, 0), c = mesh.face_vertex(f, 1), d = mesh.face_vertex(f, 2);
    if (b.region[a] || b.region[c] || b.region[d]) {
      faces.push_back(f);
      local[a] = local[c] = local[d] = 0;
    }
  }
  if (faces.empty()) throw Error("the relief region has no faces; segment a larger region");
  for (int v = 0; v < mesh.n_vertices(); ++v)
    if (local[v] == 0) {
      local[v] = static_cast<int>(x.relief_mesh_vertices.size());
      x.relief_mesh_vertices.push_back(v);
    }
  x.relief_triangles.reserve(3 * faces.size());
  for (const int f : faces)
    for (int k = 0; k < 3; ++k) x.relief_triangles.push_back(local[mesh.face_vertex(f, k)]);
  HeightPatch patch;
  patch.triangles = x.relief_triangles;
  for (const int v : x.relief_mesh_vertices) {
    patch.positions.push_back(b.base_positions[v]);
    patch.heights.push_back(b.height[v]);
  }
  x.relief_heights = patch.heights;
  x.relief_seconds = seconds_since(start);
  const Flattened flat = flatten(patch, height_map);
  x.relief_uv = flat.uv;
  const double pixel = height_map.pixel_size > 0 ? height_map.pixel_size : 0.5 * mesh.average_edge_length();
  const auto raster_start = std::chrono::steady_clock::now();
  x.height_map = rasterise(patch, flat, pixel, height_map);
  x.rasterise_seconds = seconds_since(raster_start);
  x.height_map.frame.origin = mesh.to_file(x.height_map.frame.origin);  // uv are relative to it: unchanged
  if (!flat.note.empty()) x.notes.push_back(flat.note);
  x.height_map_seconds = seconds_since(start);
  return x;
}

ExtractResult extract(const Mesh& mesh, const std::vector<char>& region, double step_height,
                      const ExtractOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const BackgroundSolver solver(mesh, options.background);
  const double weights = seconds_since(start);
  ExtractResult x = extract(solver, region, step_height, options.height_map);
  x.weights_seconds = weights;
  return x;
}

}  // namespace relief_snake

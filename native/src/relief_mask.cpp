// The relief as the background model sees it, and a start just outside it (relief_mask.hpp).
#include "relief_snake/relief_mask.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <string>

#include "relief_snake/mesh_graph.hpp"
#include "relief_snake/region.hpp"

namespace relief_snake {

std::vector<int> start_outline(const Mesh& mesh, const std::vector<char>& region, bool closed, int min_vertices) {
  std::vector<int> loop = region_outer_loop(mesh, region);
  if (static_cast<int>(loop.size()) < min_vertices) return {};
  if (closed) return loop;
  // The longest run of loop vertices off the mesh boundary, and the boundary vertex before and after it.
  const int n = static_cast<int>(loop.size());
  int best_start = -1, best_length = 0;
  for (int k = 0; k < n; ++k) {
    if (mesh.is_boundary_vertex(loop[k]) || !mesh.is_boundary_vertex(loop[(k + n - 1) % n])) continue;
    int length = 0;
    while (length < n && !mesh.is_boundary_vertex(loop[(k + length) % n])) ++length;
    if (length < n && length > best_length) best_start = k, best_length = length;
  }
  if (best_start < 0 || best_length + 2 < min_vertices) return {};
  std::vector<int> path;
  for (int j = -1; j <= best_length; ++j) path.push_back(loop[((best_start + j) % n + n) % n]);
  return path;
}

ReliefMask relief_mask(const Mesh& mesh, const std::vector<char>& seed, double h, double step,
                       const ReliefMaskOptions& options) {
  const auto t_start = std::chrono::steady_clock::now();
  ReliefMask out;
  const int n = mesh.n_vertices();
  auto done = [&](const std::string& failure) {
    out.failure = failure;
    out.ok = failure.empty();
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    return out;
  };
  if (static_cast<int>(seed.size()) != n || !(h > 0) || !(step > 0)) return done("bad input");
  const double edge = mesh.average_edge_length();
  const double grow = std::max(options.grow * h, options.grow_edges * edge);
  out.level = options.level * step;
  double seed_area = 0;
  for (int v = 0; v < n; ++v)
    if (seed[v]) seed_area += mesh.vertex_area(v);
  if (!(seed_area > 0)) return done("empty region");

  std::vector<char> current = seed;
  for (int pass = 0; pass < std::max(1, options.passes); ++pass) {
    // 1-2. The background under the grown region, from a ring round it.
    // Grown across the background once a fill gives its normals (the first pass: straight along edges).
    const BackgroundResult fill = fill_background(
        mesh, grown_region(mesh, current, grow, pass == 0 ? std::function<double(int, int)>{}
                                                            : tangential_length(mesh, out.base_normals)),
        h, options.background);
    if (!fill.ok()) return done("the background could not be filled in: " + fill.message);
    out.ring_residual = fill.ring_rms_residual;
    out.height = fill.height;
    out.base_normals = fill.base_normals;
    // 3. What stands above the level, and its component that overlaps the region most.
    std::vector<char> high(n, 0);
    for (const int v : fill.region_vertices) high[v] = fill.height[v] >= out.level;
    std::vector<int> best;
    double best_overlap = 0, best_area = 0;
    for (std::vector<int>& comp : vertex_components(mesh, high)) {
      double overlap = 0, area = 0;
      for (const int v : comp) {
        area += mesh.vertex_area(v);
        if (current[v]) overlap += mesh.vertex_area(v);
      }
      if (overlap > best_overlap) best_overlap = overlap, best_area = area, best = std::move(comp);
    }
    if (best.empty() || best_area < options.min_share * seed_area || best_area < options.min_area * h * h)
      return done("too little of the region stands half a step above the background");
    std::vector<char> mask(n, 0);
    for (const int v : best) mask[v] = 1;
    current = std::move(mask);
  }
  out.mask = current;
  // 5. The start: a little outside the step's foot.
  // Measured across the background (a sharp wall one triangle wide costs its width, not its height).
  out.start_region = grown_region(mesh, out.mask, std::max(options.margin * h, options.margin_edges * edge),
                                  tangential_length(mesh, out.base_normals));
  return done("");
}

}  // namespace relief_snake

// Background inside a region: the low pieces a bridged concavity or a lobe leaves (background_inside.hpp).
#include "relief_snake/background_inside.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "relief_snake/mesh_graph.hpp"
#include "relief_snake/height_statistics.hpp"

namespace relief_snake {

BackgroundInside measure_background_inside(const Mesh& mesh, const std::vector<char>& region, double h, double step,
                                           const BackgroundSolver* solver, const BackgroundInsideOptions& options) {
  const auto t_start = std::chrono::steady_clock::now();
  BackgroundInside out;
  const int n = mesh.n_vertices();
  if (static_cast<int>(region.size()) != n || !(h > 0) || !(step > 0)) return out;
  auto inside = [&](int v) { return region[v] != 0; };

  // 1-2. The background's height at every region vertex.
  std::vector<double> height(n, 0.0);
  if (options.model == BackgroundInsideModel::ThinPlate) {
    if (!solver) return out;
    const BackgroundResult fill = solver->solve(region, h);
    if (!fill.ok()) return out;
    for (const int v : fill.region_vertices) height[v] = fill.height[v];
  } else {
    std::vector<int> border_outside;  // outside vertices next to the region: the ring grows from them
    for (int v = 0; v < n; ++v) {
      if (inside(v)) continue;
      for (const int* w = mesh.neighbors_begin(v); w != mesh.neighbors_end(v); ++w)
        if (inside(*w)) {
          border_outside.push_back(v);
          break;
        }
    }
    if (border_outside.empty()) return out;
    const double ring = std::max(options.ring_width * h, options.ring_width_edges * mesh.average_edge_length());
    const std::vector<double> ring_distance =
        edge_distances(mesh, border_outside, ring, [&](int v) { return !inside(v); });
    std::vector<int> ring_vertices;
    for (int v = 0; v < n; ++v)
      if (!inside(v) && std::isfinite(ring_distance[v])) ring_vertices.push_back(v);
    if (ring_vertices.size() < 12) return out;
    RobustFitOptions fit_options;
    fit_options.degree = 2;
    const RobustFit fit = fit_robust_background(mesh, ring_vertices, fit_options);
    for (int v = 0; v < n; ++v)
      if (inside(v)) height[v] = fit.background.height(mesh.position(v));
  }
  out.measured = true;

  // 3. Low region vertices; their pieces that touch the outside, and each piece's depth.
  const double low = options.low_share * step;
  std::vector<char> is_low(n, 0);
  for (int v = 0; v < n; ++v)
    if (inside(v) && height[v] < low) is_low[v] = 1;
  std::vector<int> not_low_seeds;  // region vertices above the threshold and outside vertices next to a low one
  for (int v = 0; v < n; ++v) {
    if (is_low[v]) continue;
    for (const int* w = mesh.neighbors_begin(v); w != mesh.neighbors_end(v); ++w)
      if (is_low[*w]) {
        not_low_seeds.push_back(v);
        break;
      }
  }
  const std::vector<double> depth = edge_distances(mesh, not_low_seeds, std::numeric_limits<double>::infinity(),
                                                   [&](int v) { return is_low[v] != 0; });
  out.piece.assign(n, -1);
  for (const std::vector<int>& members : vertex_components(mesh, is_low)) {
    const int label = static_cast<int>(out.piece_depth.size());
    double area = 0, deepest = 0;
    int deepest_vertex = members.front();
    bool touches_outside = false;
    for (const int v : members) {
      out.piece[v] = label;
      area += mesh.vertex_area(v);
      if (depth[v] > deepest) deepest = depth[v], deepest_vertex = v;
      for (const int* w = mesh.neighbors_begin(v); w != mesh.neighbors_end(v); ++w)
        touches_outside = touches_outside || !inside(*w);
    }
    out.piece_depth.push_back(touches_outside ? deepest : -1.0);
    if (!touches_outside) continue;  // a hollow inside the relief (a drop, a deep groove's middle)
    if (deepest > out.depth) out.depth = deepest, out.area = area, out.deepest_vertex = deepest_vertex;
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return out;
}

std::vector<char> BackgroundInside::region_without(const std::vector<char>& region, double depth_limit) const {
  std::vector<char> out = region;
  if (piece.size() != region.size()) return out;
  for (std::size_t v = 0; v < region.size(); ++v)
    if (piece[v] >= 0 && piece_depth[piece[v]] > depth_limit) out[v] = 0;
  return out;
}

bool deep_background_piece(double depth, double area, double limit) {
  return depth > limit && area >= 0.5 * M_PI * limit * limit;
}

const BackgroundSolver& BackgroundInsideCheck::solver(std::unique_ptr<BackgroundSolver>& slot,
                                                      const BackgroundOptions& options) {
  if (!slot) slot = std::make_unique<BackgroundSolver>(mesh_, options);
  return *slot;
}

BackgroundInside BackgroundInsideCheck::measure(const std::vector<char>& region, double h, double step, double limit,
                                                double roughness) {
  auto deep = [&](const BackgroundInside& b) {
    return b.measured && b.deepest_vertex >= 0 && deep_background_piece(b.depth, b.area, limit);
  };
  BackgroundInsideOptions quadric;
  quadric.model = BackgroundInsideModel::RingQuadric;
  const BackgroundInside screen = measure_background_inside(mesh_, region, h, step, nullptr, quadric);
  double seconds = screen.seconds;
  // The height-field fill (uniform weights where the cotangent ones are singular), confirmed where deep
  // by the fill of the positions: the shallower depth and its area kept.
  auto filled = [&](const BackgroundOptions& options, Fills& fills) {
    BackgroundInside b = measure_background_inside(mesh_, region, h, step, &solver(fills.cotangent, options));
    seconds += b.seconds;
    if (!b.measured) {  // cotangent weights of a sharp wall's projection can be singular
      BackgroundOptions with_uniform = options;
      with_uniform.laplacian = BackgroundLaplacian::Uniform;
      b = measure_background_inside(mesh_, region, h, step, &solver(fills.uniform, with_uniform));
      seconds += b.seconds;
    }
    if (deep(b)) {
      BackgroundOptions positions = options;
      positions.model = BackgroundModel::Surface;
      const BackgroundInside second = measure_background_inside(mesh_, region, h, step, &solver(fills.surface, positions));
      seconds += second.seconds;
      if (second.measured && second.depth < b.depth) b.depth = second.depth, b.area = second.area;
    }
    return b;
  };
  BackgroundInside out;
  if (!screen.measured || deep(screen)) {
    out = filled(fill_, fills_);
    const bool textured = roughness >= textured_.min_roughness * step;
    if (textured_.smoothing > 0 && textured && deep(screen) && !deep(out)) {
      BackgroundOptions soft = fill_;
      soft.smoothing = textured_.smoothing;
      soft.smoothing_band = soft.ring_width;
      BackgroundInside again = filled(soft, textured_fills_);
      if (deep(again)) out = std::move(again);
    }
  }
  out.checked = screen.measured || out.measured;
  out.seconds = seconds;
  return out;
}

}  // namespace relief_snake

// Distances and components over the mesh's edge graph (mesh_graph.hpp).
#include "relief_snake/mesh_graph.hpp"

#include <limits>
#include <queue>
#include <utility>

namespace relief_snake {

std::vector<double> edge_distances(const Mesh& mesh, const std::vector<int>& seeds, double max_distance,
                                   const std::function<bool(int)>& allowed) {
  return edge_distances(mesh, seeds, max_distance, allowed, {});
}

std::function<double(int, int)> tangential_length(const Mesh& mesh, const std::vector<Vec3>& normals) {
  return [&mesh, &normals](int v, int w) {
    const Vec3 d = mesh.position(w) - mesh.position(v);
    return (d - d.dot(normals[v]) * normals[v]).norm();
  };
}

std::vector<double> edge_distances(const Mesh& mesh, const std::vector<int>& seeds, double max_distance,
                                   const std::function<bool(int)>& allowed,
                                   const std::function<double(int, int)>& length) {
  std::vector<double> dist(mesh.n_vertices(), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (const int s : seeds) dist[s] = 0, queue.push({0.0, s});
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    for (const int* w = mesh.neighbors_begin(v); w != mesh.neighbors_end(v); ++w) {
      if (!allowed(*w)) continue;
      const double nd = d + (length ? length(v, *w) : (mesh.position(*w) - mesh.position(v)).norm());
      if (nd <= max_distance && nd < dist[*w]) dist[*w] = nd, queue.push({nd, *w});
    }
  }
  return dist;
}

std::vector<char> grown_vertices(const Mesh& mesh, const std::vector<int>& seeds, double distance,
                                 const std::function<bool(int)>& blocked) {
  const std::vector<double> dist =
      edge_distances(mesh, seeds, distance, [&](int v) { return !blocked || !blocked(v); });
  std::vector<char> out(mesh.n_vertices(), 0);
  for (int v = 0; v < mesh.n_vertices(); ++v) out[v] = dist[v] <= distance;
  return out;
}

std::vector<char> grown_region(const Mesh& mesh, const std::vector<char>& region, double distance,
                               const std::function<double(int, int)>& length) {
  // Seeded from the region's border only: the inside is in anyway.
  std::vector<int> border;
  for (int v = 0; v < mesh.n_vertices(); ++v) {
    if (!region[v]) continue;
    for (const int* w = mesh.neighbors_begin(v); w != mesh.neighbors_end(v); ++w)
      if (!region[*w]) {
        border.push_back(v);
        break;
      }
  }
  const std::vector<double> dist = edge_distances(mesh, border, distance, [](int) { return true; }, length);
  std::vector<char> out(mesh.n_vertices(), 0);
  for (int v = 0; v < mesh.n_vertices(); ++v) out[v] = region[v] || dist[v] <= distance;
  return out;
}

std::vector<std::vector<int>> vertex_components(const Mesh& mesh, const std::vector<char>& flags) {
  std::vector<std::vector<int>> out;
  std::vector<char> seen(mesh.n_vertices(), 0);
  for (int s = 0; s < mesh.n_vertices(); ++s) {
    if (!flags[s] || seen[s]) continue;
    std::vector<int> comp = {s};
    seen[s] = 1;
    for (std::size_t head = 0; head < comp.size(); ++head)
      for (const int* w = mesh.neighbors_begin(comp[head]); w != mesh.neighbors_end(comp[head]); ++w)
        if (flags[*w] && !seen[*w]) seen[*w] = 1, comp.push_back(*w);
    out.push_back(std::move(comp));
  }
  return out;
}

}  // namespace relief_snake

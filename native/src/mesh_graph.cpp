// Distances and components over the mesh's edge graph (mesh_graph.hpp).
#include "relief_snake/mesh_graph.hpp"

#include <limits>
#include <queue>
#include <utility>

namespace relief_snake {

std::vector<double> edge_distances(const Mesh& mesh, const std::vector<int>& seeds, double max_distance,
                                   const std::function<bool(int)>& allowed) {
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
      const double nd = d + (mesh.position(*w) - mesh.position(v)).norm();
      if (nd <= max_distance && nd < dist[*w]) dist[*w] = nd, queue.push({nd, *w});
    }
  }
  return dist;
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

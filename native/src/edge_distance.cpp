// Dijkstra along mesh edges from several seeds.
#include "relief_snake/edge_distance.hpp"

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

}  // namespace relief_snake

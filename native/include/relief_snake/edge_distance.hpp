#pragma once
// Distances along mesh edges from a set of seed vertices (Dijkstra), within a radius and a
// vertex mask. The cheap metric of the region-level checks (detection, the background inside a
// region): a few percent longer than geodesic distances on a regular mesh, and never shorter.
#include <functional>
#include <vector>

#include "relief_snake/mesh.hpp"

namespace relief_snake {

/// #V distances along edges from the nearest of `seeds` (mesh vertices), walking only through
/// vertices where allowed(v) is true (seeds are always allowed) and no further than
/// max_distance; +infinity for every vertex not reached.
std::vector<double> edge_distances(const Mesh& mesh, const std::vector<int>& seeds, double max_distance,
                                   const std::function<bool(int)>& allowed);

}  // namespace relief_snake

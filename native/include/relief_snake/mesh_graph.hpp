#pragma once
// Walks over the mesh's edge graph: distances along edges from a set of seed vertices (Dijkstra),
// within a radius and a vertex mask, and the connected components of a vertex set. The cheap
// metric and grouping of the region-level stages (detection, holes, the background inside a
// region): edge distances are a few percent longer than geodesic ones on a regular mesh, never
// shorter.
#include <functional>
#include <vector>

#include "relief_snake/mesh.hpp"

namespace relief_snake {

/// #V distances along edges from the nearest of `seeds` (mesh vertices), walking only through
/// vertices where allowed(v) is true (seeds are always allowed) and no further than
/// max_distance; +infinity for every vertex not reached.
std::vector<double> edge_distances(const Mesh& mesh, const std::vector<int>& seeds, double max_distance,
                                   const std::function<bool(int)>& allowed);
/// The same with each edge (v, w) as long as length(v, w) says (>= 0), e.g. its length across a
/// background, leaving out its rise.
std::vector<double> edge_distances(const Mesh& mesh, const std::vector<int>& seeds, double max_distance,
                                   const std::function<bool(int)>& allowed,
                                   const std::function<double(int, int)>& length);
/// Edge lengths in the tangent plane of `normals` (#V unit vectors) at the edge's first vertex: a
/// sharp step's wall then costs its width, not its height.
std::function<double(int, int)> tangential_length(const Mesh& mesh, const std::vector<Vec3>& normals);

/// #V flags: the vertices within `distance` (along edges) of `seeds`, never entering a vertex where
/// blocked(v) is true (seeds are always in). No blocked: nothing is.
std::vector<char> grown_vertices(const Mesh& mesh, const std::vector<int>& seeds, double distance,
                                 const std::function<bool(int)>& blocked = {});
/// #V flags: the flagged vertices (#V flags) and every vertex within `distance` of one along edges.
std::vector<char> grown_region(const Mesh& mesh, const std::vector<char>& region, double distance,
                               const std::function<double(int, int)>& length = {});

/// The connected components (over mesh edges) of the flagged vertices (#V flags), each in
/// breadth-first order from its lowest vertex; components in order of their lowest vertex.
std::vector<std::vector<int>> vertex_components(const Mesh& mesh, const std::vector<char>& flags);

}  // namespace relief_snake

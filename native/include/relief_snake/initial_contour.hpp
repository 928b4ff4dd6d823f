#pragma once
// The initial contour (Section 7.1): the user's picks joined across the mesh by
// plane sections (Figure 5), with a shortest-edge-path fallback, and arc-length
// resampling of such paths into snaxels.
#include <cstddef>
#include <vector>

#include "relief_snake/mesh.hpp"
#include "relief_snake/surface_point.hpp"

namespace relief_snake {

/// A path on the surface: consecutive points lie on a common face, so the straight
/// segment between them is on the mesh. Paths made here also keep the invariant
/// "path[i].face contains path[i+1]" (segment i lies in face path[i].face).
using SurfacePath = std::vector<SurfacePoint>;

/// Joins a to b by intersecting the mesh with the plane through both points that
/// contains the average of their surface normals (Figure 5). Marches face to face
/// through the edges the plane crosses, starting from a in the direction that heads
/// towards b (then, if that fails, the other way). Vertices exactly on the plane
/// count as being on its positive side, so every face is crossed at most once.
/// out: a, the edge crossings, b. Returns false (out untouched) when the section
/// reaches a mesh boundary, grows longer than 3 |b - a| + 6 average edges, loops
/// back to its start, or the plane is undefined (normals cancel or are parallel to b - a).
bool plane_section_path(const Mesh& mesh, const SurfacePoint& a, const SurfacePoint& b, SurfacePath* out);

/// Fallback: shortest path along mesh edges (Dijkstra, Euclidean edge lengths) from
/// vertex va to vertex vb; out holds the vertices' points. False if not connected.
bool shortest_edge_path(const Mesh& mesh, int va, int vb, SurfacePath* out);

struct InitialContour {
  SurfacePath path;                    ///< closed: the last point joins the first (not repeated)
  int fallback_legs = 0;               ///< legs joined by the shortest edge path instead of a plane section
  std::vector<std::size_t> pick_index; ///< pick k is path[pick_index[k]]
};

/// Refuses (Error, with the order by angle around the picks' centre as advice) closed-contour
/// picks that cannot go round a relief: seen along their average vertex normal, the pick
/// polygon crosses itself (figure-eight order) or encloses almost no area (4 pi A / P^2 < 0.02:
/// collinear picks). picks: mesh vertex indices, >= 3.
void check_pick_polygon(const Mesh& mesh, const std::vector<int>& picks);

/// Joins the picks (mesh vertex indices) in order, and last to first when closed,
/// by plane sections with the shortest-path fallback per leg. Throws Error for
/// fewer than 3 (closed) or 2 (open) picks, bad indices, repeated consecutive picks,
/// picks on different connected parts of the mesh, or (closed) a pick polygon that
/// check_pick_polygon refuses.
InitialContour initial_contour(const Mesh& mesh, const std::vector<int>& picks, bool closed);

/// Arc length of a path (closed: including the segment from the last point to the first).
double path_length(const Mesh& mesh, const SurfacePath& path, bool closed);

/// Samples a path at arc-length spacing ~spacing: closed paths get
/// n = max(3, round(L / spacing)) equal steps around (n points, the first at path[0]);
/// open paths keep both ends exactly and use max(1, round(L / spacing)) equal steps
/// (n + 1 points). The result points lie on the path's segments.
std::vector<SurfacePoint> resample_path(const Mesh& mesh, const SurfacePath& path, double spacing, bool closed);

/// Open contours: if an end of the path is not on the mesh boundary, extends it from
/// there to the nearest boundary vertex (shortest edge path from the end's nearest
/// corner). Returns false (path untouched) if that component has no boundary.
bool extend_to_boundary(const Mesh& mesh, SurfacePath* path);

/// True if p lies on the mesh boundary (at a boundary vertex or on a boundary edge).
bool on_boundary(const Mesh& mesh, const SurfacePoint& p);

}  // namespace relief_snake

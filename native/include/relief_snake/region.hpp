#pragma once
// The relief region: which mesh vertices a contour encloses (closed) or has on the
// relief side (open), by cutting the mesh along the traced contour and flooding.
#include <vector>

#include "relief_snake/mesh.hpp"
#include "relief_snake/surface_point.hpp"

namespace relief_snake {

/// Per-mesh-vertex flag (#V entries, 1 = relief) for a contour of snaxels in order
/// (closed: the last joins the first). inside_left: the relief lies to the left of the
/// direction of travel seen from outside (normal towards the viewer), i.e. towards n x t.
///
/// Each contour segment is traced on the surface (plane section between the two
/// snaxels, shortest edge path if that fails); every mesh edge the trace crosses is
/// cut and its endpoints are seeded with their side, read from the mesh orientation
/// (entering face f across the edge opposite corner k, corner k+1 is on the left).
/// A competitive breadth-first flood from all seeds over uncut edges then labels
/// the rest, so a missed crossing only mislabels locally. A part of the mesh the cuts
/// close off whose seeds are all but a few on one side (at most a tenth as many on the
/// other) is then that side, but for a stray seed that won only itself: a stray seed (a
/// hairpin of the traced contour around a vertex votes its far side wrong) would otherwise
/// win a wedge of the flood running out to the mesh's end. Vertices no seed reaches (other
/// components) are not relief. Open contours should end on the mesh boundary.
std::vector<char> relief_region(const Mesh& mesh, const std::vector<SurfacePoint>& contour, bool closed,
                                bool inside_left);

/// True if the closed contour runs counter-clockwise around the region it encloses,
/// seen from outside: the vector area of its 3D polygon dotted with the average surface
/// normal along it is positive. Then the inside is to the left (inside_left = true).
bool contour_orientation_left(const Mesh& mesh, const std::vector<SurfacePoint>& closed_contour);

/// The longest closed boundary loop of the faces whose three corners are flagged (#V flags):
/// mesh vertices in order, with those faces on the left seen from outside. Empty if none.
std::vector<int> region_outer_loop(const Mesh& mesh, const std::vector<char>& flag);

}  // namespace relief_snake

#pragma once
// A place on the surface (face + barycentric coordinates) and straight walks along
// the surface. Every snaxel, candidate position and q_i is a SurfacePoint.
#include <vector>

#include "relief_snake/mesh.hpp"

namespace relief_snake {

/// A point on face `face` with barycentric weights `bary` (sum 1, all >= 0) on the
/// face's corners in order. Points on edges or vertices have zero weights; they
/// may be expressed in any incident face (see in_face()).
struct SurfacePoint {
  int face = -1;
  Vec3 bary = Vec3(1.0 / 3, 1.0 / 3, 1.0 / 3);
  bool valid() const { return face >= 0; }
};

/// The point at mesh vertex v (expressed in one of its faces).
SurfacePoint vertex_point(const Mesh& mesh, int v);
/// 3D position of p.
Vec3 position(const Mesh& mesh, const SurfacePoint& p);
/// Unit surface normal at p, interpolated from the vertex normals (smooth across edges).
Vec3 normal(const Mesh& mesh, const SurfacePoint& p);
/// Linear interpolation of a per-vertex value at p.
template <class PerVertex>
double interpolate(const Mesh& mesh, const SurfacePoint& p, const PerVertex& value) {
  return p.bary[0] * value(mesh.face_vertex(p.face, 0)) + p.bary[1] * value(mesh.face_vertex(p.face, 1)) +
         p.bary[2] * value(mesh.face_vertex(p.face, 2));
}
/// p expressed in face g, if p lies on g (inside, on one of its edges or corners).
bool in_face(const Mesh& mesh, const SurfacePoint& p, int g, Vec3* bary_in_g, double tolerance = 1e-9);
/// A face containing both a and b, with both expressed in it; false if none.
bool common_face(const Mesh& mesh, const SurfacePoint& a, const SurfacePoint& b, int* face, Vec3* bary_a,
                 Vec3* bary_b);
/// The mesh vertex nearest to p among its face's corners.
int nearest_corner(const Mesh& mesh, const SurfacePoint& p);

/// Where a straight walk on the surface ended.
struct Walk {
  SurfacePoint end;
  double travelled = 0;    ///< surface distance covered (< requested if a boundary stopped it)
  bool hit_boundary = false;
  Vec3 direction = Vec3::Zero();  ///< unit walking direction at the end (in the end face's plane)
  int boundary_face = -1, boundary_edge = -1;  ///< the boundary edge that stopped the walk (face, opposite corner)
};

/// A point a walk passed, with its distance along the walk.
struct WalkPoint {
  SurfacePoint point;
  double distance = 0;
  int tag = -1;  ///< walk_trace(): the index of the sample distance, or -1 for an edge crossing
};

/// Walks from `start` along `direction` (projected into the start face's plane)
/// for `distance`, crossing edges by unfolding the direction about them, so the
/// path is a straightest line on the surface. Stops at a mesh boundary.
Walk walk(const Mesh& mesh, const SurfacePoint& start, const Vec3& direction, double distance);

/// The same walk, also recording the point reached at each of the increasing
/// `sample_distances` (those beyond a boundary are not reached). Returns the walk;
/// samples->size() is the number of sample points reached.
Walk walk_sampled(const Mesh& mesh, const SurfacePoint& start, const Vec3& direction,
                  const std::vector<double>& sample_distances, std::vector<SurfacePoint>* samples);

/// The same walk, for sample_distances[n_samples - 1], recording in walking order
/// the point at each (increasing) sample distance and every edge crossing at a
/// distance in [crossings_from, crossings_to] (none if crossings_to < crossings_from).
Walk walk_trace(const Mesh& mesh, const SurfacePoint& start, const Vec3& direction, const double* sample_distances,
                std::size_t n_samples, double crossings_from, double crossings_to, std::vector<WalkPoint>* points);

/// The same walk from distance `from` to `to` (0 <= from <= to): *points gets every
/// edge crossing in that stretch and its two ends (those reached before a boundary),
/// in no particular order. A per-vertex value interpolated linearly in each face
/// takes its extremes over the stretch at these points.
Walk walk_stretch(const Mesh& mesh, const SurfacePoint& start, const Vec3& direction, double from, double to,
                  std::vector<SurfacePoint>* points);

/// The point of the surface nearest to `target`, searched among the faces reachable
/// from start's face through faces that come within `radius` of the target (so
/// radius >= |position(start) - target| finds it unless the surface folds away).
/// scratch: optional reusable buffer.
SurfacePoint closest_point_near(const Mesh& mesh, const SurfacePoint& start, const Vec3& target, double radius,
                                std::vector<int>* scratch = nullptr);

}  // namespace relief_snake

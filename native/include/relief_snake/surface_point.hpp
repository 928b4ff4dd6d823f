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
/// The points at the vertices of `path` (#path), in order.
std::vector<SurfacePoint> vertex_points(const Mesh& mesh, const std::vector<int>& path);
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

/// A point a walk passed, with its distance along the walk.
struct WalkPoint {
  SurfacePoint point;
  double distance = 0;
  int tag = -1;  ///< the index of the sample distance (WalkOptions::samples), or -1 for an edge crossing
};

/// What a walk records and where it stops.
struct WalkOptions {
  /// How far to walk along the surface; a mesh boundary stops it sooner.
  double distance = 0;
  /// Record the point reached at each of these increasing distances (<= distance), tagged with its
  /// index; samples beyond a boundary are not reached. The caller's array (`n_samples` values), so a
  /// walk that records nothing allocates nothing (the snake's inner loop).
  const double* samples = nullptr;
  std::size_t n_samples = 0;
  /// Record every edge crossing at a distance in [crossings_from, crossings_to] (tag -1).
  bool record_crossings = false;
  double crossings_from = 0, crossings_to = 0;
  /// A guard against ping-pong on degenerate geometry: faces crossed at most.
  int max_face_steps = 100000;
};

/// Where a straight walk on the surface ended, and what it recorded.
struct WalkResult {
  SurfacePoint end;
  double travelled = 0;    ///< surface distance covered (< WalkOptions::distance if a boundary stopped it)
  bool hit_boundary = false;
  Vec3 direction = Vec3::Zero();  ///< unit walking direction at the end (in the end face's plane)
  int boundary_face = -1, boundary_edge = -1;  ///< the boundary edge that stopped the walk (face, opposite corner)
  /// In walking order: the samples reached and the edge crossings asked for (WalkOptions).
  std::vector<WalkPoint> points;
};

/// Walks from `start` along `direction` (projected into the start face's plane) for
/// options.distance, crossing edges by unfolding the direction about them, so the path is a
/// straightest line on the surface. Stops at a mesh boundary. A per-vertex value interpolated
/// linearly in each face takes its extremes over a stretch of the walk at the stretch's ends and
/// edge crossings: sample the ends and record the crossings between them. The plain walk is
/// `walk(mesh, start, direction, WalkOptions{distance})`.
WalkResult walk(const Mesh& mesh, const SurfacePoint& start, const Vec3& direction, const WalkOptions& options);

/// The surface points of a walk's recorded points, in walking order.
std::vector<SurfacePoint> walk_points(const WalkResult& walk);

/// The point of the surface nearest to `target`, searched among the faces reachable
/// from start's face through faces that come within `radius` of the target (so
/// radius >= |position(start) - target| finds it unless the surface folds away).
/// scratch: optional reusable buffer.
SurfacePoint closest_point_near(const Mesh& mesh, const SurfacePoint& start, const Vec3& target, double radius,
                                std::vector<int>* scratch = nullptr);

}  // namespace relief_snake

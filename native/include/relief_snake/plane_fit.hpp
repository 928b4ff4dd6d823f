#pragma once
// Least-squares plane fits from accumulated moments, and the planarity of a
// vertex against such a plane (Section 5.3.1). The moments are either of points
// (the paper: the neighbouring vertices, unit weight each) or of triangles (the
// surface area of the neighbourhood, so the fit does not depend on how densely
// the scanner sampled each part of it).
#include <vector>

#include <Eigen/Core>

#include "relief_snake/mesh.hpp"

namespace relief_snake {

/// Zeroth, first and second moments of a weighted set of points or triangles,
/// about an origin chosen by the caller (keep it near the data: the covariance is
/// a difference of these sums).
struct PlaneMoments {
  double weight = 0;                                    ///< total weight (count, or area)
  Vec3 first = Vec3::Zero();                            ///< sum of w x
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();     ///< sum of w x x^T (exact over triangle areas)

  void add_point(const Vec3& x, double w = 1.0);
  /// The triangle (a, b, c) with uniform density 1: weight = its area, exact moments.
  void add_triangle(const Vec3& a, const Vec3& b, const Vec3& c);
  /// The same with its area known (Mesh::face_area()).
  void add_triangle(const Vec3& a, const Vec3& b, const Vec3& c, double area);
  void add(const PlaneMoments& other);
  /// The same moments about origin `o` (x -> x - o).
  PlaneMoments shifted(const Vec3& o) const;
};

/// P(v) = (c - v) . n for the least-squares plane (c, n) of `moments` (taken about
/// the origin v itself: pass moments of x - v), with n oriented like `vertex_normal`.
/// Degenerate sets: 0 for no weight or all points coincident; the surface normal as
/// n when the points are collinear.
double planarity_about_vertex(const PlaneMoments& moments_about_v, const Vec3& vertex_normal);

/// The least-squares plane of some mesh vertices, each weighted by its area (Mesh::vertex_area)
/// or by 1: fitted in two passes (the weighted centroid, then the covariance about it), so it
/// stays exact far from the origin. Used where the vertices are few and listed (the self-check's
/// local backgrounds, the step-height estimate, the extraction's ring); the planarity field's
/// many overlapping neighbourhoods sum PlaneMoments instead.
struct VertexPlaneFit {
  double weight = 0;                    ///< total weight; 0: no vertices (nothing else is set)
  Vec3 centroid = Vec3::Zero();         ///< weighted mean position
  Vec3 normal = Vec3::UnitZ();          ///< the least axis, oriented like the weighted vertex normals
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  ///< covariance eigenvectors, columns by increasing eigenvalue
  Vec3 eigenvalues = Vec3::Zero();      ///< of the weighted covariance sum(w d d^T), increasing
  /// RMS distance of the vertices from the plane (weighted).
  double residual() const;
};

/// `vertices` #N mesh vertex indices (repeats count twice).
VertexPlaneFit fit_vertex_plane(const Mesh& mesh, const std::vector<int>& vertices, bool area_weighted = true);

}  // namespace relief_snake

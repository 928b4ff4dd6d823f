// SurfacePoint and straight walks on the surface.
#include <gtest/gtest.h>

#include <cmath>

#include "relief_snake/surface_point.hpp"
#include "test_meshes.hpp"

using namespace relief_snake;

namespace {

SurfacePoint point_near(const Mesh& mesh, const Vec3& target) {
  int best = 0;
  for (int v = 1; v < mesh.n_vertices(); ++v)
    if ((mesh.position(v) - target).norm() < (mesh.position(best) - target).norm()) best = v;
  return vertex_point(mesh, best);
}

}  // namespace

TEST(SurfacePoint, VertexPointAndPosition) {
  const Mesh mesh = test::plane_mesh(11, 10);
  for (int v : {0, 5, 60, 120}) {
    const SurfacePoint p = vertex_point(mesh, v);
    ASSERT_TRUE(p.valid());
    EXPECT_NEAR((position(mesh, p) - mesh.position(v)).norm(), 0, 1e-12);
    EXPECT_EQ(nearest_corner(mesh, p), v);
  }
}

TEST(SurfacePoint, WalkOnPlaneIsStraightAndExact) {
  const Mesh mesh = test::plane_mesh(21, 10);
  const SurfacePoint start = point_near(mesh, Vec3(2, 2, 0));
  const Vec3 dir = Vec3(1, 0.7, 0).normalized();
  const WalkResult w = walk(mesh, start, dir, WalkOptions{5.0});
  EXPECT_FALSE(w.hit_boundary);
  EXPECT_NEAR(w.travelled, 5.0, 1e-9);
  EXPECT_NEAR((position(mesh, w.end) - (Vec3(2, 2, 0) + 5.0 * dir)).norm(), 0, 1e-9);
  EXPECT_GE(w.end.bary.minCoeff(), 0);
  EXPECT_NEAR(w.end.bary.sum(), 1, 1e-12);
}

TEST(SurfacePoint, WalkThroughVerticesAlongDiagonal) {
  // Along the grid diagonal the path passes exactly through vertices.
  const Mesh mesh = test::plane_mesh(21, 10);
  const SurfacePoint start = point_near(mesh, Vec3(1, 1, 0));
  const WalkResult w = walk(mesh, start, Vec3(1, 1, 0), WalkOptions{6.0});
  EXPECT_NEAR(w.travelled, 6.0, 1e-9);
  EXPECT_NEAR((position(mesh, w.end) - Vec3(1 + 6 / std::sqrt(2.0), 1 + 6 / std::sqrt(2.0), 0)).norm(), 0, 1e-6);
}

TEST(SurfacePoint, WalkStopsAtBoundary) {
  const Mesh mesh = test::plane_mesh(11, 10);
  const SurfacePoint start = point_near(mesh, Vec3(5, 5, 0));
  const WalkResult w = walk(mesh, start, Vec3(1, 0, 0), WalkOptions{20.0});
  EXPECT_TRUE(w.hit_boundary);
  EXPECT_NEAR(w.travelled, 5.0, 1e-9);
  EXPECT_NEAR(position(mesh, w.end).x(), 10.0, 1e-9);
}

TEST(SurfacePoint, WalkAcrossEdgesOnCylinderFollowsTheCircle) {
  // Walking around a cylinder (perpendicular to its axis) must stay on the
  // circle of radius r: the unfolding keeps the geodesic on the surface.
  const double r = 3;
  const Mesh mesh = test::cylinder_mesh(r, 121, 11, 4.0, 2 * r * 1.5);
  const SurfacePoint start = point_near(mesh, Vec3(r * std::sin(1.0 / r), 2.0, r * std::cos(1.0 / r)));
  const double arc = 6.0;
  std::vector<double> distances;
  for (int k = 1; k <= 12; ++k) distances.push_back(arc * k / 12);
  WalkOptions options;
  options.distance = arc;
  options.samples = distances.data();
  options.n_samples = distances.size();
  const WalkResult w = walk(mesh, start, Vec3(1, 0, 0), options);
  const std::vector<SurfacePoint> samples = walk_points(w);
  ASSERT_EQ(samples.size(), distances.size());
  EXPECT_FALSE(w.hit_boundary);
  for (const SurfacePoint& s : samples) {
    const Vec3 p = position(mesh, s);
    EXPECT_NEAR(p.y(), 2.0, 1e-6);                        // no drift along the axis
    EXPECT_NEAR(std::hypot(p.x(), p.z()), r, 2e-3 * r);  // on the (polygonal) cylinder
  }
  // The arc angle covered matches the distance (chordal polygon: within 1%).
  const Vec3 a = position(mesh, start), b = position(mesh, w.end);
  const double angle = std::atan2(b.x(), b.z()) - std::atan2(a.x(), a.z());
  EXPECT_NEAR(angle * r, arc, 0.01 * arc);
}

TEST(SurfacePoint, InFaceAndCommonFace) {
  const Mesh mesh = test::plane_mesh(11, 10);
  const int v = 60;
  const SurfacePoint a = vertex_point(mesh, v);
  for (const int* f = mesh.faces_begin(v); f != mesh.faces_end(v); ++f) {
    Vec3 b;
    ASSERT_TRUE(in_face(mesh, a, *f, &b));
    EXPECT_NEAR((position(mesh, SurfacePoint{*f, b}) - mesh.position(v)).norm(), 0, 1e-12);
  }
  const SurfacePoint far = vertex_point(mesh, 0);
  int face;
  Vec3 ba, bb;
  EXPECT_FALSE(common_face(mesh, a, far, &face, &ba, &bb));
  const SurfacePoint neighbour = vertex_point(mesh, *mesh.neighbors_begin(v));
  ASSERT_TRUE(common_face(mesh, a, neighbour, &face, &ba, &bb));
  EXPECT_NEAR((position(mesh, SurfacePoint{face, ba}) - mesh.position(v)).norm(), 0, 1e-12);
}

TEST(SurfacePoint, InterpolateIsLinear) {
  const Mesh mesh = test::plane_mesh(11, 10);
  SurfacePoint p{10, Vec3(0.2, 0.3, 0.5)};
  const Vec3 x = position(mesh, p);
  const double value = interpolate(mesh, p, [&](int v) { return 2 * mesh.position(v).x() - mesh.position(v).y(); });
  EXPECT_NEAR(value, 2 * x.x() - x.y(), 1e-12);
}

TEST(SurfacePoint, ClosestPointNearMatchesBruteForce) {
  // A bumpy sheet; targets a little off the surface; the local search must find the
  // same nearest point as a scan over every face.
  const Mesh mesh = test::grid_mesh(31, 31, 6, 6, [](double u, double v) {
    return Vec3(u, v, 0.4 * std::sin(1.7 * u) * std::cos(1.3 * v));
  });
  for (const Vec3& target : {Vec3(2.1, 3.3, 0.5), Vec3(4.0, 1.2, -0.3), Vec3(0.5, 5.5, 0.05), Vec3(3, 3, 0.8)}) {
    double best = 1e300;
    for (int f = 0; f < mesh.n_faces(); ++f) {
      // Dense barycentric sampling is enough for a reference to 1e-3.
      for (int i = 0; i <= 40; ++i)
        for (int j = 0; i + j <= 40; ++j) {
          const SurfacePoint p{f, Vec3(1 - (i + j) / 40.0, i / 40.0, j / 40.0)};
          best = std::min(best, (position(mesh, p) - target).norm());
        }
    }
    const SurfacePoint start = point_near(mesh, Vec3(target.x(), target.y(), 0));
    const double r = (position(mesh, start) - target).norm();
    const SurfacePoint found = closest_point_near(mesh, start, target, r);
    ASSERT_TRUE(found.valid());
    EXPECT_NEAR(found.bary.sum(), 1.0, 1e-12);
    EXPECT_GE(found.bary.minCoeff(), -1e-12);
    EXPECT_NEAR((position(mesh, found) - target).norm(), best, 2e-3) << target.transpose();
    EXPECT_LE((position(mesh, found) - target).norm(), best + 1e-12 + 2e-3);
  }
}

TEST(SurfacePoint, WalkStretchHoldsTheExtremesOfALinearField) {
  // A per-vertex field linear inside each face takes its extremes over a stretch of a
  // walk at the stretch's edge crossings or ends: a walk sampling the ends and recording the
  // crossings between them must return them all.
  const Mesh mesh = test::grid_mesh(21, 21, 10, 10, [](double u, double v) { return Vec3(u, v, 0); });
  auto field = [&](int v) { const Vec3& p = mesh.position(v); return std::sin(3 * p.x()) + std::cos(2.3 * p.y()); };
  const SurfacePoint start = point_near(mesh, Vec3(2, 3, 0));
  const Vec3 dir = Vec3(1, 0.37, 0).normalized();
  const double ends[2] = {1.5, 4.0};
  WalkOptions stretch;
  stretch.distance = 4.0;
  stretch.samples = ends;
  stretch.n_samples = 2;
  stretch.record_crossings = true;
  stretch.crossings_from = 1.5;
  stretch.crossings_to = 4.0;
  const WalkResult w = walk(mesh, start, dir, stretch);
  const std::vector<SurfacePoint> points = walk_points(w);
  EXPECT_FALSE(w.hit_boundary);
  ASSERT_GE(points.size(), 6u);  // the stretch crosses several edges
  double lo = 1e300, hi = -1e300;
  for (const SurfacePoint& p : points) {
    const double d = (position(mesh, p) - position(mesh, start)).norm();
    EXPECT_GE(d, 1.5 - 1e-9);
    EXPECT_LE(d, 4.0 + 1e-9);
    const double f = interpolate(mesh, p, field);
    lo = std::min(lo, f);
    hi = std::max(hi, f);
  }
  std::vector<double> dense;
  for (int k = 0; k <= 2000; ++k) dense.push_back(1.5 + 2.5 * k / 2000.0);
  WalkOptions sampled;
  sampled.distance = dense.back();
  sampled.samples = dense.data();
  sampled.n_samples = dense.size();
  const std::vector<SurfacePoint> samples = walk_points(walk(mesh, start, dir, sampled));
  ASSERT_EQ(samples.size(), dense.size());
  for (const SurfacePoint& p : samples) {
    const double f = interpolate(mesh, p, field);
    EXPECT_GE(f, lo - 1e-9);
    EXPECT_LE(f, hi + 1e-9);
  }
}

TEST(SurfacePoint, WalkRecordsSamplesAndCrossingsInWalkingOrder) {
  // Across a grid of unit cells, slightly off the x axis: the walk crosses a vertical edge
  // about every unit (and diagonals in between). Samples carry their index, crossings tag -1,
  // all in order of distance, crossings only inside the range asked for.
  const Mesh mesh = test::grid_mesh(11, 11, 10, 10, [](double u, double v) { return Vec3(u, v, 0); });
  const SurfacePoint start = point_near(mesh, Vec3(1, 5, 0));
  const Vec3 from = position(mesh, start);
  const Vec3 dir = Vec3(1, 0.13, 0).normalized();
  // Leaving the start vertex, the walk nudges its crossing 1e-9 (barycentric) off the corner.
  const double tol = 1e-8;
  const double samples[3] = {0.5, 2.0, 3.5};
  WalkOptions options;
  options.distance = 4.0;
  options.samples = samples;
  options.n_samples = 3;
  const WalkResult plain = walk(mesh, start, dir, options);
  ASSERT_EQ(plain.points.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(plain.points[k].tag, k);
    EXPECT_NEAR((position(mesh, plain.points[k].point) - (from + samples[k] * dir)).norm(), 0, tol);
  }
  options.record_crossings = true;
  options.crossings_from = 1.0;
  options.crossings_to = 3.0;
  const WalkResult traced = walk(mesh, start, dir, options);
  int crossings = 0;
  double last = -1;
  for (const WalkPoint& p : traced.points) {
    EXPECT_GE(p.distance, last);
    last = p.distance;
    if (p.tag >= 0) continue;
    ++crossings;
    EXPECT_GE(p.distance, 1.0 - 1e-12);
    EXPECT_LE(p.distance, 3.0 + 1e-12);
    EXPECT_NEAR((position(mesh, p.point) - (from + p.distance * dir)).norm(), 0, tol);
  }
  EXPECT_GE(crossings, 2);  // at least the vertical edges x = 3 and x = 4
  EXPECT_EQ(static_cast<int>(traced.points.size()) - crossings, 3);
  // Nothing asked for, nothing recorded; the end is the same.
  const WalkResult bare = walk(mesh, start, dir, WalkOptions{4.0});
  EXPECT_TRUE(bare.points.empty());
  EXPECT_EQ(bare.end.face, traced.end.face);
  EXPECT_NEAR((position(mesh, bare.end) - (from + 4.0 * dir)).norm(), 0, tol);
}

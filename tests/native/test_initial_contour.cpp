// Initial contour: plane sections (Section 7.1), fallback, resampling, boundary extension.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Geometry>

#include "relief_snake/error.hpp"
#include "relief_snake/initial_contour.hpp"
#include "relief_snake/mesh.hpp"
#include "relief_snake/surface_point.hpp"

namespace rs = relief_snake;
using rs::Vec3;

namespace {

// (nx+1) x (ny+1) vertices over [0, nx h] x [0, ny h], z = height(x, y); cells split
// on the diagonal; optionally skipping cells (holes). Vertex (i, j) is input j (nx+1) + i.
rs::Mesh grid(int nx, int ny, double h, const std::function<double(double, double)>& height,
              const std::function<bool(int, int)>& skip_cell = nullptr) {
  std::vector<double> V;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const double x = i * h, y = j * h;
      V.insert(V.end(), {x, y, height(x, y)});
    }
  std::vector<std::int64_t> F;
  auto id = [nx](int i, int j) { return static_cast<std::int64_t>(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (skip_cell && skip_cell(i, j)) continue;
      F.insert(F.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      F.insert(F.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return rs::Mesh::from_triangles(V.data(), V.size() / 3, F.data(), F.size() / 3);
}

// Open cylinder of radius r around the z axis, n around, m rows of height dz; normals outward.
rs::Mesh cylinder(int n, int m, double r, double dz) {
  std::vector<double> V;
  for (int j = 0; j <= m; ++j)
    for (int i = 0; i < n; ++i) {
      const double t = 2 * M_PI * i / n;
      V.insert(V.end(), {r * std::cos(t), r * std::sin(t), j * dz});
    }
  std::vector<std::int64_t> F;
  auto id = [n](int i, int j) { return static_cast<std::int64_t>(j * n + (i % n)); };
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i) {
      F.insert(F.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      F.insert(F.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return rs::Mesh::from_triangles(V.data(), V.size() / 3, F.data(), F.size() / 3);
}

int vid(const rs::Mesh& mesh, int nx, int i, int j) { return mesh.input_to_mesh(j * (nx + 1) + i); }

// Barycentrics of x in face f by projection; true if x is on f (inside and in its plane).
bool on_face(const rs::Mesh& mesh, int f, const Vec3& x, double tol = 1e-9) {
  const Vec3 a = mesh.position(mesh.face_vertex(f, 0)), b = mesh.position(mesh.face_vertex(f, 1)),
             c = mesh.position(mesh.face_vertex(f, 2));
  const Vec3 n = (b - a).cross(c - a);
  const double area2 = n.squaredNorm();
  const double scale = std::max({(b - a).norm(), (c - a).norm(), 1.0});
  if (std::abs((x - a).dot(n.normalized())) > tol * scale) return false;
  const double wa = (b - x).cross(c - x).dot(n) / area2, wb = (c - x).cross(a - x).dot(n) / area2;
  const double wc = 1 - wa - wb;
  return wa >= -tol && wb >= -tol && wc >= -tol;
}

// Checks a path is a valid surface path: weights are barycentric and every segment lies on a face.
void expect_valid_path(const rs::Mesh& mesh, const rs::SurfacePath& path, bool closed) {
  ASSERT_GE(path.size(), 2u);
  for (std::size_t i = 0; i < path.size(); ++i) {
    const auto& p = path[i];
    ASSERT_TRUE(p.valid());
    EXPECT_NEAR(p.bary.sum(), 1.0, 1e-12);
    EXPECT_GE(p.bary.minCoeff(), -1e-12);
    if (i + 1 < path.size() || closed) {
      const auto& q = path[(i + 1) % path.size()];
      // The invariant of paths made here: path[i].face contains path[i+1].
      EXPECT_TRUE(on_face(mesh, p.face, rs::position(mesh, q))) << "segment " << i << " leaves face " << p.face;
    }
  }
}

Vec3 section_normal(const rs::Mesh& mesh, const rs::SurfacePoint& a, const rs::SurfacePoint& b) {
  const Vec3 d = rs::position(mesh, b) - rs::position(mesh, a);
  return d.cross(rs::normal(mesh, a) + rs::normal(mesh, b)).normalized();
}

// Plane-section leg between vertices va and vb: valid, joins them, stays in the section plane.
rs::SurfacePath check_section(const rs::Mesh& mesh, int va, int vb) {
  const rs::SurfacePoint a = rs::vertex_point(mesh, va), b = rs::vertex_point(mesh, vb);
  rs::SurfacePath path;
  EXPECT_TRUE(rs::plane_section_path(mesh, a, b, &path));
  if (path.empty()) return path;
  expect_valid_path(mesh, path, false);
  EXPECT_LT((rs::position(mesh, path.front()) - mesh.position(va)).norm(), 1e-12);
  EXPECT_LT((rs::position(mesh, path.back()) - mesh.position(vb)).norm(), 1e-12);
  const Vec3 m = section_normal(mesh, a, b);
  for (const auto& p : path) EXPECT_LT(std::abs((rs::position(mesh, p) - mesh.position(va)).dot(m)), 1e-9);
  // Not a detour: no longer than 1.6 times the straight distance.
  EXPECT_LT(rs::path_length(mesh, path, false), 1.6 * (mesh.position(vb) - mesh.position(va)).norm());
  return path;
}

}  // namespace

TEST(PlaneSection, FlatGridGenericAndThroughVertices) {
  const int n = 20;
  const rs::Mesh mesh = grid(n, n, 1.0, [](double, double) { return 0.0; });
  // Generic direction.
  check_section(mesh, vid(mesh, n, 2, 3), vid(mesh, n, 17, 11));
  // Along a grid row: the plane contains every vertex of the row (perturbation case).
  rs::SurfacePath row = check_section(mesh, vid(mesh, n, 1, 5), vid(mesh, n, 18, 5));
  // Along a diagonal: the plane contains the diagonal edges and vertices.
  check_section(mesh, vid(mesh, n, 2, 2), vid(mesh, n, 16, 16));
  check_section(mesh, vid(mesh, n, 16, 2), vid(mesh, n, 2, 16));
  // Reverse direction of the row.
  check_section(mesh, vid(mesh, n, 18, 5), vid(mesh, n, 1, 5));
  // Points inside faces and on edges, not only vertices.
  rs::SurfacePoint a = rs::vertex_point(mesh, vid(mesh, n, 3, 3)), b = rs::vertex_point(mesh, vid(mesh, n, 15, 9));
  a.bary = Vec3(0.2, 0.5, 0.3);
  b.bary = Vec3(0.5, 0.5, 0.0);
  rs::SurfacePath path;
  ASSERT_TRUE(rs::plane_section_path(mesh, a, b, &path));
  expect_valid_path(mesh, path, false);
  EXPECT_LT((rs::position(mesh, path.front()) - rs::position(mesh, a)).norm(), 1e-12);
  EXPECT_LT((rs::position(mesh, path.back()) - rs::position(mesh, b)).norm(), 1e-12);
  const Vec3 m = section_normal(mesh, a, b);
  for (const auto& p : path) EXPECT_LT(std::abs((rs::position(mesh, p) - rs::position(mesh, a)).dot(m)), 1e-9);
  // On a plane the section is the straight segment: length equals the distance.
  EXPECT_NEAR(rs::path_length(mesh, path, false), (rs::position(mesh, b) - rs::position(mesh, a)).norm(), 1e-9);
}

TEST(PlaneSection, CurvedBackgrounds) {
  const int n = 30;
  // Sphere cap of radius 25 and a saddle, as height fields.
  const rs::Mesh sphere = grid(n, n, 1.0, [](double x, double y) {
    return std::sqrt(625.0 - (x - 15) * (x - 15) - (y - 15) * (y - 15));
  });
  check_section(sphere, vid(sphere, n, 3, 4), vid(sphere, n, 26, 21));
  check_section(sphere, vid(sphere, n, 5, 15), vid(sphere, n, 25, 15));
  const rs::Mesh saddle =
      grid(n, n, 1.0, [](double x, double y) { return 0.02 * ((x - 15) * (x - 15) - (y - 15) * (y - 15)); });
  check_section(saddle, vid(saddle, n, 3, 4), vid(saddle, n, 26, 21));
  check_section(saddle, vid(saddle, n, 2, 27), vid(saddle, n, 27, 5));
  // Cylinder: legs a third of the way round, at different heights.
  const int around = 48;
  const rs::Mesh cyl = cylinder(around, 20, 5.0, 0.5);
  const auto cv = [&](int i, int j) { return cyl.input_to_mesh(j * around + i); };
  check_section(cyl, cv(0, 3), cv(16, 15));
  check_section(cyl, cv(40, 10), cv(8, 12));  // across the seam of the index wrap
  check_section(cyl, cv(5, 2), cv(5, 18));    // along a generator (plane through vertices)
}

TEST(PlaneSection, LongLegCrossesHundredsOfFaces) {
  const int n = 300;
  const rs::Mesh mesh =
      grid(n, n, 0.1, [](double x, double y) { return 0.5 * std::sin(0.2 * x) * std::cos(0.15 * y); });
  rs::SurfacePath path = check_section(mesh, vid(mesh, n, 5, 7), vid(mesh, n, 290, 281));
  EXPECT_GT(path.size(), 500u);
}

TEST(PlaneSection, FailsAtAHoleAndFallbackJoins) {
  const int n = 20;
  // A hole of cells 9..10 x 5..14 sits between the picks.
  const rs::Mesh mesh = grid(n, n, 1.0, [](double, double) { return 0.0; },
                             [](int i, int j) { return i >= 9 && i <= 10 && j >= 5 && j <= 14; });
  const int va = vid(mesh, n, 3, 10), vb = vid(mesh, n, 17, 10);
  rs::SurfacePath path;
  EXPECT_FALSE(rs::plane_section_path(mesh, rs::vertex_point(mesh, va), rs::vertex_point(mesh, vb), &path));
  EXPECT_TRUE(path.empty());  // untouched on failure
  ASSERT_TRUE(rs::shortest_edge_path(mesh, va, vb, &path));
  expect_valid_path(mesh, path, false);
  EXPECT_LT((rs::position(mesh, path.front()) - mesh.position(va)).norm(), 1e-12);
  EXPECT_LT((rs::position(mesh, path.back()) - mesh.position(vb)).norm(), 1e-12);

  // A closed contour around the hole: the legs crossing it fall back, the contour still joins the picks.
  const std::vector<int> picks = {vid(mesh, n, 3, 10), vid(mesh, n, 10, 1), vid(mesh, n, 17, 10),
                                  vid(mesh, n, 10, 19)};
  rs::InitialContour c = rs::initial_contour(mesh, {picks[0], picks[2], picks[3]}, true);
  EXPECT_GE(c.fallback_legs, 1);
  expect_valid_path(mesh, c.path, true);
  c = rs::initial_contour(mesh, picks, true);
  EXPECT_EQ(c.fallback_legs, 0);  // these legs go around the hole
  expect_valid_path(mesh, c.path, true);
  ASSERT_EQ(c.pick_index.size(), picks.size());
  for (std::size_t k = 0; k < picks.size(); ++k)
    EXPECT_LT((rs::position(mesh, c.path[c.pick_index[k]]) - mesh.position(picks[k])).norm(), 1e-12);
}

TEST(ShortestEdgePath, DisconnectedAndErrors) {
  const int n = 10;
  // Two strips with no shared edge.
  const rs::Mesh mesh = grid(n, n, 1.0, [](double, double) { return 0.0; }, [](int i, int) { return i == 5; });
  rs::SurfacePath path;
  EXPECT_FALSE(rs::shortest_edge_path(mesh, vid(mesh, n, 1, 1), vid(mesh, n, 9, 1), &path));
  EXPECT_THROW(rs::initial_contour(mesh, {vid(mesh, n, 1, 1), vid(mesh, n, 9, 1), vid(mesh, n, 9, 9)}, true),
               rs::Error);
  EXPECT_THROW(rs::initial_contour(mesh, {vid(mesh, n, 1, 1), vid(mesh, n, 2, 2)}, true), rs::Error);
  EXPECT_THROW(rs::initial_contour(mesh, {vid(mesh, n, 1, 1), vid(mesh, n, 1, 1), vid(mesh, n, 2, 2)}, false),
               rs::Error);
  EXPECT_THROW(rs::initial_contour(mesh, {0, mesh.n_vertices()}, false), rs::Error);
}

TEST(InitialContour, ClosedOnSphereJoinsPicksAndResamples) {
  const int n = 160;
  const rs::Mesh mesh = grid(n, n, 0.125, [](double x, double y) {
    return std::sqrt(400.0 - (x - 10) * (x - 10) - (y - 10) * (y - 10));
  });
  // 24 picks (vertices nearest to a circle of radius 7 around the centre): turns of about 15 degrees.
  std::vector<int> picks;
  for (int k = 0; k < 24; ++k) {
    const double t = 2 * M_PI * k / 24;
    picks.push_back(vid(mesh, n, static_cast<int>(std::lround(80 + 56 * std::cos(t))),
                        static_cast<int>(std::lround(80 + 56 * std::sin(t)))));
  }
  const rs::InitialContour c = rs::initial_contour(mesh, picks, true);
  EXPECT_EQ(c.fallback_legs, 0);
  expect_valid_path(mesh, c.path, true);
  for (std::size_t k = 0; k < picks.size(); ++k)
    EXPECT_LT((rs::position(mesh, c.path[c.pick_index[k]]) - mesh.position(picks[k])).norm(), 1e-12);

  const double L = rs::path_length(mesh, c.path, true);
  const double spacing = 0.8;
  const std::vector<rs::SurfacePoint> s = rs::resample_path(mesh, c.path, spacing, true);
  ASSERT_EQ(static_cast<long>(s.size()), std::lround(L / spacing));
  const double step = L / s.size();
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double d = (rs::position(mesh, s[(i + 1) % s.size()]) - rs::position(mesh, s[i])).norm();
    EXPECT_NEAR(d, step, 0.03 * step) << "sample " << i;  // includes the closing step
  }
  EXPECT_LT((rs::position(mesh, s[0]) - rs::position(mesh, c.path[0])).norm(), 1e-12);
  // Every sample lies on a face of the path (it is a point of the path's segments).
  for (const auto& p : s) {
    EXPECT_NEAR(p.bary.sum(), 1.0, 1e-12);
    EXPECT_GE(p.bary.minCoeff(), -1e-12);
  }
  // Tiny loops still get 3 points.
  EXPECT_EQ(rs::resample_path(mesh, c.path, 1e6, true).size(), 3u);
}

TEST(Resample, OpenKeepsEndsAndSpacing) {
  const int n = 30;
  const rs::Mesh mesh = grid(n, n, 1.0, [](double x, double) { return 0.01 * x * x; });
  const rs::InitialContour c =
      rs::initial_contour(mesh, {vid(mesh, n, 2, 2), vid(mesh, n, 14, 20), vid(mesh, n, 27, 25)}, false);
  expect_valid_path(mesh, c.path, false);
  ASSERT_EQ(c.pick_index.size(), 3u);
  EXPECT_EQ(c.pick_index.back(), c.path.size() - 1);
  const double L = rs::path_length(mesh, c.path, false);
  const std::vector<rs::SurfacePoint> s = rs::resample_path(mesh, c.path, 1.0, false);
  ASSERT_EQ(static_cast<long>(s.size()), std::lround(L) + 1);
  EXPECT_LT((rs::position(mesh, s.front()) - rs::position(mesh, c.path.front())).norm(), 1e-12);
  EXPECT_LT((rs::position(mesh, s.back()) - rs::position(mesh, c.path.back())).norm(), 1e-12);
  const double step = L / (s.size() - 1);
  int short_steps = 0;
  for (std::size_t i = 0; i + 1 < s.size(); ++i) {
    const double d = (rs::position(mesh, s[i + 1]) - rs::position(mesh, s[i])).norm();
    EXPECT_LE(d, step * (1 + 1e-9));
    if (d < 0.97 * step) ++short_steps;  // only where the path turns at the middle pick
  }
  EXPECT_LE(short_steps, 1);
}

TEST(ExtendToBoundary, ReachesTheBoundaryAtBothEnds) {
  const int n = 20;
  const rs::Mesh mesh = grid(n, n, 1.0, [](double x, double y) { return 0.05 * x * y; });
  rs::InitialContour c = rs::initial_contour(mesh, {vid(mesh, n, 6, 5), vid(mesh, n, 12, 14)}, false);
  rs::SurfacePath path = c.path;
  EXPECT_FALSE(rs::on_boundary(mesh, path.front()));
  ASSERT_TRUE(rs::extend_to_boundary(mesh, &path));
  EXPECT_TRUE(rs::on_boundary(mesh, path.front()));
  EXPECT_TRUE(rs::on_boundary(mesh, path.back()));
  EXPECT_GT(path.size(), c.path.size());
  expect_valid_path(mesh, path, false);
  // Already on the boundary: unchanged.
  rs::SurfacePath again = path;
  ASSERT_TRUE(rs::extend_to_boundary(mesh, &again));
  EXPECT_EQ(again.size(), path.size());

  // A closed surface has no boundary to extend to.
  const rs::Mesh cyl = cylinder(12, 6, 1.0, 0.5);
  std::vector<double> V;
  std::vector<std::int64_t> F;
  // Close the cylinder with two fan caps.
  for (int v = 0; v < cyl.n_vertices(); ++v) {
    const Vec3& x = cyl.position(v);
    V.insert(V.end(), {x.x(), x.y(), x.z()});
  }
  for (int f = 0; f < cyl.n_faces(); ++f)
    for (int k = 0; k < 3; ++k) F.push_back(cyl.face_vertex(f, k));
  const int bottom = cyl.n_vertices(), top = bottom + 1;
  V.insert(V.end(), {0, 0, 0, 0, 0, 3.0});
  auto ring = [&](int i, int j) { return static_cast<std::int64_t>(cyl.input_to_mesh(j * 12 + (i % 12))); };
  for (int i = 0; i < 12; ++i) {
    F.insert(F.end(), {bottom, ring(i + 1, 0), ring(i, 0)});
    F.insert(F.end(), {top, ring(i, 6), ring(i + 1, 6)});
  }
  const rs::Mesh closed = rs::Mesh::from_triangles(V.data(), V.size() / 3, F.data(), F.size() / 3);
  ASSERT_EQ(closed.report().boundary_edges, 0u);
  rs::SurfacePath p = {rs::vertex_point(closed, 3), rs::vertex_point(closed, 4)};
  EXPECT_FALSE(rs::extend_to_boundary(closed, &p));
  EXPECT_EQ(p.size(), 2u);
}

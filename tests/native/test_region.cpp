// Relief region: cut along the traced contour and flood from both sides.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iostream>
#include <vector>

#include "relief_snake/mesh.hpp"
#include "relief_snake/region.hpp"
#include "relief_snake/surface_point.hpp"

namespace rs = relief_snake;
using rs::Vec3;

namespace {

struct Grid {
  int nx, ny;
  double h;
  std::function<double(double, double)> height;
  rs::Mesh mesh;
};

// (nx+1) x (ny+1) vertices over [0, nx h] x [0, ny h], z = height(x, y), cells split on the diagonal.
Grid make_grid(int nx, int ny, double h, std::function<double(double, double)> height) {
  std::vector<double> V;
  V.reserve(3 * (nx + 1) * (ny + 1));
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) V.insert(V.end(), {i * h, j * h, height(i * h, j * h)});
  std::vector<std::int64_t> F;
  F.reserve(6 * nx * ny);
  auto id = [nx](int i, int j) { return static_cast<std::int64_t>(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      F.insert(F.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      F.insert(F.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return Grid{nx, ny, h, height, rs::Mesh::from_triangles(V.data(), V.size() / 3, F.data(), F.size() / 3)};
}

// The surface point above (x, y) on the grid (exact zeros on edges and at vertices).
rs::SurfacePoint locate(const Grid& g, double x, double y) {
  int i = std::min(std::max(static_cast<int>(std::floor(x / g.h)), 0), g.nx - 1);
  int j = std::min(std::max(static_cast<int>(std::floor(y / g.h)), 0), g.ny - 1);
  const double u = x / g.h - i, v = y / g.h - j;
  auto vid = [&](int a, int b) { return g.mesh.input_to_mesh(b * (g.nx + 1) + a); };
  int corners[3];
  double w[3];
  if (u >= v) {
    corners[0] = vid(i, j), corners[1] = vid(i + 1, j), corners[2] = vid(i + 1, j + 1);
    w[0] = 1 - u, w[1] = u - v, w[2] = v;
  } else {
    corners[0] = vid(i, j), corners[1] = vid(i + 1, j + 1), corners[2] = vid(i, j + 1);
    w[0] = 1 - v, w[1] = u, w[2] = v - u;
  }
  for (const int* f = g.mesh.faces_begin(corners[0]); f != g.mesh.faces_end(corners[0]); ++f) {
    rs::SurfacePoint p;
    p.face = *f;
    int found = 0;
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c)
        if (g.mesh.face_vertex(*f, k) == corners[c]) {
          p.bary[k] = std::abs(w[c]) < 1e-14 ? 0.0 : w[c];
          ++found;
        }
    if (found == 3) {
      p.bary /= p.bary.sum();
      return p;
    }
  }
  ADD_FAILURE() << "locate failed";
  return {};
}

std::vector<rs::SurfacePoint> circle(const Grid& g, double cx, double cy, double r, int n, bool ccw) {
  std::vector<rs::SurfacePoint> out;
  for (int k = 0; k < n; ++k) {
    const double t = (ccw ? 1 : -1) * 2 * M_PI * k / n;
    out.push_back(locate(g, cx + r * std::cos(t), cy + r * std::sin(t)));
  }
  return out;
}

struct XY {
  double x, y;
};
std::vector<XY> xy_of(const rs::Mesh& mesh, const std::vector<rs::SurfacePoint>& c) {
  std::vector<XY> out;
  for (const auto& p : c) {
    const Vec3 x = rs::position(mesh, p);
    out.push_back({x.x(), x.y()});
  }
  return out;
}

// Crossing-number point-in-polygon, and the distance to the polygon's edges.
bool inside_polygon(const std::vector<XY>& poly, double x, double y) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    if ((poly[i].y > y) != (poly[j].y > y) &&
        x < (poly[j].x - poly[i].x) * (y - poly[i].y) / (poly[j].y - poly[i].y) + poly[i].x)
      in = !in;
  }
  return in;
}
double distance_to_polyline(const std::vector<XY>& poly, bool closed, double x, double y) {
  double best = 1e300;
  const std::size_t segs = closed ? poly.size() : poly.size() - 1;
  for (std::size_t i = 0; i < segs; ++i) {
    const XY a = poly[i], b = poly[(i + 1) % poly.size()];
    const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
    double t = len2 > 0 ? ((x - a.x) * dx + (y - a.y) * dy) / len2 : 0;
    t = std::min(1.0, std::max(0.0, t));
    best = std::min(best, std::hypot(x - a.x - t * dx, y - a.y - t * dy));
  }
  return best;
}

// Counts vertices farther than `margin` from the polygon whose flag differs from point-in-polygon;
// *checked gets how many were compared, *inside how many of those are inside.
int mismatches(const Grid& g, const std::vector<char>& relief, const std::vector<XY>& poly, bool expect_inside,
               double margin, int* checked = nullptr, int* inside = nullptr) {
  int bad = 0, n = 0, in = 0;
  for (int v = 0; v < g.mesh.n_vertices(); ++v) {
    const Vec3& x = g.mesh.position(v);
    if (distance_to_polyline(poly, true, x.x(), x.y()) <= margin) continue;
    const bool truth = inside_polygon(poly, x.x(), x.y()) == expect_inside;
    ++n;
    in += truth;
    bad += (relief[v] != 0) != truth;
  }
  if (checked) *checked = n;
  if (inside) *inside = in;
  return bad;
}

}  // namespace

TEST(Region, CircleOnPlaneEitherOrientation) {
  const Grid g = make_grid(60, 60, 1.0, [](double, double) { return 0.0; });
  for (bool ccw : {true, false}) {
    const auto c = circle(g, 30.3, 29.7, 20.0, 150, ccw);
    const auto poly = xy_of(g.mesh, c);
    EXPECT_EQ(rs::contour_orientation_left(g.mesh, c), ccw);
    int checked = 0, inside = 0;
    const auto relief = rs::relief_region(g.mesh, c, true, ccw);
    EXPECT_EQ(mismatches(g, relief, poly, true, 1e-9, &checked, &inside), 0) << "ccw " << ccw;
    EXPECT_GT(inside, 1000);
    EXPECT_GT(checked - inside, 1000);
    // The wrong flag gives the complement.
    const auto outside = rs::relief_region(g.mesh, c, true, !ccw);
    EXPECT_EQ(mismatches(g, outside, poly, false, 1e-9), 0) << "ccw " << ccw;
  }
}

TEST(Region, SnaxelsOnVerticesAndEdges) {
  const Grid g = make_grid(50, 50, 1.0, [](double, double) { return 0.0; });
  // A square whose snaxels are all grid vertices: every segment runs along a mesh edge.
  std::vector<rs::SurfacePoint> square;
  for (int k = 0; k < 30; ++k) square.push_back(locate(g, 10 + k, 10));
  for (int k = 0; k < 30; ++k) square.push_back(locate(g, 40, 10 + k));
  for (int k = 0; k < 30; ++k) square.push_back(locate(g, 40 - k, 40));
  for (int k = 0; k < 30; ++k) square.push_back(locate(g, 10, 40 - k));
  ASSERT_TRUE(rs::contour_orientation_left(g.mesh, square));
  int inside = 0;
  EXPECT_EQ(mismatches(g, rs::relief_region(g.mesh, square, true, true), xy_of(g.mesh, square), true, 1e-9,
                       nullptr, &inside),
            0);
  EXPECT_EQ(inside, 29 * 29);
  // A circle through vertices (radius 20 around a vertex) and edge midpoints, with a diagonal chord.
  std::vector<rs::SurfacePoint> c = circle(g, 25, 25, 20, 64, true);
  c.insert(c.begin() + 8, locate(g, 25 + 14.5, 25 + 14.5));  // an edge midpoint on a cell diagonal
  EXPECT_EQ(mismatches(g, rs::relief_region(g.mesh, c, true, true), xy_of(g.mesh, c), true, 1e-9), 0);
}

TEST(Region, OpenContourSplitsAStripBySide) {
  const Grid g = make_grid(60, 20, 1.0, [](double, double) { return 0.0; });
  // From the bottom boundary to the top boundary, heading +y: the left side is -x.
  // Ends on boundary edges, then ends on boundary vertices.
  for (const std::vector<XY>& pts :
       {std::vector<XY>{{30.37, 0}, {31.2, 4.5}, {28.9, 9.1}, {29.55, 14.0}, {30.8, 17.3}, {29.6, 20}},
        std::vector<XY>{{30, 0}, {31.2, 4.5}, {28.9, 9.1}, {29.55, 14.0}, {30.8, 17.3}, {27, 20}}})
  for (bool left : {true, false}) {
    std::vector<rs::SurfacePoint> c;
    for (const XY& p : pts) c.push_back(locate(g, p.x, p.y));
    const auto relief = rs::relief_region(g.mesh, c, false, left);
    int bad = 0, checked = 0, relief_count = 0;
    for (int v = 0; v < g.mesh.n_vertices(); ++v) {
      const Vec3& x = g.mesh.position(v);
      if (distance_to_polyline(pts, false, x.x(), x.y()) <= 1e-9) continue;
      // x of the polyline at this height.
      std::size_t s = 0;
      while (s + 2 < pts.size() && pts[s + 1].y < x.y()) ++s;
      const double t = (x.y() - pts[s].y) / (pts[s + 1].y - pts[s].y);
      const double line_x = pts[s].x + t * (pts[s + 1].x - pts[s].x);
      const bool truth = (x.x() < line_x) == left;
      ++checked;
      relief_count += relief[v];
      bad += (relief[v] != 0) != truth;
    }
    EXPECT_EQ(bad, 0) << "left " << left << ", starting at x = " << pts[0].x;
    EXPECT_GT(relief_count, 500);
    EXPECT_LT(relief_count, checked - 500);
  }
}

TEST(Region, MissingPieceOfContourLeaksOnlyLocally) {
  const Grid g = make_grid(60, 60, 1.0, [](double, double) { return 0.0; });
  const auto c = circle(g, 30.3, 29.7, 20.0, 150, true);
  const auto poly = xy_of(g.mesh, c);
  // Treating the loop as open leaves its last segment untraced: a gap of ~1 edge in the cut.
  const auto relief = rs::relief_region(g.mesh, c, false, true);
  const XY gap{(poly.back().x + poly.front().x) / 2, (poly.back().y + poly.front().y) / 2};
  int bad = 0, bad_far = 0, inside = 0;
  for (int v = 0; v < g.mesh.n_vertices(); ++v) {
    const Vec3& x = g.mesh.position(v);
    if (distance_to_polyline(poly, true, x.x(), x.y()) <= 1e-9) continue;
    const bool truth = inside_polygon(poly, x.x(), x.y());
    inside += truth;
    if ((relief[v] != 0) != truth) {
      ++bad;
      if (std::hypot(x.x() - gap.x, x.y() - gap.y) > 4.0) ++bad_far;
    }
  }
  EXPECT_GT(inside, 1000);
  EXPECT_LE(bad, 10);
  EXPECT_EQ(bad_far, 0);
}

TEST(Region, CurvedBackgroundFarFromContourIsExact) {
  // Wavy background: traces are plane sections, so only vertices next to the contour may differ
  // from the xy polygon of the snaxels.
  const Grid g = make_grid(80, 80, 0.5, [](double x, double y) { return 2.0 * std::sin(0.3 * x) * std::cos(0.2 * y); });
  const auto c = circle(g, 20.1, 19.8, 13.0, 120, true);
  ASSERT_TRUE(rs::contour_orientation_left(g.mesh, c));
  int checked = 0, inside = 0;
  const auto relief = rs::relief_region(g.mesh, c, true, true);
  EXPECT_EQ(mismatches(g, relief, xy_of(g.mesh, c), true, g.h, &checked, &inside), 0);
  EXPECT_GT(inside, 1500);
}

TEST(Region, SpeedTwoThousandSnaxelsOnAMillionTriangles) {
  const int n = 708;  // 708^2 * 2 = 1,002,528 triangles
  const auto t0 = std::chrono::steady_clock::now();
  const Grid g = make_grid(n, n, 1.0, [](double x, double y) { return 0.001 * (x * x - y * y); });
  const auto t1 = std::chrono::steady_clock::now();
  const double cx = 354.2, cy = 353.9, r = 300.0;
  const auto c = circle(g, cx, cy, r, 2000, true);
  const auto t2 = std::chrono::steady_clock::now();
  const auto relief = rs::relief_region(g.mesh, c, true, true);
  const auto t3 = std::chrono::steady_clock::now();
  const double seconds = std::chrono::duration<double>(t3 - t2).count();
  std::cout << "[ timing ] mesh of " << g.mesh.n_faces() << " triangles built in "
            << std::chrono::duration<double>(t1 - t0).count() << " s; relief_region with " << c.size()
            << " snaxels: " << seconds << " s" << std::endl;
  RecordProperty("relief_region_seconds", std::to_string(seconds));
  EXPECT_EQ(g.mesh.n_faces(), 2 * n * n);
  // Away from the contour (chords are within r (1 - cos(pi/2000)) ~ 4e-4 of the circle): exact.
  int bad = 0, inside = 0;
  for (int v = 0; v < g.mesh.n_vertices(); ++v) {
    const Vec3& x = g.mesh.position(v);
    const double d = std::hypot(x.x() - cx, x.y() - cy);
    if (std::abs(d - r) < 1.0) continue;
    inside += d < r;
    bad += (relief[v] != 0) != (d < r);
  }
  EXPECT_EQ(bad, 0);
  EXPECT_NEAR(inside, M_PI * r * r, 0.01 * M_PI * r * r);
  EXPECT_LT(seconds, 5.0);
}

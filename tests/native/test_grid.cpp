// The engine's one hash grid (native/src/grid.hpp): neighbour searches agree with brute force,
// cell indices stay in range for georeferenced coordinates (offsets of 1e7 with millimetre
// cells, beyond what an int cell index holds) and for absurd or NaN ones, and the snake's
// grid users (loop removal, the convergence check) work the same far from the origin.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "../../native/src/grid.hpp"
#include "relief_snake/snake.hpp"
#include "test_meshes.hpp"

using namespace relief_snake;

namespace {

// Every item within `radius` of p, by brute force and through the grid's cells around p.
std::set<int> near_brute(const std::vector<Vec3>& points, const Vec3& p, double radius) {
  std::set<int> out;
  for (int i = 0; i < static_cast<int>(points.size()); ++i)
    if ((points[i] - p).norm() <= radius) out.insert(i);
  return out;
}

std::set<int> near_grid(const HashGrid& grid, const std::vector<Vec3>& points, const Vec3& p, double radius) {
  std::set<int> out;
  const int reach = static_cast<int>(std::ceil(radius / grid.cell_size()));
  const HashGrid::Cell c = grid.cell_of(p);
  for (int x = -reach; x <= reach; ++x)
    for (int y = -reach; y <= reach; ++y)
      for (int z = -reach; z <= reach; ++z)
        grid.for_each(c + HashGrid::Cell(x, y, z), [&](int i) {
          if ((points[i] - p).norm() <= radius) out.insert(i);
        });
  return out;
}

void expect_grid_matches_brute_force(const Vec3& offset, double cell) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 40 * cell);
  std::vector<Vec3> points;
  for (int i = 0; i < 2000; ++i) points.push_back(offset + Vec3(u(rng), u(rng), u(rng)));
  HashGrid grid(points[0], cell);
  for (int i = 0; i < static_cast<int>(points.size()); ++i) grid.add(grid.cell_of(points[i]), i);
  grid.build();
  for (int k = 0; k < 50; ++k) {
    const Vec3 p = offset + Vec3(u(rng), u(rng), u(rng));
    EXPECT_EQ(near_grid(grid, points, p, 2.5 * cell), near_brute(points, p, 2.5 * cell)) << "query " << k;
  }
}

}  // namespace

TEST(Grid, NeighboursMatchBruteForceNearTheOrigin) { expect_grid_matches_brute_force(Vec3::Zero(), 0.5); }

TEST(Grid, NeighboursMatchBruteForceAtGeoreferencedCoordinates) {
  // 1e7 (a UTM northing in metres) with 1 mm cells: 1e10 cells from the coordinate origin,
  // beyond an int; the grid counts cells from its own origin, near the items.
  expect_grid_matches_brute_force(Vec3(1e7, 1e7, 1e7), 1e-3);
  expect_grid_matches_brute_force(Vec3(-3e7, 5e6, 120.0), 1e-3);
}

TEST(Grid, CellIndicesAreClampedForAbsurdAndNaNCoordinates) {
  const HashGrid grid(Vec3::Zero(), 1e-3);
  const HashGrid::Cell far = grid.cell_of(Vec3(1e300, -1e300, 0.0));
  EXPECT_EQ(far.x(), static_cast<int>(HashGrid::kMaxIndex));
  EXPECT_EQ(far.y(), -static_cast<int>(HashGrid::kMaxIndex));
  EXPECT_EQ(far.z(), 0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const HashGrid coarse(Vec3::Zero(), 0.5);
  const HashGrid::Cell none = coarse.cell_of(Vec3(nan, 1.25, nan));
  EXPECT_EQ(none.x(), 0);
  EXPECT_EQ(none.y(), 2);
  EXPECT_EQ(none.z(), 0);
  // Neighbours of a clamped cell stay ints.
  const HashGrid::Cell next = far + HashGrid::Cell(1, -1, 0);
  EXPECT_GT(next.x(), far.x());
  EXPECT_LT(next.y(), far.y());
}

TEST(Grid, SnakeLoopRemovalAndConvergenceCheckFarFromTheOrigin) {
  // The twisted circle of Snake.RemoveLoopsCutsTheSmallSideOfACrossing, 1000 times smaller
  // (millimetres in metres) and moved to georeferenced coordinates: the loop grid's cells
  // (twice the longest segment, about 2.6 mm) would be 4e9 cells from the coordinate origin.
  const Vec3 offset(1e7, 1e7, 0);
  const double scale = 1e-3;
  const Mesh mesh = test::grid_mesh(41, 41, 20 * scale, 20 * scale,
                                    [&](double u, double v) { return Vec3(offset.x() + u, offset.y() + v, 0); });
  // The circle's points: straight walks of its radius from the centre vertex (20, 20).
  const SurfacePoint centre = vertex_point(mesh, 20 * 41 + 20);
  const Vec3 c = position(mesh, centre);
  std::vector<SurfacePoint> pts;
  for (int k = 0; k < 24; ++k) {
    const double a = 2 * M_PI * k / 24;
    pts.push_back(walk(mesh, centre, Vec3(std::cos(a), std::sin(a), 0), WalkOptions{5 * scale}).end);
  }
  std::swap(pts[6], pts[7]);
  Snake snake(mesh, pts, true, true);
  const int removed = snake.remove_loops();
  EXPECT_GE(removed, 1);
  EXPECT_LE(removed, 3);
  EXPECT_EQ(snake.remove_loops(), 0);
  EXPECT_GE(snake.size(), 21);
  for (int i = 0; i < snake.size(); ++i) EXPECT_NEAR((snake[i].position - c).norm(), 5 * scale, 0.1 * scale);
  // The convergence check: the snake is within a hair of itself, not within 0.1 mm of a circle
  // 0.2 mm smaller.
  const std::vector<Vec3> before = snake.polyline();
  EXPECT_TRUE(snake.within(before, 1e-9));
  std::vector<Vec3> smaller;
  for (const Vec3& p : before) smaller.push_back(c + (p - c) * (4.8 / 5.0));
  EXPECT_FALSE(snake.within(smaller, 0.1 * scale));
  EXPECT_TRUE(snake.within(smaller, 0.3 * scale));
}

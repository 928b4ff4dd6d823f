// The snake's housekeeping: resampling keeps the spacing, sharp turns go,
// open ends slide along the boundary, inward points inside.
#include <gtest/gtest.h>

#include <cmath>

#include "relief_snake/snake.hpp"
#include "relief_snake/step_anchors.hpp"
#include "test_meshes.hpp"

using namespace relief_snake;

namespace {

SurfacePoint point_at(const Mesh& mesh, const Vec3& target) {
  // Walk from the nearest vertex to the exact point (plane meshes only).
  int best = 0;
  for (int v = 1; v < mesh.n_vertices(); ++v)
    if ((mesh.position(v) - target).norm() < (mesh.position(best) - target).norm()) best = v;
  const SurfacePoint start = vertex_point(mesh, best);
  const Vec3 d = target - mesh.position(best);
  return d.norm() > 0 ? walk(mesh, start, d, WalkOptions{d.norm()}).end : start;
}

std::vector<SurfacePoint> circle(const Mesh& mesh, Vec3 c, double r, int n, bool ccw = true) {
  std::vector<SurfacePoint> pts;
  for (int k = 0; k < n; ++k) {
    const double a = (ccw ? 1 : -1) * 2 * M_PI * k / n;
    pts.push_back(point_at(mesh, c + r * Vec3(std::cos(a), std::sin(a), 0)));
  }
  return pts;
}

}  // namespace

TEST(Snake, ResampleKeepsSpacingWithinHalfToOneAndAHalfL) {
  const Mesh mesh = test::plane_mesh(61, 20);
  // Uneven circle: 12 points, then move a few close together.
  std::vector<SurfacePoint> pts = circle(mesh, Vec3(10, 10, 0), 6, 12);
  pts.insert(pts.begin() + 3, point_at(mesh, position(mesh, pts[3]) + Vec3(0.05, 0.05, 0)));
  Snake snake(mesh, pts, true, true);
  const double l = 1.0;
  snake.resample(l);
  ASSERT_GE(snake.size(), 30);
  for (int i = 0; i < snake.size(); ++i) {
    const double d = (snake[snake.next(i)].position - snake[i].position).norm();
    EXPECT_GE(d, 0.5 * l - 1e-9) << "segment " << i;
    EXPECT_LE(d, 1.5 * l + 1e-9) << "segment " << i;
  }
  // Points stay on the circle's neighbourhood (inserted on chords).
  for (int i = 0; i < snake.size(); ++i) EXPECT_NEAR((snake[i].position - Vec3(10, 10, 0)).norm(), 6, 0.4);
}

TEST(Snake, InwardPointsToTheCentreForEitherOrientation) {
  const Mesh mesh = test::plane_mesh(41, 20);
  for (bool ccw : {true, false}) {
    Snake snake(mesh, circle(mesh, Vec3(10, 10, 0), 5, 24, ccw), true, /*inside_left=*/ccw);
    for (int i = 0; i < snake.size(); ++i) {
      const Vec3 to_centre = (Vec3(10, 10, 0) - snake[i].position).normalized();
      EXPECT_GT(snake.inward(i).dot(to_centre), 0.99);
    }
  }
}

TEST(Snake, SharpTurnsAreRemoved) {
  const Mesh mesh = test::plane_mesh(41, 20);
  std::vector<SurfacePoint> pts = circle(mesh, Vec3(10, 10, 0), 5, 16);
  Snake snake(mesh, pts, true, true);
  // Fold a snaxel back onto its predecessor to make a turn of ~170 degrees.
  snake.move(5, point_at(mesh, snake[4].position + 0.98 * (snake[3].position - snake[4].position) +
                                   Vec3(0.05, 0, 0)));
  ASSERT_GT(snake.turn_degrees(4), 160);
  const int before = snake.size();
  EXPECT_GE(snake.remove_sharp_turns(160), 1);
  EXPECT_LT(snake.size(), before);
  for (int i = 0; i < snake.size(); ++i) EXPECT_LE(snake.turn_degrees(i), 160);
}

TEST(Snake, OpenEndsSlideAlongTheBoundary) {
  const Mesh mesh = test::plane_mesh(21, 10);
  const SurfacePoint end = point_at(mesh, Vec3(0, 5, 0));  // on the left border x = 0
  int f, k;
  ASSERT_TRUE(boundary_edge_of(mesh, end, &f, &k));
  const Vec3 a = position(mesh, slide_along_boundary(mesh, end, 1.3));
  const Vec3 b = position(mesh, slide_along_boundary(mesh, end, -1.3));
  EXPECT_NEAR(a.x(), 0, 1e-9);
  EXPECT_NEAR(b.x(), 0, 1e-9);
  EXPECT_NEAR(std::abs(a.y() - 5), 1.3, 1e-9);
  EXPECT_NEAR(std::abs(b.y() - 5), 1.3, 1e-9);
  EXPECT_NEAR(a.y() + b.y(), 10, 1e-9);  // opposite directions
  // Sliding around a corner continues on the next side.
  const Vec3 c = position(mesh, slide_along_boundary(mesh, point_at(mesh, Vec3(0, 1, 0)), a.y() > 5 ? -3.0 : 3.0));
  EXPECT_NEAR(c.y(), 0, 1e-9);
  EXPECT_NEAR(c.x(), 2, 1e-9);
}

TEST(Snake, AnOpenSnakeDropsTheSnaxelsHeldAlongTheBoundary) {
  // A plane 10 x 10: the snake runs along the bottom border from x = 1 to x = 4, turns up into the
  // mesh, across, and back down to the border at x = 8, then along it to x = 9.
  const Mesh mesh = test::plane_mesh(21, 10);
  std::vector<SurfacePoint> pts;
  for (double x = 1; x <= 4.01; x += 0.5) pts.push_back(point_at(mesh, Vec3(x, 0, 0)));
  for (double y = 1; y <= 5.01; y += 1) pts.push_back(point_at(mesh, Vec3(4, y, 0)));
  for (double x = 5; x <= 7.01; x += 1) pts.push_back(point_at(mesh, Vec3(x, 5, 0)));
  for (double y = 4; y >= 0.99; y -= 1) pts.push_back(point_at(mesh, Vec3(8, y, 0)));
  for (double x = 8; x <= 9.01; x += 0.5) pts.push_back(point_at(mesh, Vec3(x, 0, 0)));
  Snake snake(mesh, pts, false, true);
  const int before = snake.size();
  EXPECT_EQ(snake.trim_boundary_ends(), 6 + 2);  // x = 1 .. 3.5 at the start, x = 8.5, 9 at the end
  EXPECT_EQ(snake.size(), before - 8);
  // Each end is now the last boundary point before the snake leaves the boundary.
  EXPECT_NEAR((snake[0].position - Vec3(4, 0, 0)).norm(), 0, 1e-9);
  EXPECT_NEAR((snake[snake.size() - 1].position - Vec3(8, 0, 0)).norm(), 0, 1e-9);
  EXPECT_EQ(snake.trim_boundary_ends(), 0);  // nothing left to trim
  // A snake lying wholly along the boundary keeps three snaxels; a closed one is never trimmed.
  std::vector<SurfacePoint> border;
  for (double x = 1; x <= 9.01; x += 1) border.push_back(point_at(mesh, Vec3(x, 0, 0)));
  Snake flat(mesh, border, false, true);
  flat.trim_boundary_ends();
  EXPECT_EQ(flat.size(), 3);
  Snake loop(mesh, circle(mesh, Vec3(5, 5, 0), 3, 24), true, true);
  EXPECT_EQ(loop.trim_boundary_ends(), 0);
}

TEST(Snake, SubdivideReachesTheRequestedSpacing) {
  const Mesh mesh = test::plane_mesh(41, 20);
  Snake snake(mesh, circle(mesh, Vec3(10, 10, 0), 5, 10), true, true);
  snake.subdivide(0.25);
  const double expected = snake.length() / snake.size();
  EXPECT_NEAR(expected, 0.25, 0.05);
  for (int i = 0; i < snake.size(); ++i)
    EXPECT_NEAR((snake[snake.next(i)].position - snake[i].position).norm(), expected, 0.1);
}

TEST(Snake, RemoveLoopsCutsTheSmallSideOfACrossing) {
  const Mesh mesh = test::plane_mesh(41, 20);
  // A circle of 24 snaxels with a small twisted loop: snaxels 6 and 7 swapped
  // across the curve make segments 5-6 and 7-8 cross.
  std::vector<SurfacePoint> pts = circle(mesh, Vec3(10, 10, 0), 5, 24);
  std::swap(pts[6], pts[7]);
  Snake snake(mesh, pts, true, true);
  const int removed = snake.remove_loops();
  EXPECT_GE(removed, 1);
  EXPECT_LE(removed, 3);
  EXPECT_EQ(snake.remove_loops(), 0);  // nothing left to cut
  // Most of the circle survives.
  EXPECT_GE(snake.size(), 21);
  for (int i = 0; i < snake.size(); ++i) EXPECT_NEAR((snake[i].position - Vec3(10, 10, 0)).norm(), 5, 0.1);
}

TEST(Snake, RemoveLoopsKeepsTheLargerAreaNotTheMoreSnaxels) {
  // A figure eight: a big lobe of 11 snaxels (radius 8) and a small, densely
  // sampled lobe of 40 (radius 1.5) joined by two crossing segments, as when
  // a wrinkled stretch of the snake folds over. The big lobe is the outline.
  const Mesh mesh = test::plane_mesh(81, 40);
  const Vec3 c(20, 20, 0), small(29.5, 20, 0);
  std::vector<SurfacePoint> pts;
  for (int k = 0; k <= 10; ++k) {
    const double a = (10 + 34 * k) * M_PI / 180;  // 10 .. 350 degrees, counter-clockwise
    pts.push_back(point_at(mesh, c + 8 * Vec3(std::cos(a), std::sin(a), 0)));
  }
  for (int k = 0; k < 40; ++k) {
    const double a = M_PI / 2 - M_PI * k / 39;  // top to bottom through the right side
    pts.push_back(point_at(mesh, small + 1.5 * Vec3(std::cos(a), std::sin(a), 0)));
  }
  Snake snake(mesh, pts, true, true);
  EXPECT_GE(snake.remove_loops(), 40);
  EXPECT_LE(snake.size(), 11);
  for (int i = 0; i < snake.size(); ++i) EXPECT_NEAR((snake[i].position - c).norm(), 8, 1e-6) << "snaxel " << i;
}

TEST(Snake, RemoveLoopsLeavesASimpleCurveAlone) {
  const Mesh mesh = test::plane_mesh(41, 20);
  Snake snake(mesh, circle(mesh, Vec3(10, 10, 0), 5, 40), true, true);
  EXPECT_EQ(snake.remove_loops(), 0);
  EXPECT_EQ(snake.size(), 40);
}

TEST(Snake, WithinToleratesMotionAlongTheContourOnly) {
  const Mesh mesh = test::plane_mesh(41, 20);
  Snake snake(mesh, circle(mesh, Vec3(10, 10, 0), 5, 60), true, true);
  const std::vector<Vec3> before = snake.polyline();
  EXPECT_TRUE(snake.within(before, 1e-9));
  // The same circle sampled elsewhere along it (a circulation): still within.
  Snake rotated(mesh, circle(mesh, Vec3(10, 10, 0), 5, 47), true, true);
  EXPECT_TRUE(rotated.within(before, 0.05));   // chords of the 60-gon sag 0.007 at most
  // A circle 0.2 smaller: not within 0.1.
  Snake smaller(mesh, circle(mesh, Vec3(10, 10, 0), 4.8, 60), true, true);
  EXPECT_FALSE(smaller.within(before, 0.1));
  EXPECT_TRUE(smaller.within(before, 0.25));
}

TEST(Snake, NearestResamplingKeepsNewSnaxelsOffAOneTriangleWall) {
  // A relief x > 4.5 + 0.3 |y - 7| of height 1 whose wall is a single band of grid
  // triangles (no vertex on it), pointing its corner at y = 7. The chord between two
  // points at its foot (y = 6 and y = 8, x = 4.75) passes under the corner: a straight
  // surface walk along it climbs the wall, the surface point nearest the chord stays
  // at the foot (about 0.06 up the wall).
  const Mesh mesh = test::grid_mesh(81, 81, 20, 20, [](double u, double v) {
    return Vec3(u, v, u > 4.5 + 0.3 * std::abs(v - 7) + 1e-9 ? 1.0 : 0.0);
  });
  const SurfacePoint a = point_at(mesh, Vec3(4.75, 6, 0)), b = point_at(mesh, Vec3(4.75, 8, 0));
  ASSERT_NEAR(position(mesh, a).z(), 0, 1e-12);
  ASSERT_NEAR(position(mesh, b).z(), 0, 1e-12);
  std::vector<double> fractions;
  for (int k = 1; k < 20; ++k) fractions.push_back(k / 20.0);
  double walk_top = 0;
  for (const SurfacePoint& p : surface_between(mesh, a, b, fractions, false))
    walk_top = std::max(walk_top, position(mesh, p).z());
  EXPECT_GT(walk_top, 0.3);  // the failure the nearest point avoids
  for (const SurfacePoint& p : surface_between(mesh, a, b, fractions, true)) EXPECT_LT(position(mesh, p).z(), 0.1);
}

TEST(Snake, ACutLoopMakesTheNextIterationLookAtEverySnaxel) {
  const Mesh mesh = test::plane_mesh(41, 20);
  std::vector<SurfacePoint> pts = circle(mesh, Vec3(10, 10, 0), 5, 24);
  std::swap(pts[6], pts[7]);
  Snake snake(mesh, pts, true, true);
  std::vector<char> moved;
  snake.take_moved_flags(&moved);
  EXPECT_FALSE(snake.take_moved_flags(&moved));  // nothing cut yet
  ASSERT_GE(snake.remove_loops(), 1);
  EXPECT_TRUE(snake.take_moved_flags(&moved));  // once after the cut
  EXPECT_FALSE(snake.take_moved_flags(&moved));
  // The flags themselves: only the two ends of the new segment (the greedy step decides which
  // other snaxels it must look at, evolution.cpp).
  Snake cut(mesh, pts, true, true);
  cut.take_moved_flags(&moved);
  ASSERT_GE(cut.remove_loops(), 1);
  cut.take_moved_flags(&moved);
  int flagged = 0;
  for (const char m : moved) flagged += m;
  EXPECT_EQ(flagged, 2);
}

TEST(Snake, AStepLeftCountsTheOnStepAnchorsNoSnaxelComesNear) {
  const Mesh mesh = test::plane_mesh(41, 20);
  const Vec3 c(10, 10, 0);
  Snake snake(mesh, circle(mesh, c, 5, 80), true, true);
  // 40 anchors on the snake's circle; 38, 39, 0 and 1 (a run across the start) and 20 moved out to
  // radius 8, and anchor 10 off the step: 5 of 39 on-step anchors left, the longest run 4.
  StepAnchors anchors;
  for (int k = 0; k < 40; ++k) {
    const double a = 2 * M_PI * k / 40;
    const bool out = k == 38 || k == 39 || k == 0 || k == 1 || k == 20;
    anchors.points.push_back(c + (out ? 8.0 : 5.0) * Vec3(std::cos(a), std::sin(a), 0));
    anchors.on_step.push_back(k != 10);
  }
  anchors.spacing = 2 * M_PI * 5 / 40;
  EXPECT_EQ(anchors.on_step_count(), 39);
  const StepLeft left = step_left(anchors, snake, 1.0);
  EXPECT_NEAR(left.share, 5.0 / 39, 1e-12);
  EXPECT_NEAR(left.longest, 4 * anchors.spacing, 1e-12);
  // Open contours' runs do not wrap: 38-39 and 0-1 are two runs of 2.
  anchors.closed = false;
  EXPECT_NEAR(step_left(anchors, snake, 1.0).longest, 2 * anchors.spacing, 1e-12);
  // Within 3.5 of a snaxel every anchor is reached.
  EXPECT_EQ(step_left(anchors, snake, 3.5).share, 0.0);
}

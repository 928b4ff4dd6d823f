// Settling a contour at the foot of the step (foot.hpp).
#include <gtest/gtest.h>

#include <cmath>

#include "relief_snake/foot.hpp"
#include "synthetic.hpp"

using namespace relief_snake;
namespace syn = relief_snake::synthetic;

namespace {

// A closed snake on the circle of radius r around the disk relief's centre (counter-
// clockwise, relief inside), through the vertices nearest to it.
Snake circle_snake(const Mesh& mesh, const syn::Scan& scan, double r, int n) {
  std::vector<SurfacePoint> points;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    points.push_back(vertex_point(mesh, scan.nearest_vertex(r * std::cos(a), r * std::sin(a))));
  }
  return Snake(mesh, points, true, true);
}

double mean_radius(const Snake& snake) {
  double sum = 0;
  for (int i = 0; i < snake.size(); ++i) sum += std::hypot(snake[i].position.x(), snake[i].position.y());
  return sum / snake.size();
}

// The disk relief (radius 12: the foot of its blended step is at r = 12) on 60k triangles.
syn::Scan blended_disk(double noise = 0) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Disk;
  spec.step = syn::Step::Blended;
  spec.triangles = 60000;
  spec.noise = noise;
  return syn::generate(spec);
}

}  // namespace

TEST(Foot, MovesASnakeFromTheSlopeOutToTheFoot) {
  const syn::Scan scan = blended_disk();
  const Mesh mesh = syn::to_mesh(scan);
  Snake snake = circle_snake(mesh, scan, 11.75, 150);  // a quarter h up the slope
  ASSERT_LT(mean_radius(snake), 11.85);
  FootOptions o;
  o.h = scan.h;
  const FootResult r = settle_at_foot(&snake, o);
  EXPECT_FALSE(r.noisy);
  // Most of the 150. Not all: walked obliquely from this jagged snake (through the vertices
  // nearest the circle), some bands reach onto the slope (residual 0.02 h), and read at those
  // snaxels their fits cannot tell the slope from the background (118 moved; 123 before the
  // threshold allowed for the fit's error).
  EXPECT_GT(r.moved, 110);
  EXPECT_NEAR(mean_radius(snake), 12.0, 0.1);
  // Already at the foot: (almost) nothing moves.
  Snake outside = circle_snake(mesh, scan, 12.3, 150);
  const double before = mean_radius(outside);
  settle_at_foot(&outside, o);
  EXPECT_NEAR(mean_radius(outside), before, 0.03);
}

TEST(Foot, LeavesAContourMostlyWithoutCleanBackgroundAlone) {
  const syn::Scan scan = blended_disk();
  const Mesh mesh = syn::to_mesh(scan);
  FootOptions o;
  o.h = scan.h;
  o.max_unclean_share = 0.5;
  Snake snake = circle_snake(mesh, scan, 11.75, 150);
  const FootResult clean = settle_at_foot(&snake, o);
  EXPECT_FALSE(clean.unclean);
  EXPECT_GT(clean.moved, 110);  // as in MovesASnakeFromTheSlopeOutToTheFoot
  // A band beyond the mesh's edge for every snaxel: no clean background anywhere.
  o.band_from = 30;
  o.band_to = 40;
  Snake far = circle_snake(mesh, scan, 11.75, 150);
  const double before = mean_radius(far);
  const FootResult none = settle_at_foot(&far, o);
  EXPECT_TRUE(none.unclean);
  EXPECT_EQ(none.moved, 0);
  EXPECT_EQ(mean_radius(far), before);
  o.max_unclean_share = 1.0;  // the plain foot stage: each snaxel on its own, nothing to move either
  const FootResult plain = settle_at_foot(&far, o);
  EXPECT_FALSE(plain.unclean);
  EXPECT_EQ(plain.moved, 0);
}

TEST(Foot, LeavesANoisyBackgroundAlone) {
  const syn::Scan scan = blended_disk(0.05);
  const Mesh mesh = syn::to_mesh(scan);
  Snake snake = circle_snake(mesh, scan, 11.75, 300);
  const double before = mean_radius(snake);
  FootOptions o;
  o.h = scan.h;
  const FootResult r = settle_at_foot(&snake, o);
  EXPECT_TRUE(r.noisy);
  EXPECT_EQ(r.moved, 0);
  EXPECT_EQ(mean_radius(snake), before);
}


// Pooled profiles (FootOptions::pool): on a background with noise of 0.04 h, each snaxel's own band
// is too rough for the foot to show through 4 times its residual, and snaxels stay part of the way up
// the slope; the median of 11 neighbours' profiles (about 1 h of contour on each side) has a lower
// residual and the contour comes nearer the foot (measured: residual 0.0071 h alone, 0.0051 h pooled,
// not the square root of 11 lower: neighbouring profiles cross the same faces; mean radius 11.92
// alone, 11.98 pooled, the foot at 12).
TEST(Foot, PooledProfilesFindTheFootThroughNoise) {
  const syn::Scan scan = blended_disk(0.04);
  const Mesh mesh = syn::to_mesh(scan);
  FootOptions o;
  o.h = scan.h;
  o.max_noise = 0.05;  // as the gated stage (segment.cpp) has it
  Snake alone = circle_snake(mesh, scan, 11.75, 150);
  const FootResult single = settle_at_foot(&alone, o);
  o.pool = 5;
  Snake pooled = circle_snake(mesh, scan, 11.75, 150);
  const FootResult pool = settle_at_foot(&pooled, o);
  EXPECT_LT(pool.background_residual, single.background_residual);
  EXPECT_LT(std::fabs(mean_radius(pooled) - 12.0), std::fabs(mean_radius(alone) - 12.0));
  EXPECT_NEAR(mean_radius(pooled), 12.0, 0.1);
  // Already at the foot on a clean background: pooling does not push it further out. (On this noisy
  // one it does, as each snaxel alone does: a contour 0.3 h outside the foot moved out by 0.24 h on
  // average pooled, 0.15 h alone (mean radius), a sample near the band's inner end rising past the threshold. The
  // gated stage runs only where the contour sits up a wide rise, segment.cpp.)
  const syn::Scan clean_scan = blended_disk();
  const Mesh clean_mesh = syn::to_mesh(clean_scan);
  Snake outside = circle_snake(clean_mesh, clean_scan, 12.3, 150);
  const double before = mean_radius(outside);
  settle_at_foot(&outside, o);
  EXPECT_NEAR(mean_radius(outside), before, 0.03);
}

// The toe (FootOptions::toe): a smoothstep as wide as the step is tall, on a scan with about 9 edges
// per h, leaves the background so gently that the surface clears the threshold only some way inside
// the true foot; the toe's fit of the square root of the rise carries the snaxels out to the foot.
// Fitted against the distance walked along the surface instead of the distance across, it overshot:
// the contour ended 0.68 edges outside the foot (the blend's slope, up to 1.5, stretches the walk).
TEST(Foot, TheToeFindsTheFootOfATangentBlend) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Disk;
  spec.step = syn::Step::Blended;
  spec.h = 4;  // the disk's radius stays 12: the blend runs from r = 8 (top) out to r = 12 (foot)
  spec.blend_width = 1.0;
  spec.triangles = 60000;
  const syn::Scan scan = syn::generate(spec);
  const Mesh mesh = syn::to_mesh(scan);
  const double edge = mesh.average_edge_length();
  FootOptions o;
  o.h = scan.h;
  Snake crossing = circle_snake(mesh, scan, 11.0, 150);  // a quarter h in, 0.16 h up the blend
  const FootResult plain = settle_at_foot(&crossing, o);
  o.toe = true;
  Snake toe = circle_snake(mesh, scan, 11.0, 150);
  const FootResult fitted = settle_at_foot(&toe, o);
  EXPECT_EQ(plain.toe_fitted, 0);
  EXPECT_GT(fitted.toe_fitted, 100);
  EXPECT_GT(12.0 - mean_radius(crossing), 0.3 * edge);        // the crossing stops inside the foot
  // The toe comes nearer the foot than the crossing, within a third of an edge (measured: the crossing
  // 0.38 edges inside, the toe 0.25 edges outside; the square root of the smoothstep's toe is concave, so
  // the line meets zero a little outside).
  EXPECT_LT(std::fabs(mean_radius(toe) - 12.0), 12.0 - mean_radius(crossing));
  EXPECT_LT(std::fabs(mean_radius(toe) - 12.0), edge / 3);
}

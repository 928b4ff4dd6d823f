// Background inside a region (background_inside.hpp) on generated scans with exact truth: the true
// relief region holds no piece of background deeper than a strip; a region that also takes in a
// lobe of background does, and the piece is where the lobe is; a hollow inside the relief (a drop)
// does not count, since it does not reach the contour.
#include <gtest/gtest.h>

#include <cmath>

#include "relief_snake/background_inside.hpp"
#include "relief_snake/evidence.hpp"
#include "synthetic.hpp"

using namespace relief_snake;
namespace syn = relief_snake::synthetic;

namespace {

syn::Scan disk_scan(syn::Background background, syn::Step step, bool drop = false) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Disk;  // radius 12 round the parameter plane's origin
  spec.background = background;
  spec.step = step;
  spec.h = 1.0;
  spec.drop = drop;
  spec.triangles = 60000;
  return syn::generate(spec);
}

// The disk, and optionally a disk of background of radius `lobe` centred `lobe` outside its edge
// at angle 0 (parameter plane).
std::vector<char> disk_region(const syn::Scan& scan, const Mesh& mesh, double lobe) {
  std::vector<char> region(mesh.n_vertices(), 0);
  for (std::size_t i = 0; i < scan.n_vertices(); ++i) {
    const double u = scan.UV[2 * i], w = scan.UV[2 * i + 1];
    const int v = mesh.input_to_mesh(i);
    if (v < 0) continue;
    region[v] = std::hypot(u, w) < 12 || (lobe > 0 && std::hypot(u - 12 - lobe, w) < lobe);
  }
  return region;
}

double depth_limit(const Mesh& mesh, double h) {
  return std::max(SelfCheckOptions{}.max_background_depth * h, 2 * mesh.average_edge_length());
}

}  // namespace

TEST(BackgroundInside, TheTrueReliefHoldsNoPieceOfBackground) {
  for (const auto background : {syn::Background::Plane, syn::Background::Cylinder, syn::Background::Sphere,
                                syn::Background::Saddle}) {
    for (const auto step : {syn::Step::Sharp, syn::Step::Blended}) {
      SCOPED_TRACE(std::to_string(static_cast<int>(background)) + (step == syn::Step::Sharp ? " sharp" : " blended"));
      const syn::Scan scan = disk_scan(background, step);
      const Mesh mesh = syn::to_mesh(scan);
      const BackgroundSolver solver(mesh);
      const BackgroundInside in = measure_background_inside(mesh, disk_region(scan, mesh, 0), scan.h, scan.h, &solver);
      ASSERT_TRUE(in.measured);
      EXPECT_LT(in.depth, depth_limit(mesh, scan.h));
    }
  }
}

TEST(BackgroundInside, ALobeOfBackgroundIsFoundWhereItIs) {
  for (const auto background : {syn::Background::Plane, syn::Background::Sphere, syn::Background::Saddle}) {
    SCOPED_TRACE(static_cast<int>(background));
    const syn::Scan scan = disk_scan(background, syn::Step::Blended);
    const Mesh mesh = syn::to_mesh(scan);
    const BackgroundSolver solver(mesh);
    const double lobe = 2.5 * scan.h;
    const std::vector<char> region = disk_region(scan, mesh, lobe);
    const BackgroundInside in = measure_background_inside(mesh, region, scan.h, scan.h, &solver);
    ASSERT_TRUE(in.measured);
    EXPECT_GT(in.depth, depth_limit(mesh, scan.h));
    EXPECT_GT(in.area, 0.5 * M_PI * lobe * lobe);  // most of the lobe (its part over the blend is not low)
    ASSERT_GE(in.deepest_vertex, 0);
    // The deepest point lies in the lobe, and the region without the piece is the disk again.
    const Vec3 p = mesh.position(in.deepest_vertex);
    const std::vector<char> disk = disk_region(scan, mesh, 0);
    EXPECT_FALSE(disk[in.deepest_vertex]) << p.transpose();
    const std::vector<char> cut = in.region_without(region, depth_limit(mesh, scan.h));
    // The disk loses only the low part of its blended step next to the lobe (the blend is 0.5 h wide).
    std::vector<double> radius(mesh.n_vertices(), 0.0);
    for (std::size_t i = 0; i < scan.n_vertices(); ++i)
      if (mesh.input_to_mesh(i) >= 0) radius[mesh.input_to_mesh(i)] = std::hypot(scan.UV[2 * i], scan.UV[2 * i + 1]);
    int lobe_left = 0, disk_lost = 0;
    for (int v = 0; v < mesh.n_vertices(); ++v) {
      lobe_left += cut[v] && !disk[v];
      disk_lost += disk[v] && !cut[v] && radius[v] < 12 - 0.5 * scan.h - mesh.average_edge_length();
    }
    EXPECT_LT(lobe_left, 0.1 * std::count(region.begin(), region.end(), 1) * (lobe * lobe) / (12.0 * 12.0));
    EXPECT_EQ(disk_lost, 0);
    // The quadric model sees the same lobe on these quadric backgrounds.
    BackgroundInsideOptions quadric;
    quadric.model = BackgroundInsideModel::RingQuadric;
    EXPECT_GT(measure_background_inside(mesh, region, scan.h, scan.h, nullptr, quadric).depth,
              depth_limit(mesh, scan.h));
  }
}

TEST(BackgroundInside, AHollowInsideTheReliefIsNotBackgroundTakenIn) {
  // The drop: the relief rises by h at its edge, then falls to 0.3 h, below half the step.
  const syn::Scan scan = disk_scan(syn::Background::Sphere, syn::Step::Sharp, true);
  const Mesh mesh = syn::to_mesh(scan);
  const BackgroundSolver solver(mesh);
  const BackgroundInside in = measure_background_inside(mesh, disk_region(scan, mesh, 0), scan.h, scan.h, &solver);
  ASSERT_TRUE(in.measured);
  EXPECT_LT(in.depth, depth_limit(mesh, scan.h));
  bool hollow_seen = false;  // the hollow is a low piece, just not one that reaches the contour
  for (const double d : in.piece_depth) hollow_seen = hollow_seen || d < 0;
  EXPECT_TRUE(hollow_seen);
}

TEST(BackgroundInside, NothingToMeasureWithoutARingOrAStep) {
  const syn::Scan scan = disk_scan(syn::Background::Plane, syn::Step::Sharp);
  const Mesh mesh = syn::to_mesh(scan);
  const BackgroundSolver solver(mesh);
  const std::vector<char> all(mesh.n_vertices(), 1);
  EXPECT_FALSE(measure_background_inside(mesh, all, scan.h, scan.h, &solver).measured);
  EXPECT_FALSE(measure_background_inside(mesh, disk_region(scan, mesh, 0), scan.h, 0.0, &solver).measured);
  EXPECT_FALSE(measure_background_inside(mesh, disk_region(scan, mesh, 0), scan.h, scan.h, nullptr).measured);
  EXPECT_FALSE(measure_background_inside(mesh, std::vector<char>(3, 1), scan.h, scan.h, &solver).measured);
}

TEST(BackgroundInside, TheCheckSaysWhetherItCouldLook) {
  // The segmenter's check: on the true relief its screen sees nothing deep, so no piece is
  // reported (measured stays false), but the region was checked, and the self-check relies on it
  // instead of the contour's far run. With no ring round the region it could not look at all.
  const syn::Scan scan = disk_scan(syn::Background::Sphere, syn::Step::Blended);
  const Mesh mesh = syn::to_mesh(scan);
  BackgroundInsideCheck check(mesh);
  const double limit = depth_limit(mesh, scan.h);
  const BackgroundInside right = check.measure(disk_region(scan, mesh, 0), scan.h, scan.h, limit);
  EXPECT_TRUE(right.checked);
  EXPECT_FALSE(right.measured && deep_background_piece(right.depth, right.area, limit));
  const BackgroundInside lobe = check.measure(disk_region(scan, mesh, 2.5 * scan.h), scan.h, scan.h, limit);
  EXPECT_TRUE(lobe.checked);
  ASSERT_TRUE(lobe.measured);
  EXPECT_TRUE(deep_background_piece(lobe.depth, lobe.area, limit));
  const BackgroundInside none = check.measure(std::vector<char>(mesh.n_vertices(), 1), scan.h, scan.h, limit);
  EXPECT_FALSE(none.checked);
  EXPECT_FALSE(none.measured);
}

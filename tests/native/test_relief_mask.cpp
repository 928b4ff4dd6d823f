// The relief as the heights see it (relief_mask.hpp), the start outline from it, and the height
// barrier of the greedy step (evolution.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "relief_snake/evolution.hpp"
#include "relief_snake/mesh_graph.hpp"
#include "relief_snake/relief_mask.hpp"
#include "relief_snake/snake.hpp"
#include "synthetic.hpp"

namespace relief_snake {
namespace {

namespace syn = synthetic;

// A gear with four slots 2.5 h wide on a plane under striations of 0.25 h: the texture's planarity
// holds a snake from the picks short of the slots; the heights do not care.
syn::Scan striated_gear() {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Gear;
  spec.triangles = 60000;
  spec.h = 1;
  spec.gear_radius = 14;
  spec.gear_slot_depth = 5;
  spec.slot_widths = {10, 10, 10, 10};  // in nominal edges (about 2.5 h here)
  spec.texture = syn::Texture::Striations;
  spec.texture_amplitude = 0.25;
  spec.texture_period = 1.5;
  spec.texture_angle = 0.6;
  spec.seed = 5;
  return syn::generate(spec);
}

double area_of(const Mesh& mesh, const std::vector<char>& flags) {
  double a = 0;
  for (int v = 0; v < mesh.n_vertices(); ++v)
    if (flags[v]) a += mesh.vertex_area(v);
  return a;
}

// The seed bridges every slot (the disk the gear's teeth reach): the mask finds the slots again, and
// the start region holds the whole relief while leaving the slots' floors open.
TEST(ReliefMask, FindsTheSlotsASeedBridgedUnderStriations) {
  const syn::Scan scan = striated_gear();
  const Mesh mesh = syn::to_mesh(scan);
  std::vector<char> truth(scan.relief.begin(), scan.relief.end());
  std::vector<char> seed(mesh.n_vertices(), 0);
  for (int v = 0; v < mesh.n_vertices(); ++v) seed[v] = std::hypot(scan.UV[2 * v], scan.UV[2 * v + 1]) < 14;
  const ReliefMask mask = relief_mask(mesh, seed, scan.h, scan.h);
  ASSERT_TRUE(mask.ok) << mask.failure;
  double both = 0, either = 0, truth_in_start = 0, floor = 0, floor_in_start = 0;
  for (int v = 0; v < mesh.n_vertices(); ++v) {
    const double a = mesh.vertex_area(v);
    both += truth[v] && mask.mask[v] ? a : 0.0;
    either += truth[v] || mask.mask[v] ? a : 0.0;
    truth_in_start += truth[v] && mask.start_region[v] ? a : 0.0;
    // The slots' floors well away from their walls: seed, not relief, more than 0.75 h from the relief.
    if (seed[v] && !truth[v] && -scan.signed_distance(scan.UV[2 * v], scan.UV[2 * v + 1]) < -1.25 * scan.h) {
      floor += a;
      floor_in_start += mask.start_region[v] ? a : 0.0;
    }
  }
  const double iou = both / either;
  std::printf("[ measured ] mask IoU %.3f, relief in the start region %.4f, slot floors in it %.3f, %.2f s\n", iou,
              truth_in_start / area_of(mesh, truth), floor_in_start / floor, mask.seconds);
  EXPECT_GT(iou, 0.9);
  EXPECT_GT(truth_in_start / area_of(mesh, truth), 0.995);
  ASSERT_GT(floor, 0);
  EXPECT_LT(floor_in_start / floor, 0.1);
  // The outline runs round it as one loop, with the relief on its left.
  const std::vector<int> loop = start_outline(mesh, mask.start_region, true);
  EXPECT_GT(loop.size(), 100u);
}

// Nothing stands above the level: no mask, and a reason.
TEST(ReliefMask, ABarePlaneHasNone) {
  syn::ScanSpec spec = striated_gear().spec;
  spec.h = 1;
  const syn::Scan gear = syn::generate(spec);
  const Mesh mesh = syn::to_mesh(gear);
  std::vector<char> seed(mesh.n_vertices(), 0);
  // A disk of background beside the gear.
  for (int v = 0; v < mesh.n_vertices(); ++v) seed[v] = std::hypot(gear.UV[2 * v] - 28, gear.UV[2 * v + 1]) < 6;
  const ReliefMask mask = relief_mask(mesh, seed, gear.h, gear.h);
  EXPECT_FALSE(mask.ok);
  EXPECT_FALSE(mask.failure.empty());
}

// An open contour's start: the stretch of the region's loop off the mesh boundary, from one boundary
// vertex to another.
TEST(ReliefMask, AnOpenStartRunsFromTheMeshBoundaryToTheMeshBoundary) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Band;
  spec.triangles = 40000;
  spec.h = 1;
  spec.band_length = 30;
  spec.band_half_width = 5;
  const syn::Scan scan = syn::generate(spec);
  const Mesh mesh = syn::to_mesh(scan);
  std::vector<char> truth(scan.relief.begin(), scan.relief.end());
  const std::vector<char> region = grown_region(mesh, truth, 1.0);
  const std::vector<int> path = start_outline(mesh, region, false);
  ASSERT_GT(path.size(), 20u);
  EXPECT_TRUE(mesh.is_boundary_vertex(path.front()));
  EXPECT_TRUE(mesh.is_boundary_vertex(path.back()));
  for (std::size_t k = 1; k + 1 < path.size(); ++k) EXPECT_FALSE(mesh.is_boundary_vertex(path[k])) << k;
  // A closed region has no open start.
  std::vector<char> inner(mesh.n_vertices(), 0);
  for (int v = 0; v < mesh.n_vertices(); ++v) inner[v] = std::hypot(scan.UV[2 * v] + 30, scan.UV[2 * v + 1]) < 3;
  EXPECT_TRUE(start_outline(mesh, inner, false).empty());
}

// The greedy step with a barrier: deflation pushes a snake inwards across a disk's step, but no
// snaxel moves onto ground above the level (it may stay where it is or move down).
TEST(HeightBarrier, DeflationDoesNotCarryASnakeOntoTheRelief) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Disk;
  spec.triangles = 30000;
  spec.h = 1;
  const syn::Scan scan = syn::generate(spec);
  const Mesh mesh = syn::to_mesh(scan);
  std::vector<double> height(mesh.n_vertices());
  for (int v = 0; v < mesh.n_vertices(); ++v) height[v] = scan.relief_height[v];
  // A ring of snaxels 2 h outside the disk's edge (the relief outline), counter-clockwise.
  double radius = 0;
  for (const Vec3& p : scan.boundary.front().points) radius += std::hypot(p.x(), p.y());
  radius /= scan.boundary.front().points.size();
  std::vector<SurfacePoint> ring;
  const int n = 200;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    const Vec3 target((radius + 2) * std::cos(a), (radius + 2) * std::sin(a), 0);
    int nearest = 0;
    for (int v = 1; v < mesh.n_vertices(); ++v)
      if ((mesh.position(v) - target).squaredNorm() < (mesh.position(nearest) - target).squaredNorm()) nearest = v;
    ring.push_back(vertex_point(mesh, nearest));
  }
  Snake snake(mesh, ring, true, true);
  PlanarityOptions po;
  po.radius = scan.h;
  PlanarityField planarity(mesh, po);
  FeatureEnergy feature(planarity, scan.h, 0.2, 5);
  PhaseSettings phase;
  phase.l = 0.5 * mesh.average_edge_length();
  phase.alpha = normalise_alpha(phase.l);
  phase.beta = normalise_beta(phase.l, 160);
  phase.w_int = 0.25;
  phase.w_f = 0;  // no feature energy to hold it: deflation alone
  phase.w_d = 3.5;
  phase.max_iterations = 400;
  phase.barrier = &height;
  phase.barrier_level = 0.5 * scan.h;
  snake.subdivide(phase.l);
  for (int it = 0; it < 400; ++it) greedy_iteration(snake, feature, phase);
  double highest = 0;
  for (int i = 0; i < snake.size(); ++i)
    highest = std::max(highest, interpolate(mesh, snake[i].point, [&](int v) { return height[v]; }));
  std::printf("[ measured ] highest snaxel %.3f h after 400 iterations (%d snaxels)\n", highest, snake.size());
  EXPECT_LE(highest, 0.5 * scan.h + 1e-9);
  // Without the barrier the same deflation carries it onto the disk.
  Snake free(mesh, ring, true, true);
  free.subdivide(phase.l);
  phase.barrier = nullptr;
  for (int it = 0; it < 400; ++it) greedy_iteration(free, feature, phase);
  double free_highest = 0;
  for (int i = 0; i < free.size(); ++i)
    free_highest = std::max(free_highest, interpolate(mesh, free[i].point, [&](int v) { return height[v]; }));
  EXPECT_GT(free_highest, 0.9 * scan.h);
}

}  // namespace
}  // namespace relief_snake

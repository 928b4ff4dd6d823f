// The whole segmentation does not depend on the thread count (docs/design.md, "Order of the
// greedy moves"): threads = 1, 2, 3 and 0 (all cores) give the same contour, bit for bit, the
// same region and the same status, on a closed and an open generated scan.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "relief_snake/segment.hpp"
#include "synthetic.hpp"

using namespace relief_snake;
namespace syn = relief_snake::synthetic;

namespace {

struct Run {
  Status status;
  std::vector<Vec3> contour;
  std::vector<std::int64_t> region;
  int attempts;
};

Run run(const Mesh& mesh, const syn::Picks& picks, double h, int threads, bool foot_snap) {
  Options options;
  options.step_height = h;
  options.closed = picks.closed;
  options.relief_side = picks.relief_side;
  options.threads = threads;
  options.foot_snap = foot_snap;
  const Result r = segment(mesh, picks.vertices, options);
  return {r.status, r.polyline, r.relief_vertices, r.attempts};
}

void expect_same_for_every_thread_count(const syn::ScanSpec& spec, syn::Start start, bool foot_snap) {
  const syn::Scan scan = syn::generate(spec);
  const Mesh mesh = syn::to_mesh(scan);
  syn::PickSpec pick_spec;
  pick_spec.start = start;
  const syn::Picks picks = scan.picks(pick_spec);
  const Run serial = run(mesh, picks, scan.h, 1, foot_snap);
  ASSERT_GE(serial.contour.size(), 10u);
  ASSERT_FALSE(serial.region.empty());
  for (const int threads : {2, 3, 0}) {
    const Run parallel = run(mesh, picks, scan.h, threads, foot_snap);
    EXPECT_EQ(parallel.status, serial.status) << "threads " << threads;
    EXPECT_EQ(parallel.attempts, serial.attempts) << "threads " << threads;
    ASSERT_EQ(parallel.contour.size(), serial.contour.size()) << "threads " << threads;
    for (std::size_t k = 0; k < serial.contour.size(); ++k)
      ASSERT_TRUE(parallel.contour[k] == serial.contour[k])  // exact, not within a tolerance
          << "threads " << threads << ", snaxel " << k << ": " << parallel.contour[k].transpose() << " vs "
          << serial.contour[k].transpose();
    EXPECT_EQ(parallel.region, serial.region) << "threads " << threads;
  }
}

TEST(ThreadIndependence, ClosedDuckFromAZigzagStart) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Duck;
  spec.step = syn::Step::Blended;
  spec.triangles = 30000;
  expect_same_for_every_thread_count(spec, syn::Start::Zigzag, false);
}

TEST(ThreadIndependence, OpenNoisyScanWithTheFootSnap) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Open;
  spec.step = syn::Step::Sharp;
  spec.triangles = 30000;
  spec.noise = 0.02;
  expect_same_for_every_thread_count(spec, syn::Start::Near, true);
}

}  // namespace

// The evolution schedule (schedule.hpp): refinements from the coarse snake, and the early stop
// of a refinement whose contour shrinks away from the coarse one, or leaves the step the coarse one
// sat on (it is crossing the relief).
#include <gtest/gtest.h>

#include "relief_snake/evidence.hpp"
#include "relief_snake/initial_contour.hpp"
#include "relief_snake/planarity.hpp"
#include "relief_snake/region.hpp"
#include "relief_snake/schedule.hpp"
#include "synthetic.hpp"

using namespace relief_snake;
namespace syn = relief_snake::synthetic;

namespace {

struct DiskSchedule {
  syn::Scan scan;
  Mesh mesh;
  std::unique_ptr<PlanarityField> planarity;
  std::unique_ptr<EvolutionSchedule> schedule;

  DiskSchedule() {
    syn::ScanSpec spec;
    spec.shape = syn::Shape::Disk;
    spec.step = syn::Step::Blended;
    spec.triangles = 40000;
    scan = syn::generate(spec);
    mesh = syn::to_mesh(scan);
    const syn::Picks picks = scan.picks(syn::PickSpec{});
    std::vector<int> vertices;
    for (const std::int64_t p : picks.vertices) vertices.push_back(mesh.input_to_mesh(static_cast<std::size_t>(p)));
    const InitialContour initial = initial_contour(mesh, vertices, true);
    const std::vector<SurfacePoint> start = resample_path(mesh, initial.path, scan.h, true);
    PlanarityOptions po;
    po.radius = scan.h;
    planarity = std::make_unique<PlanarityField>(mesh, po);
    std::vector<int> sample;
    for (int v = 0; v < mesh.n_vertices(); v += 13) sample.push_back(v);
    planarity->estimate_sigma_s(sample);
    Options options;
    options.step_height = scan.h;
    schedule = std::make_unique<EvolutionSchedule>(mesh, *planarity, options, scan.h, start,
                                                   picks.relief_side == ReliefSide::Left);
  }
};

double enclosed(const Mesh& mesh, const std::vector<SurfacePoint>& contour) {
  std::vector<Vec3> line;
  for (const SurfacePoint& p : contour) line.push_back(position(mesh, p));
  return vector_area(line).norm();
}

// The self-check's verdict on an otherwise good contour whose refinement was abandoned.
SelfCheck abandoned_verdict(double h, double area_share, double left_share) {
  ContourEvidence e;
  e.step.attempted = 10;
  e.step.profiles.resize(10);
  e.step.step_share = 1.0;
  e.step.step_height = h;
  e.abandoned_area_share = area_share;
  e.abandoned_left_share = left_share;
  return judge(e, h);
}

RefineStop area_stop(double share) {
  RefineStop stop;
  stop.min_area_share = share;
  return stop;
}

}  // namespace

TEST(Schedule, ARefinementThatKeepsItsAreaRunsToTheEnd) {
  DiskSchedule d;
  const ScheduleRun& coarse = d.schedule->coarse(nullptr);
  ASSERT_FALSE(coarse.collapsed);
  // The disk's contour keeps its area through refinement: half the coarse area never stops it.
  const ScheduleRun run = d.schedule->refine(0.25, nullptr, area_stop(0.5));
  EXPECT_FALSE(run.abandoned);
  ASSERT_FALSE(run.phases.empty());
  EXPECT_EQ(run.phases.back().name, "stabilise");
  EXPECT_GT(enclosed(d.mesh, run.contour), 0.8 * enclosed(d.mesh, coarse.contour));
}

TEST(Schedule, ARefinementBelowItsAreaShareIsAbandoned) {
  DiskSchedule d;
  const ScheduleRun& coarse = d.schedule->coarse(nullptr);
  ASSERT_FALSE(coarse.collapsed);
  // A share no contour on this relief can reach (twice the coarse area) stops the refinement at
  // its first look: no stabilisation, the contour where it was, the share it had.
  const ScheduleRun run = d.schedule->refine(0.25, nullptr, area_stop(2.0));
  ASSERT_TRUE(run.abandoned);
  EXPECT_FALSE(run.hit_cap);
  ASSERT_FALSE(run.phases.empty());
  EXPECT_EQ(run.phases.back().name, "refine");
  EXPECT_FALSE(run.phases.back().converged);
  EXPECT_LE(run.phases.back().iterations, 10);  // the first lock_interval
  ASSERT_GE(run.contour.size(), 10u);
  EXPECT_GT(run.abandoned_area_share, 0.5);
  EXPECT_LT(run.abandoned_area_share, 2.0);
  EXPECT_NEAR(run.abandoned_area_share, enclosed(d.mesh, run.contour) / enclosed(d.mesh, coarse.contour), 1e-9);
  // The self-check names it.
  const SelfCheck check = abandoned_verdict(d.scan.h, run.abandoned_area_share, -1);
  ASSERT_FALSE(check.holds);
  ASSERT_EQ(check.reasons.size(), 1u);
  EXPECT_NE(check.reasons.front().find("refinement was stopped"), std::string::npos);
}

TEST(Schedule, ARefinementThatKeepsToTheCoarseStepRunsToTheEnd) {
  DiskSchedule d;
  const ScheduleRun& coarse = d.schedule->coarse(nullptr);
  ASSERT_FALSE(coarse.collapsed);
  // The coarse contour's measured points on the disk's step, as segment() gives them: the
  // refinement settles on the same step and never leaves a tenth of them behind.
  const std::vector<char> region = relief_region(d.mesh, coarse.contour, true, true);
  const StepEvidence evidence = measure_step(d.mesh, coarse.contour, region, d.scan.h);
  const StepAnchors anchors = step_anchors(d.mesh, coarse.contour, evidence, true);
  ASSERT_GT(anchors.on_step_count(), 10);
  RefineStop stop;
  stop.anchors = &anchors;
  const ScheduleRun run = d.schedule->refine(0.25, nullptr, stop);
  EXPECT_FALSE(run.abandoned);
  ASSERT_FALSE(run.phases.empty());
  EXPECT_EQ(run.phases.back().name, "stabilise");
  EXPECT_LE(step_left(anchors, *run.snake, 2 * d.scan.h).share, 0.02);
}

TEST(Schedule, ARefinementThatLeavesTheCoarseStepIsAbandoned) {
  DiskSchedule d;
  const ScheduleRun& coarse = d.schedule->coarse(nullptr);
  ASSERT_FALSE(coarse.collapsed);
  // Anchors on a step no contour on this disk comes near (the coarse points lifted 10 h off the
  // plate), a fifth of them on it: left at the first look.
  StepAnchors anchors;
  for (std::size_t k = 0; k < coarse.contour.size(); ++k) {
    anchors.points.push_back(position(d.mesh, coarse.contour[k]) + Vec3(0, 0, 10 * d.scan.h));
    anchors.on_step.push_back(k % 5 == 0);
  }
  anchors.spacing = d.scan.h;
  RefineStop stop;
  stop.anchors = &anchors;
  const ScheduleRun run = d.schedule->refine(0.25, nullptr, stop);
  ASSERT_TRUE(run.abandoned);
  EXPECT_FALSE(run.abandoned_for_area);
  EXPECT_DOUBLE_EQ(run.abandoned_left_share, 1.0);
  EXPECT_LE(run.phases.back().iterations, 10);
  // Only the on-step anchors count: with none of them on a step nothing stops it.
  for (char& on : anchors.on_step) on = 0;
  const ScheduleRun kept = d.schedule->refine(0.25, nullptr, stop);
  EXPECT_FALSE(kept.abandoned);
  // The self-check names it.
  const SelfCheck check = abandoned_verdict(d.scan.h, -1, run.abandoned_left_share);
  ASSERT_FALSE(check.holds);
  ASSERT_EQ(check.reasons.size(), 1u);
  EXPECT_NE(check.reasons.front().find("refinement was stopped"), std::string::npos);
  EXPECT_NE(check.reasons.front().find("100% of the step"), std::string::npos);
}

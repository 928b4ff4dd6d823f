// The evolution schedule (schedule.hpp): refinements from the coarse snake, and the early stop
// of a refinement whose contour shrinks away from the coarse one (it is crossing the relief).
#include <gtest/gtest.h>

#include "relief_snake/evidence.hpp"
#include "relief_snake/initial_contour.hpp"
#include "relief_snake/planarity.hpp"
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

}  // namespace

TEST(Schedule, ARefinementThatKeepsItsAreaRunsToTheEnd) {
  DiskSchedule d;
  const ScheduleRun& coarse = d.schedule->coarse(nullptr);
  ASSERT_FALSE(coarse.collapsed);
  // The disk's contour keeps its area through refinement: half the coarse area never stops it.
  const ScheduleRun run = d.schedule->refine(0.25, nullptr, 0.5);
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
  const ScheduleRun run = d.schedule->refine(0.25, nullptr, 2.0);
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
  ContourEvidence e;
  e.step.attempted = 10;
  e.step.profiles.resize(10);
  e.step.step_share = 1.0;
  e.step.step_height = d.scan.h;
  e.abandoned_area_share = run.abandoned_area_share;
  const SelfCheck check = judge(e, d.scan.h);
  ASSERT_FALSE(check.holds);
  ASSERT_EQ(check.reasons.size(), 1u);
  EXPECT_NE(check.reasons.front().find("refinement was stopped"), std::string::npos);
}

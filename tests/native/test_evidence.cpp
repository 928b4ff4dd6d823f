// The self-check (evidence.hpp) and the step height estimate (step_height.hpp) on
// generated scans with exact truth: a contour on the true boundary shows a step of the
// true height all round; one that crossed into the relief, or stopped on the background,
// does not.
#include <gtest/gtest.h>

#include <cmath>

#include "relief_snake/evidence.hpp"
#include "relief_snake/initial_contour.hpp"
#include "relief_snake/region.hpp"
#include "relief_snake/segment.hpp"
#include "relief_snake/step_height.hpp"
#include "synthetic.hpp"

using namespace relief_snake;
namespace syn = relief_snake::synthetic;

namespace {

syn::Scan disk_scan(syn::Background background, syn::Step step, double h = 1.0, std::size_t triangles = 60000) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Disk;
  spec.background = background;
  spec.step = step;
  spec.h = h;
  spec.triangles = triangles;
  return syn::generate(spec);
}

// A closed contour on the level set sd = offset of the scan's silhouette (negative: inside
// the relief), as snaxels at the nearest mesh vertices, counter-clockwise.
std::vector<SurfacePoint> level_set_contour(const syn::Scan& scan, const Mesh& mesh, double radius_offset) {
  // The disk has radius 12 centred at the origin of the parameter plane.
  std::vector<SurfacePoint> out;
  const int n = 200;
  int last = -1;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n, r = 12 + radius_offset;
    const int v = scan.nearest_vertex(r * std::cos(a), r * std::sin(a));
    if (v != last) out.push_back(vertex_point(mesh, v));
    last = v;
  }
  return out;
}

StepEvidence evidence_at(const syn::Scan& scan, const Mesh& mesh, double offset, double h) {
  const std::vector<SurfacePoint> contour = level_set_contour(scan, mesh, offset);
  const bool left = contour_orientation_left(mesh, contour);
  const std::vector<char> region = relief_region(mesh, contour, true, left);
  return measure_step(mesh, contour, region, h);
}

}  // namespace

TEST(Evidence, AContourOnTheStepShowsTheTrueStepAllRound) {
  for (const auto background : {syn::Background::Plane, syn::Background::Sphere, syn::Background::Saddle}) {
    const syn::Scan scan = disk_scan(background, syn::Step::Blended);
    const Mesh mesh = syn::to_mesh(scan);
    const StepEvidence e = evidence_at(scan, mesh, 0.0, scan.h);
    EXPECT_GT(e.measured_share(), 0.95);
    EXPECT_GT(e.step_share, 0.95);
    EXPECT_NEAR(e.step_height, scan.h, 0.2 * scan.h);
    // A rough h does not change the step found.
    EXPECT_NEAR(evidence_at(scan, mesh, 0.0, 0.6 * scan.h).step_height, scan.h, 0.25 * scan.h);
    EXPECT_NEAR(evidence_at(scan, mesh, 0.0, 1.6 * scan.h).step_height, scan.h, 0.25 * scan.h);
  }
}

TEST(Evidence, AContourInsideTheReliefOrOnTheBackgroundShowsNoStep) {
  const syn::Scan scan = disk_scan(syn::Background::Cylinder, syn::Step::Sharp);
  const Mesh mesh = syn::to_mesh(scan);
  EXPECT_LT(evidence_at(scan, mesh, -5.0, scan.h).step_share, 0.2);  // collapsed onto the relief's top
  EXPECT_LT(evidence_at(scan, mesh, 6.0, scan.h).step_share, 0.2);   // still out on the background
}

TEST(Evidence, JudgeNamesEachFailedCheck) {
  ContourEvidence e;
  e.step.attempted = 10;
  e.step.profiles.resize(10);
  e.step.step_share = 0.95;
  e.step.step_height = 1.0;
  EXPECT_TRUE(judge(e, 1.0).holds);
  e.step.step_share = 0.4;
  SelfCheck c = judge(e, 1.0);
  ASSERT_FALSE(c.holds);
  EXPECT_NE(c.reasons.front().find("40%"), std::string::npos);
  e.step.step_share = 0.95;
  e.coarse_step_share = 1.0;
  e.coarse_iou = 0.3;
  c = judge(e, 1.0);
  ASSERT_EQ(c.reasons.size(), 1u);
  EXPECT_NE(c.reasons.front().find("coarse"), std::string::npos);
  e.coarse_step_share = 0.2;  // the coarse contour never reached the step: leaving it behind is fine
  EXPECT_TRUE(judge(e, 1.0).holds);
  e.area_ratio = 2.0;
  EXPECT_FALSE(judge(e, 1.0).holds);
  e.area_ratio = 1.0;
  EXPECT_FALSE(judge(e, 3.0).holds);  // the step found is a third of h
  EXPECT_GT(judge(e, 1.0).score, judge(e, 3.0).score);
}

TEST(StepHeight, EstimatedFromThePicksWithinAQuarter) {
  for (const auto background : {syn::Background::Plane, syn::Background::Cylinder, syn::Background::Sphere})
    for (const auto step : {syn::Step::Sharp, syn::Step::Blended})
      for (const double h : {0.5, 2.0}) {
        const syn::Scan scan = disk_scan(background, step, h);
        const Mesh mesh = syn::to_mesh(scan);
        const syn::Picks picks = scan.picks();
        std::vector<int> vertices(picks.vertices.begin(), picks.vertices.end());
        const InitialContour initial = initial_contour(mesh, vertices, true);
        const StepHeightEstimate e =
            estimate_step_height(mesh, initial.path, true, contour_orientation_left(mesh, initial.path));
        EXPECT_GT(e.value, 0.75 * h) << syn::to_string(background) << " " << syn::to_string(step) << " h " << h;
        EXPECT_LT(e.value, 1.33 * h) << syn::to_string(background) << " " << syn::to_string(step) << " h " << h;
        EXPECT_GT(e.confidence, 0.3);
      }
}

TEST(StepHeight, OpenContoursFindTheSideThatRises) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Open;
  spec.step = syn::Step::Blended;
  spec.triangles = 60000;
  const syn::Scan scan = syn::generate(spec);
  const Mesh mesh = syn::to_mesh(scan);
  for (const bool reverse : {false, true}) {
    syn::PickSpec ps;
    ps.reverse = reverse;
    const syn::Picks picks = scan.picks(ps);
    std::vector<int> vertices(picks.vertices.begin(), picks.vertices.end());
    InitialContour initial = initial_contour(mesh, vertices, false);
    ASSERT_TRUE(extend_to_boundary(mesh, &initial.path));
    const StepHeightEstimate e = estimate_step_height(mesh, initial.path, false, true);
    EXPECT_EQ(e.relief_left, picks.relief_side == ReliefSide::Left) << "reverse " << reverse;
    EXPECT_NEAR(e.value, scan.h, 0.33 * scan.h);
  }
}

// The self-check (evidence.hpp) and the step height estimate (step_height.hpp) on
// generated scans with exact truth: a contour on the true boundary shows a step of the
// true height all round; one that crossed into the relief, or stopped on the background,
// does not.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "relief_snake/background.hpp"
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
// the relief), as snaxels at the nearest mesh vertices, counter-clockwise; optionally with
// a lobe of height `lobe` (parameter units) and half-width `lobe_half_width` (radians)
// out into the background around angle 0.
std::vector<SurfacePoint> level_set_contour(const syn::Scan& scan, const Mesh& mesh, double radius_offset,
                                            double lobe = 0, double lobe_half_width = 0.3) {
  // The disk has radius 12 centred at the origin of the parameter plane.
  std::vector<SurfacePoint> out;
  const int n = 200;
  int last = -1;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n, from_lobe = std::min(a, 2 * M_PI - a);
    const double r = 12 + radius_offset + lobe * std::max(0.0, 1 - from_lobe / lobe_half_width);
    const int v = scan.nearest_vertex(r * std::cos(a), r * std::sin(a));
    if (v != last) out.push_back(vertex_point(mesh, v));
    last = v;
  }
  return out;
}

StepEvidence evidence_at(const syn::Scan& scan, const Mesh& mesh, double offset, double h, double lobe = 0) {
  const std::vector<SurfacePoint> contour = level_set_contour(scan, mesh, offset, lobe);
  const bool left = contour_orientation_left(mesh, contour);
  const std::vector<char> region = relief_region(mesh, contour, true, left);
  return measure_step(mesh, contour, region, h);
}

// The disk's contour with a lobe out into the background, and the region it encloses
// (taken from the parameter plane: snapping a lobe to vertices can make it touch itself).
StepEvidence lobe_evidence(const syn::Scan& scan, const Mesh& mesh, double lobe) {
  const double half_width = 0.3;
  const auto radius_at = [&](double a) {
    a = std::fmod(a + 2 * M_PI, 2 * M_PI);
    return 12 + lobe * std::max(0.0, 1 - std::min(a, 2 * M_PI - a) / half_width);
  };
  std::vector<SurfacePoint> contour;
  int last = -1;
  for (int k = 0; k < 400; ++k) {
    const double a = 2 * M_PI * k / 400;
    const int v = scan.nearest_vertex(radius_at(a) * std::cos(a), radius_at(a) * std::sin(a));
    if (v != last) contour.push_back(vertex_point(mesh, v));
    last = v;
  }
  std::vector<char> region(mesh.n_vertices(), 0);
  for (std::size_t i = 0; i < scan.n_vertices(); ++i) {
    const double u = scan.UV[2 * i], w = scan.UV[2 * i + 1];
    const int v = mesh.input_to_mesh(i);
    if (v >= 0) region[v] = std::hypot(u, w) < radius_at(std::atan2(w, u)) ? 1 : 0;
  }
  return measure_step(mesh, contour, region, scan.h);
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

// The step at the edge (the knee of each profile) reads the height the relief stands at right behind
// its edge, where the inside's heights over the whole ball (step_height) read a dome inside the edge
// too high and a rim's inner fall too low. The domes here are the steepest the randomized suite draws
// (1 h over 3 h). The contour runs at the foot, a quarter h outside the edge, as a settled snake does.
TEST(Evidence, TheStepAtTheEdgeIgnoresADomeOrARimBehindIt) {
  struct Case {
    syn::Step step;
    double dome;
    bool drop;
  };
  for (const Case c : {Case{syn::Step::Sharp, 0, false}, Case{syn::Step::Blended, 0, false},
                       Case{syn::Step::Sharp, 1.0, false}, Case{syn::Step::Blended, 1.0, false},
                       Case{syn::Step::Sharp, 0, true}}) {
    syn::ScanSpec spec;
    spec.shape = syn::Shape::Disk;
    spec.step = c.step;
    spec.dome = c.dome;
    spec.dome_width = 3;
    spec.drop = c.drop;
    spec.triangles = 60000;
    const syn::Scan scan = syn::generate(spec);
    const Mesh mesh = syn::to_mesh(scan);
    for (const double typed : {0.6, 1.0, 1.6}) {
      SCOPED_TRACE(std::string(c.step == syn::Step::Sharp ? "sharp" : "blended") + (c.dome > 0 ? ", dome" : "") +
                   (c.drop ? ", rim" : "") + ", h typed x" + std::to_string(typed));
      const StepEvidence e = evidence_at(scan, mesh, 0.25 * scan.h, typed * scan.h);
      EXPECT_GT(e.edge_step_height, 0.9 * scan.h);
      EXPECT_LT(e.edge_step_height, 1.3 * scan.h);
      // Where the whole ball's rise is off by more than a tenth, the edge's is nearer the step.
      if (std::fabs(std::log(e.step_height / scan.h)) > std::log(1.1)) {
        EXPECT_LT(std::fabs(std::log(e.edge_step_height / scan.h)), std::fabs(std::log(e.step_height / scan.h)));
      }
    }
  }
}

// The background's roughness apart from its curvature (background_quadric_residual, the blended foot
// stage's gate): a small sphere's plane residual reads as texture would, its quadric residual does not;
// on a striated plane both read the texture.
TEST(Evidence, TheQuadricResidualSeesTextureNotCurvature) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Disk;
  spec.step = syn::Step::Blended;
  spec.background = syn::Background::Sphere;
  spec.radius = 15;
  spec.width = 40, spec.height = 40;
  spec.h = 1.0;
  spec.triangles = 20000;
  const syn::Scan sphere = syn::generate(spec);
  const Mesh sphere_mesh = syn::to_mesh(sphere);
  const StepEvidence curved = evidence_at(sphere, sphere_mesh, 0.25, sphere.h);
  EXPECT_GT(curved.background_residual, 0.05 * sphere.h);  // the plane gate would hold the foot stage off
  EXPECT_LT(curved.background_quadric_residual, 0.01 * sphere.h);

  spec.background = syn::Background::Plane;
  spec.texture = syn::Texture::Striations;
  spec.texture_amplitude = 0.2;
  spec.texture_period = 2;
  const syn::Scan striated = syn::generate(spec);
  const Mesh striated_mesh = syn::to_mesh(striated);
  const StepEvidence textured = evidence_at(striated, striated_mesh, 0.25, striated.h);
  EXPECT_GT(textured.background_quadric_residual, 0.05 * striated.h);
  EXPECT_LE(textured.background_quadric_residual, textured.background_residual);
}

// A region short of a blended step's foot leaves the toe of the slope outside it all along the
// contour; with the clearance (EvidenceOptions::quadric_clearance, the foot stage's gate) the
// roughness is measured beyond it, on the clean background.
TEST(Evidence, TheQuadricResidualClearsTheToeLeftOutside) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Disk;
  spec.step = syn::Step::Blended;
  spec.blend_width = 1.0;
  spec.background = syn::Background::Cylinder;
  spec.h = 2.0;
  spec.triangles = 60000;
  const syn::Scan scan = syn::generate(spec);
  const Mesh mesh = syn::to_mesh(scan);
  // Measured: a contour 0.2, 0.35 and 0.5 h up the slope reads 0.023, 0.048 and 0.069 h over all
  // the outside vertices, 0.0001, 0.013 and 0.030 h beyond 0.5 h of the region.
  for (const double inside : {0.0, 0.2, 0.35, 0.5}) {
    SCOPED_TRACE("contour " + std::to_string(inside) + " h inside the foot");
    const std::vector<SurfacePoint> contour = level_set_contour(scan, mesh, -inside * scan.h);
    const std::vector<char> region = relief_region(mesh, contour, true, contour_orientation_left(mesh, contour));
    EvidenceOptions clear;
    clear.quadric_clearance = 0.5;
    const double all = measure_step(mesh, contour, region, scan.h).background_quadric_residual;
    const double beyond = measure_step(mesh, contour, region, scan.h, clear).background_quadric_residual;
    if (inside == 0.0) {
      EXPECT_LT(all, 0.01 * scan.h);  // at the foot nothing of the slope lies outside
      EXPECT_LT(beyond, 0.01 * scan.h);
    } else {
      EXPECT_LT(beyond, 0.5 * all);
    }
    if (inside == 0.5) {
      EXPECT_GT(all, 0.05 * scan.h);    // the gate of stop 37 (foot_gate_residual 0.05) shut ...
      EXPECT_LT(beyond, 0.05 * scan.h); // ... and open beyond the toe
    }
  }
}

TEST(Evidence, AContourInsideTheReliefOrOnTheBackgroundShowsNoStep) {
  const syn::Scan scan = disk_scan(syn::Background::Cylinder, syn::Step::Sharp);
  const Mesh mesh = syn::to_mesh(scan);
  EXPECT_LT(evidence_at(scan, mesh, -5.0, scan.h).step_share, 0.2);  // collapsed onto the relief's top
  EXPECT_LT(evidence_at(scan, mesh, 6.0, scan.h).step_share, 0.2);   // still out on the background
}

TEST(Evidence, ALobeOutIntoTheBackgroundRunsAwayFromTheStep) {
  for (const auto step : {syn::Step::Sharp, syn::Step::Blended}) {
    SCOPED_TRACE(step == syn::Step::Sharp ? "sharp" : "blended");
    const syn::Scan scan = disk_scan(syn::Background::Sphere, step);
    const Mesh mesh = syn::to_mesh(scan);
    const StepEvidence on = evidence_at(scan, mesh, 0.0, scan.h);
    EXPECT_LT(on.longest_far, SelfCheckOptions{}.max_far_run * scan.h);  // the true contour passes
    // A lobe 3 h out and about 7 h wide: most of the contour is still on the step, but the
    // stretch round the lobe is not, and it is found.
    const StepEvidence lobe = lobe_evidence(scan, mesh, 3.0 * scan.h);
    EXPECT_GT(lobe.step_share, 0.85);
    EXPECT_GT(lobe.longest_far, 2.0 * scan.h);
    EXPECT_GE(lobe.far_point, 0);
    ContourEvidence e;
    e.step = lobe;
    const SelfCheck c = judge(e, scan.h);
    ASSERT_FALSE(c.holds);
    bool named = false;
    for (const std::string& r : c.reasons) named = named || r.find("runs away from the step") != std::string::npos;
    EXPECT_TRUE(named);
  }
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
  // What refinement let go of was background (a bridged concavity): the region kept the coarse
  // region's relief. Measured and under the share, it still fails.
  e.coarse_relief_kept = 0.95;
  EXPECT_TRUE(judge(e, 1.0).holds);
  e.coarse_relief_kept = 0.5;
  c = judge(e, 1.0);
  ASSERT_EQ(c.reasons.size(), 1u);
  EXPECT_NE(c.reasons.front().find("keeps 50% of the relief"), std::string::npos) << c.reasons.front();
  e.coarse_relief_kept = -1;  // not measured: the overlap alone decides
  EXPECT_FALSE(judge(e, 1.0).holds);
  // A coarse contour on a step along 3/4 of its length (under min_step_share): a region that left
  // most of it (overlap under strayed_coarse_iou) fails; one that overlaps it by half does not.
  e.coarse_step_share = 0.8;
  EXPECT_TRUE(strayed_from_coarse(e.coarse_step_share, e.coarse_iou));
  c = judge(e, 1.0);
  ASSERT_EQ(c.reasons.size(), 1u);
  EXPECT_NE(c.reasons.front().find("overlaps the coarse contour's by only 30%"), std::string::npos) << c.reasons.front();
  e.coarse_relief_kept = 0.95;  // the relief kept exempts it as on the upper tier
  EXPECT_TRUE(judge(e, 1.0).holds);
  e.coarse_relief_kept = -1;
  e.coarse_iou = 0.5;
  EXPECT_FALSE(strayed_from_coarse(e.coarse_step_share, e.coarse_iou));
  EXPECT_TRUE(judge(e, 1.0).holds);
  e.coarse_iou = 0.3;
  e.coarse_step_share = 0.2;  // the coarse contour never reached the step: leaving it behind is fine
  EXPECT_FALSE(strayed_from_coarse(e.coarse_step_share, e.coarse_iou));
  EXPECT_TRUE(judge(e, 1.0).holds);
  e.area_ratio = 2.0;
  EXPECT_FALSE(judge(e, 1.0).holds);
  e.area_ratio = 1.0;
  EXPECT_FALSE(judge(e, 3.0).holds);  // the step found is a third of h
  EXPECT_GT(judge(e, 1.0).score, judge(e, 3.0).score);
  e.step.longest_far = 2.0;  // 2 h of contour away from the step
  const Vec3 where(1, 2, 3);
  c = judge(e, 1.0, {}, &where);
  ASSERT_EQ(c.reasons.size(), 1u);
  EXPECT_NE(c.reasons.front().find("(1, 2, 3)"), std::string::npos);
  // Where the region-wide check could look at the region, it, not the far run, decides on
  // background taken in.
  e.region_checked = true;
  EXPECT_TRUE(judge(e, 1.0, {}, &where).holds);
  // ... unless the run is long (over max_far_run_checked, 2.5 h), over 5% of the profiles, on a mesh
  // that resolves the step (h at least 3 average edges): on texture the fills can miss a bridge.
  e.step.longest_far = 3.0;
  e.step.far_share = 0.1;
  e.step.average_edge = 0.2;  // 5 edges per h
  c = judge(e, 1.0, {}, &where);
  ASSERT_EQ(c.reasons.size(), 1u);
  EXPECT_NE(c.reasons.front().find("3 h long"), std::string::npos) << c.reasons.front();
  e.step.average_edge = 0.5;  // 2 edges per h: the profiles' 2-edge tolerance is a whole h
  EXPECT_TRUE(judge(e, 1.0).holds);
  e.step.average_edge = 0.2;
  e.step.far_share = 0.04;
  EXPECT_TRUE(judge(e, 1.0).holds);
  e.step.far_share = 0.1;
  e.step.longest_far = 2.4;
  EXPECT_TRUE(judge(e, 1.0).holds);
  e.step.longest_far = 3.0;
  SelfCheckOptions off;
  off.max_far_run_checked = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(judge(e, 1.0, off).holds);
  e.step.average_edge = 0;
  e.step.far_share = 0;
  e.region_checked = false;
  e.step.longest_far = 0;
  // Background inside the region: judged only when measured, above the depth and the edge floor.
  e.background_depth = 2.0;
  e.background_area = 7.5;
  e.background_where = Vec3(4, 5, 6);
  EXPECT_TRUE(judge(e, 1.0).holds);  // not measured
  e.background_measured = true;
  c = judge(e, 1.0);
  ASSERT_EQ(c.reasons.size(), 1u);
  EXPECT_NE(c.reasons.front().find("7.5 h^2"), std::string::npos);
  EXPECT_NE(c.reasons.front().find("(4, 5, 6)"), std::string::npos);
  e.background_depth_floor = 2.5;  // on a coarse mesh a 2 h strip is one edge or two
  EXPECT_TRUE(judge(e, 1.0).holds);
  e.background_depth_floor = 0;
  e.background_depth = 0.5;
  EXPECT_TRUE(judge(e, 1.0).holds);
  // The region against the risen area the picks enclose: judged only when measured (>= 0).
  e.covered_share = 0.05;
  c = judge(e, 1.0);
  ASSERT_EQ(c.reasons.size(), 1u);
  EXPECT_NE(c.reasons.front().find("covers only 5%"), std::string::npos);
  e.covered_share = 0.001;
  EXPECT_NE(judge(e, 1.0).reasons.front().find("under 1%"), std::string::npos);
  e.covered_share = 0.6;
  EXPECT_TRUE(judge(e, 1.0).holds);
  e.covered_share = -1;
  EXPECT_TRUE(judge(e, 1.0).holds);
  // The step at the contour's edge (the knee) against h, both ways, judged only when measured (> 0):
  // the whole-ball step (1.0 here) agrees with h.
  const double limit = SelfCheckOptions().max_edge_step_ratio;
  for (const double knee : {0.95 / limit, 1.05 * limit}) {
    e.step.edge_step_height = knee;
    c = judge(e, 1.0);
    ASSERT_EQ(c.reasons.size(), 1u) << knee;
    EXPECT_NE(c.reasons.front().find("the step at the contour's edge is"), std::string::npos);
  }
  for (const double knee : {1.05 / limit, 0.95 * limit, 0.0}) {
    e.step.edge_step_height = knee;
    EXPECT_TRUE(judge(e, 1.0).holds) << knee;
  }
}

// The relief a coarse region encloses (background.hpp's fill from around it): a region that
// keeps the disk keeps all of it, whatever background it leaves; one that lost half the disk
// keeps about half; a region of background keeps none.
TEST(Evidence, KeptReliefShareCountsReliefNotBackground) {
  const syn::Scan scan = disk_scan(syn::Background::Plane, syn::Step::Sharp);
  const Mesh mesh = syn::to_mesh(scan);
  const auto region_where = [&](auto inside) {
    std::vector<char> region(mesh.n_vertices(), 0);
    for (std::size_t i = 0; i < scan.n_vertices(); ++i) {
      const int v = mesh.input_to_mesh(i);
      if (v >= 0) region[v] = inside(scan.UV[2 * i], scan.UV[2 * i + 1]) ? 1 : 0;
    }
    return region;
  };
  // The coarse region: the disk (radius 12) and a lobe of background beside it out to 20.
  const std::vector<char> coarse =
      region_where([](double u, double w) { return std::hypot(u, w) < 12.5 || (u > 0 && u < 20 && std::fabs(w) < 4); });
  const BackgroundResult fill = fill_background(mesh, coarse, scan.h);
  ASSERT_TRUE(fill.ok()) << fill.message;
  const double rise = 0.5 * scan.h;
  const std::vector<char> disk = region_where([](double u, double w) { return std::hypot(u, w) < 12.5; });
  EXPECT_GT(kept_relief_share(mesh, fill, disk, rise), 0.98);
  EXPECT_LT(region_iou(mesh, coarse, disk), 0.95);  // it left the lobe behind
  const double half = kept_relief_share(mesh, fill, region_where([](double u, double) { return u < 0; }), rise);
  EXPECT_GT(half, 0.4);
  EXPECT_LT(half, 0.6);
  EXPECT_LT(kept_relief_share(mesh, fill, region_where([](double u, double w) { return u > 14 && std::fabs(w) < 4; }), rise), 0.01);
  // Nothing in the fill's region stands that high: not measured.
  EXPECT_EQ(kept_relief_share(mesh, fill, disk, 100 * scan.h), -1.0);
}

// A relief whose top drops to 0.3 h within 1.5 h of its edge (the randomized suite's "drop"): a region
// that keeps only the rim, a ring 2 h wide, keeps nearly all of the area standing half a step high,
// but little more than half of the relief's volume above the background, so the share it reports is
// the volume's (under the check's 0.8); the whole disk keeps both.
TEST(Evidence, KeptReliefShareCountsTheVolumeARingLeavesOut) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Disk;
  spec.step = syn::Step::Sharp;
  spec.drop = true;
  spec.h = 1.0;
  spec.triangles = 60000;
  const syn::Scan scan = syn::generate(spec);
  const Mesh mesh = syn::to_mesh(scan);
  const auto region_where = [&](auto inside) {
    std::vector<char> region(mesh.n_vertices(), 0);
    for (std::size_t i = 0; i < scan.n_vertices(); ++i) {
      const int v = mesh.input_to_mesh(i);
      if (v >= 0) region[v] = inside(std::hypot(scan.UV[2 * i], scan.UV[2 * i + 1])) ? 1 : 0;
    }
    return region;
  };
  const std::vector<char> disk = region_where([](double r) { return r < 12.5; });
  const BackgroundResult fill = fill_background(mesh, disk, scan.h);
  ASSERT_TRUE(fill.ok()) << fill.message;
  const std::vector<char> rim = region_where([](double r) { return r > 10 && r < 12.5; });
  double relief = 0, rim_relief = 0;  // the area standing half a step high, and the rim's part of it
  for (const int v : fill.region_vertices)
    if (fill.height[v] >= 0.5 * scan.h) relief += mesh.vertex_area(v), rim_relief += rim[v] ? mesh.vertex_area(v) : 0;
  ASSERT_GT(rim_relief / relief, 0.9);  // by area alone the ring would pass min_coarse_relief_kept
  const double kept = kept_relief_share(mesh, fill, rim, 0.5 * scan.h);
  EXPECT_LT(kept, 0.6);
  EXPECT_LT(kept, SelfCheckOptions().min_coarse_relief_kept);
  EXPECT_GT(kept_relief_share(mesh, fill, disk, 0.5 * scan.h), 0.98);
}

// A blended step beside a flat band running off the mesh (an open contour's scan).
static syn::Scan blended_open_scan() {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Open;
  spec.step = syn::Step::Blended;
  spec.triangles = 60000;
  return syn::generate(spec);
}

// The initial contour of open picks, extended to the mesh boundary as segment() extends it (empty
// when it cannot reach the boundary).
static SurfacePath extended_open_path(const Mesh& mesh, const std::vector<std::int64_t>& picks) {
  const std::vector<int> vertices(picks.begin(), picks.end());
  InitialContour initial = initial_contour(mesh, vertices, false);
  if (!extend_to_boundary(mesh, &initial.path)) return {};
  return initial.path;
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
        // The true step is well within what the picks make plausible (a quarter of their diameter).
        EXPECT_GT(largest_plausible_step_height(mesh, initial.path, true), 2 * h);
      }
}

TEST(StepHeight, OpenContoursFindTheSideThatRises) {
  const syn::Scan scan = blended_open_scan();
  const Mesh mesh = syn::to_mesh(scan);
  for (const bool reverse : {false, true}) {
    syn::PickSpec ps;
    ps.reverse = reverse;
    const syn::Picks picks = scan.picks(ps);
    const SurfacePath path = extended_open_path(mesh, picks.vertices);
    ASSERT_FALSE(path.empty());
    const StepHeightEstimate e = estimate_step_height(mesh, path, false, true);
    EXPECT_EQ(e.relief_left, picks.relief_side == ReliefSide::Left) << "reverse " << reverse;
    EXPECT_NEAR(e.value, scan.h, 0.33 * scan.h);
  }
}

// A side the user named is the side h is measured on: named wrongly, the estimate does not take the
// relief's height from the other side (it stays on the flat background and finds no step there).
TEST(StepHeight, OpenContoursMeasureTheSideTheUserNamed) {
  const syn::Scan scan = blended_open_scan();
  const Mesh mesh = syn::to_mesh(scan);
  const syn::Picks picks = scan.picks();
  const SurfacePath path = extended_open_path(mesh, picks.vertices);
  ASSERT_FALSE(path.empty());
  const bool relief_left = picks.relief_side == ReliefSide::Left;
  StepHeightOptions named;
  named.decide_side = false;
  const StepHeightEstimate right = estimate_step_height(mesh, path, false, relief_left, named);
  EXPECT_EQ(right.relief_left, relief_left);
  EXPECT_NEAR(right.value, scan.h, 0.33 * scan.h);
  const StepHeightEstimate wrong = estimate_step_height(mesh, path, false, !relief_left, named);
  EXPECT_EQ(wrong.relief_left, !relief_left);
  EXPECT_LT(wrong.value, 0.25 * scan.h);
  EXPECT_LT(wrong.confidence, right.confidence);
}

// Open contours' further guesses start with the thin-plate fill of the background under the relief
// side. Random scan 2032: a blended band on a wavy background, picked 2.2 h from it: the quadric
// along the picks puts nothing above itself on the relief side (the first estimate finds no relief,
// and the quadric over the wider strip guesses x0.2-x0.45); the fill follows the waves and its
// first guess is within a quarter of h.
TEST(StepHeight, OpenContoursGuessHOverTheFill) {
  const syn::RandomScan random = syn::generate_random(2032);
  ASSERT_FALSE(random.picks.closed);
  const Mesh mesh = syn::to_mesh(random.scan);
  const SurfacePath path = extended_open_path(mesh, random.picks.vertices);
  ASSERT_FALSE(path.empty());
  const bool relief_left = random.picks.relief_side == ReliefSide::Left;
  const double h = random.scan.h;
  StepHeightOptions named;
  named.decide_side = false;
  const StepHeightEstimate first = estimate_step_height(mesh, path, false, relief_left, named);
  EXPECT_LT(first.value, 0.5 * h);
  const std::vector<StepHeightGuess> guesses = alternative_step_heights(mesh, path, false, relief_left, first);
  ASSERT_GE(guesses.size(), 3u);
  EXPECT_NE(guesses.front().source.find("filled in"), std::string::npos) << guesses.front().source;
  EXPECT_GT(guesses.front().value, 0.75 * h);
  EXPECT_LT(guesses.front().value, 1.33 * h);
  for (const StepHeightGuess& g : guesses) {
    if (g.source.find("wider strip") != std::string::npos) {
      EXPECT_LT(g.value, 0.5 * h) << g.source;
    }
  }
}

// The further guesses (for when the first estimate's result fails): over a thin-plate fill of the
// background a closed contour's guesses follow a vase's swell that one quadric over a plane misses
// (random scan 115: a blended ellipse over most of the swell, where the first estimate is x7): one
// comes within x2 of h, the range the snake and the refit along the contour hold from. Open
// contours compare a wider strip.
TEST(StepHeight, FurtherGuessesFollowTheBackgroundTheQuadricMisses) {
  const syn::RandomScan random = syn::generate_random(115);
  const Mesh mesh = syn::to_mesh(random.scan);
  std::vector<int> vertices(random.picks.vertices.begin(), random.picks.vertices.end());
  const InitialContour initial = initial_contour(mesh, vertices, true);
  const bool left = contour_orientation_left(mesh, initial.path);
  const StepHeightEstimate first = estimate_step_height(mesh, initial.path, true, left);
  const std::vector<StepHeightGuess> guesses = alternative_step_heights(mesh, initial.path, true, left, first);
  ASSERT_FALSE(guesses.empty());
  bool near = false;
  for (const StepHeightGuess& g : guesses) {
    EXPECT_GT(g.value, 0.0);
    EXPECT_FALSE(g.source.empty());
    near = near || (g.value > 0.5 * random.scan.h && g.value < 2 * random.scan.h);
  }
  EXPECT_TRUE(near) << "first estimate " << first.value << ", true h " << random.scan.h;

  // Open: on the flat band beside a blended step, every guess is positive and the wide strip's
  // median is near h.
  const syn::Scan scan = blended_open_scan();
  const Mesh open_mesh = syn::to_mesh(scan);
  const syn::Picks picks = scan.picks();
  const SurfacePath open_path = extended_open_path(open_mesh, picks.vertices);
  ASSERT_FALSE(open_path.empty());
  const bool relief_left = picks.relief_side == ReliefSide::Left;
  const StepHeightEstimate open_first = estimate_step_height(open_mesh, open_path, false, relief_left);
  const std::vector<StepHeightGuess> open_guesses =
      alternative_step_heights(open_mesh, open_path, false, open_first.relief_left, open_first);
  ASSERT_GE(open_guesses.size(), 2u);
  EXPECT_NEAR(open_guesses.front().value, scan.h, 0.33 * scan.h);
}

// Several reliefs on one scan: segment_many (one snake per pick group, overlaps reported) and
// detect (robust background, Otsu, components, plateaus, snake refinement), on generated plates
// with the truth per relief (tests/synthetic/plate_scans.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "plate_scans.hpp"
#include "relief_snake/detect.hpp"
#include "relief_snake/error.hpp"
#include "relief_snake/multi_json.hpp"
#include "relief_snake/multi_segment.hpp"

namespace rs = relief_snake;
namespace syn = relief_snake::synthetic;

namespace {

syn::PlateRelief disk(double u, double v, double r, double h) {
  syn::PlateRelief p;
  p.shape = syn::PlateShape::Disk;
  p.center_u = u, p.center_v = v, p.size_u = p.size_v = r, p.h = h;
  return p;
}

syn::PlateRelief box(double u, double v, double hu, double hv, double h) {
  syn::PlateRelief p;
  p.shape = syn::PlateShape::Box;
  p.center_u = u, p.center_v = v, p.size_u = hu, p.size_v = hv, p.h = h;
  return p;
}

/// Picks on a circle of radius r around (u, v), counter-clockwise.
std::vector<std::int64_t> ring(const syn::Scan& scan, double u, double v, double r, int count = 10) {
  std::vector<std::int64_t> out;
  for (int k = 0; k < count; ++k) {
    const double a = 2 * M_PI * k / count;
    out.push_back(scan.nearest_vertex(u + r * std::cos(a), v + r * std::sin(a)));
  }
  return out;
}

/// found: truth reliefs of at least min_area matched by a candidate with IoU >= 0.9;
/// false_candidates: candidates that match no truth relief with IoU >= 0.5.
struct Tally {
  int expected = 0, found = 0, false_candidates = 0;
  double worst_iou = 1;
};

Tally tally(const syn::PlateScan& plate, const rs::DetectResult& result, double min_area) {
  Tally t;
  std::vector<char> matched(result.candidates.size(), 0);
  for (std::size_t r = 0; r < plate.truth.size(); ++r) {
    double best = 0;
    for (std::size_t c = 0; c < result.candidates.size(); ++c) {
      const auto& cand = result.candidates[c];
      if (!cand.refined.ok) continue;
      const double iou = syn::index_iou(cand.refined.result.relief_vertices, plate.truth[r]);
      if (iou >= 0.5) matched[c] = 1;
      best = std::max(best, iou);
    }
    if (plate.truth_area[r] < min_area) continue;
    ++t.expected;
    if (best >= 0.9) ++t.found;
    t.worst_iou = std::min(t.worst_iou, best);
  }
  for (const char m : matched) t.false_candidates += !m;
  return t;
}

// A 40k-triangle plate with two disks of radius 7, 40 apart.
syn::PlateScan two_disks() {
  syn::PlateSpec spec;
  spec.triangles = 40000;
  spec.reliefs = {disk(-20, 0, 7, 1), disk(20, 0, 7, 1)};
  return syn::generate_plate(spec);
}

}  // namespace

TEST(SegmentMany, OneSnakePerGroupSharingThePlanarity) {
  syn::PlateSpec spec;
  spec.triangles = 60000;
  spec.reliefs = {disk(-20, 0, 8, 1), box(18, 0, 8, 6, 1)};
  const syn::PlateScan plate = syn::generate_plate(spec);
  const rs::Mesh mesh = syn::to_mesh(plate.scan);
  rs::Segmenter segmenter(mesh);
  rs::Options options;
  options.step_height = 1;
  const std::vector<std::vector<std::int64_t>> groups = {ring(plate.scan, -20, 0, 11), ring(plate.scan, 18, 0, 13)};
  std::vector<std::size_t> seen_groups;
  const rs::MultiResult multi = rs::segment_many(segmenter, mesh, groups, options, [&](std::size_t g, const rs::Progress&) {
    if (seen_groups.empty() || seen_groups.back() != g) seen_groups.push_back(g);
    return true;
  });
  ASSERT_EQ(multi.reliefs.size(), 2u);
  EXPECT_EQ(seen_groups, (std::vector<std::size_t>{0, 1}));
  for (std::size_t g = 0; g < 2; ++g) {
    ASSERT_TRUE(multi.reliefs[g].ok) << multi.reliefs[g].error;
    EXPECT_EQ(multi.reliefs[g].result.status, rs::Status::Converged) << multi.reliefs[g].result.message;
    EXPECT_GE(syn::index_iou(multi.reliefs[g].result.relief_vertices, plate.truth[g]), 0.9);
  }
  EXPECT_TRUE(multi.overlaps.empty());
  // Same h: the second snake reads the planarity cache the first one filled (the count is the cache's).
  EXPECT_GT(multi.reliefs[1].result.planarity_vertices, multi.reliefs[0].result.planarity_vertices);

  const nlohmann::json doc = rs::multi_result_json(multi, groups, options, mesh, {});
  EXPECT_EQ(doc["format"], "relief-snake-results/1");
  EXPECT_EQ(doc["status"], "converged");
  ASSERT_EQ(doc["reliefs"].size(), 2u);
  EXPECT_EQ(doc["reliefs"][1]["format"], "relief-snake-result/1");
  EXPECT_EQ(doc["reliefs"][1]["parameters"]["picks"].get<std::vector<std::int64_t>>(), groups[1]);
}

TEST(SegmentMany, OverlapsAreReportedNotMerged) {
  syn::PlateSpec spec;
  spec.triangles = 40000;
  spec.reliefs = {disk(0, 0, 9, 1)};
  const syn::PlateScan plate = syn::generate_plate(spec);
  const rs::Mesh mesh = syn::to_mesh(plate.scan);
  rs::Segmenter segmenter(mesh);
  rs::Options options;
  options.step_height = 1;
  // Two groups around the same disk, and one that cannot run (a repeated pick).
  std::vector<std::int64_t> bad = ring(plate.scan, 0, 0, 12, 4);
  bad[2] = bad[0];
  const rs::MultiResult multi = rs::segment_many(
      segmenter, mesh, {ring(plate.scan, 0, 0, 12), ring(plate.scan, 0.5, 0.5, 14, 12), bad}, options);
  ASSERT_EQ(multi.reliefs.size(), 3u);
  ASSERT_TRUE(multi.reliefs[0].ok && multi.reliefs[1].ok);
  EXPECT_FALSE(multi.reliefs[2].ok);
  EXPECT_NE(multi.reliefs[2].error.find("repeated"), std::string::npos) << multi.reliefs[2].error;
  ASSERT_EQ(multi.overlaps.size(), 1u);
  EXPECT_EQ(multi.overlaps[0].a, 0u);
  EXPECT_EQ(multi.overlaps[0].b, 1u);
  EXPECT_GT(multi.overlaps[0].share_of_a, 0.9);
  for (std::size_t g = 0; g < 2; ++g) {
    const rs::Result& r = multi.reliefs[g].result;
    EXPECT_EQ(r.status, rs::Status::Doubtful);
    ASSERT_FALSE(r.reasons.empty());
    EXPECT_NE(r.reasons.back().find("relief " + std::to_string(1 - g)), std::string::npos) << r.reasons.back();
    // Each keeps its own region: nothing merged.
    EXPECT_GE(syn::index_iou(r.relief_vertices, plate.truth[0]), 0.9);
  }
  EXPECT_THROW(rs::segment_many(segmenter, mesh, {}, options), rs::Error);
}

TEST(Detect, FindsEveryReliefOfARandomPlate) {
  // Several layouts and backgrounds (not one hand-picked case): every relief above the minimum
  // area found with IoU >= 0.9, no false candidate. The sweep with more seeds is bench/detect_suite.py.
  struct Case {
    std::uint64_t seed;
    syn::Background background;
    double noise;
  };
  for (const Case& c : {Case{1, syn::Background::Plane, 0.0}, Case{2, syn::Background::Cylinder, 0.02},
                        Case{3, syn::Background::Sphere, 0.0}}) {
    syn::PlateSpec spec;
    spec.triangles = 60000;
    spec.seed = c.seed;
    spec.background = c.background;
    spec.noise = c.noise;
    spec.reliefs = syn::random_plate_layout(c.seed);
    const syn::PlateScan plate = syn::generate_plate(spec);
    const rs::Mesh mesh = syn::to_mesh(plate.scan);
    rs::Segmenter segmenter(mesh);
    const rs::DetectResult result = rs::detect(segmenter, mesh, {});
    const double min_area = std::pow(12 * mesh.average_edge_length(), 2);
    const Tally t = tally(plate, result, min_area);
    SCOPED_TRACE("seed " + std::to_string(c.seed) + " " + syn::to_string(c.background));
    EXPECT_GE(t.expected, 3);
    EXPECT_EQ(t.found, t.expected) << "worst IoU " << t.worst_iou;
    EXPECT_EQ(t.false_candidates, 0);
  }
}

TEST(Detect, NoCandidateWithoutRelief) {
  struct Case {
    syn::Background background;
    double noise;
  };
  for (const Case& c : {Case{syn::Background::Plane, 0.0}, Case{syn::Background::Plane, 0.05},
                        Case{syn::Background::Cylinder, 0.03}, Case{syn::Background::Sphere, 0.03},
                        Case{syn::Background::Saddle, 0.0}}) {
    syn::PlateSpec spec;
    spec.triangles = 40000;
    spec.background = c.background;
    spec.noise = c.noise;
    const syn::PlateScan plate = syn::generate_plate(spec);
    const rs::Mesh mesh = syn::to_mesh(plate.scan);
    rs::Segmenter segmenter(mesh);
    const rs::DetectResult result = rs::detect(segmenter, mesh, {});
    EXPECT_TRUE(result.candidates.empty()) << syn::to_string(c.background) << " noise " << c.noise << ": "
                                           << result.candidates.size() << " candidates, threshold "
                                           << result.background.threshold << ", sigma " << result.background.sigma;
    ASSERT_FALSE(result.notes.empty());
  }
}

TEST(Detect, TouchingReliefsOfDifferentHeightsStayApart) {
  syn::PlateSpec spec;
  spec.triangles = 60000;
  // Two boxes sharing a side (heights 1 and 2), and a disk apart.
  syn::PlateRelief a = box(-10, 0, 7, 6, 1), b = box(4, 0, 7, 6, 2);
  a.touches = 1, b.touches = 0;
  spec.reliefs = {a, b, disk(24, 10, 6, 1.5)};
  const syn::PlateScan plate = syn::generate_plate(spec);
  const rs::Mesh mesh = syn::to_mesh(plate.scan);
  rs::Segmenter segmenter(mesh);
  const rs::DetectResult result = rs::detect(segmenter, mesh, {});
  const Tally t = tally(plate, result, 0);
  EXPECT_EQ(t.expected, 3);
  EXPECT_EQ(t.found, 3) << "worst IoU " << t.worst_iou;
  EXPECT_EQ(t.false_candidates, 0);
}

TEST(Detect, RegionAndOptions) {
  const syn::PlateScan plate = two_disks();
  const rs::Mesh mesh = syn::to_mesh(plate.scan);
  rs::Segmenter segmenter(mesh);
  // The left half only: one relief.
  std::vector<std::int64_t> left;
  for (std::size_t k = 0; k < plate.scan.n_vertices(); ++k)
    if (plate.scan.UV[2 * k] < 0) left.push_back(static_cast<std::int64_t>(k));
  rs::DetectOptions fast;
  fast.refine = false;
  const rs::DetectResult half = rs::detect(segmenter, mesh, left, fast);
  ASSERT_EQ(half.candidates.size(), 1u);
  EXPECT_GT(syn::index_iou(half.candidates[0].component, plate.truth[0]), 0.7);
  EXPECT_FALSE(half.candidates[0].refined.ok);
  EXPECT_GE(half.candidates[0].picks.size(), 6u);
  // A minimum area above both reliefs: none.
  rs::DetectOptions big = fast;
  big.min_area = 1000;
  EXPECT_TRUE(rs::detect(segmenter, mesh, {}, big).candidates.empty());
  rs::DetectOptions bad;
  bad.background_degree = 9;
  EXPECT_THROW(rs::detect(segmenter, mesh, {}, bad), rs::Error);
  EXPECT_THROW(rs::detect(segmenter, mesh, {static_cast<std::int64_t>(plate.scan.n_vertices())}), rs::Error);
  EXPECT_THROW(rs::detect(segmenter, mesh, {0, 1, 2}), rs::Error);  // too few to fit
}

TEST(Detect, ReportsProgressBeforeRefiningAndCancelsThere) {
  // The background fits and the components call progress too (front ends show them and can
  // cancel there): "background" before each of the three fits, "candidates" with their count,
  // and only then the snake's phases.
  const syn::PlateScan plate = two_disks();
  const rs::Mesh mesh = syn::to_mesh(plate.scan);
  rs::Segmenter segmenter(mesh);
  struct Call {
    std::string phase;
    int iteration;
    std::size_t index;
  };
  std::vector<Call> calls;
  std::size_t stop_after = 0;  // 0: never cancel
  const rs::GroupProgressCallback progress = [&](std::size_t c, const rs::Progress& p) {
    calls.push_back({p.phase, p.iteration, c});
    if (calls.back().phase == "background" || calls.back().phase == "candidates") {
      EXPECT_TRUE(p.contour().empty());  // callable, and nothing to draw yet
    }
    return stop_after == 0 || calls.size() < stop_after;
  };
  const rs::DetectResult result = rs::detect(segmenter, mesh, {}, {}, progress);
  ASSERT_FALSE(result.cancelled);
  ASSERT_EQ(result.candidates.size(), 2u);
  ASSERT_GE(calls.size(), 5u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(calls[k].phase, "background");
    EXPECT_EQ(calls[k].iteration, k);
    EXPECT_EQ(calls[k].index, 0u);
  }
  EXPECT_EQ(calls[3].phase, "candidates");
  EXPECT_EQ(calls[3].iteration, 2);
  for (std::size_t k = 4; k < calls.size(); ++k) {
    EXPECT_NE(calls[k].phase, "background");
    EXPECT_NE(calls[k].phase, "candidates");
  }
  // Cancelled during the fits, and once the candidates are known: nothing is refined.
  for (const std::size_t stop : {std::size_t{1}, std::size_t{2}, std::size_t{4}}) {
    calls.clear();
    stop_after = stop;
    const rs::DetectResult cancelled = rs::detect(segmenter, mesh, {}, {}, progress);
    EXPECT_TRUE(cancelled.cancelled) << stop;
    EXPECT_TRUE(cancelled.candidates.empty()) << stop;
    EXPECT_EQ(calls.size(), stop);
  }
  // A fixed degree: one fit, one "background" call.
  calls.clear();
  stop_after = 0;
  rs::DetectOptions quadric;
  quadric.background_degree = 2;
  quadric.refine = false;
  rs::detect(segmenter, mesh, {}, quadric, progress);
  ASSERT_EQ(calls.size(), 2u);
  EXPECT_EQ(calls[0].phase, "background");
  EXPECT_EQ(calls[1].phase, "candidates");
}

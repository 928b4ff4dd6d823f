// Pick sets that cannot enclose a relief (issue 11, part 6): a figure-eight order or collinear
// picks are refused with advice instead of converging to nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "relief_snake/enclosure.hpp"
#include "relief_snake/error.hpp"
#include "relief_snake/initial_contour.hpp"
#include "relief_snake/region.hpp"
#include "relief_snake/segment.hpp"
#include "synthetic.hpp"

namespace rs = relief_snake;
namespace syn = relief_snake::synthetic;

namespace {

std::string error_of(const rs::Mesh& mesh, const std::vector<int>& picks) {
  try {
    rs::check_pick_polygon(mesh, picks);
  } catch (const rs::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(PickOrder, FigureEightCollinearAndGoodRings) {
  syn::ScanSpec spec;
  spec.triangles = 20000;
  const syn::Scan scan = syn::generate(spec);
  const rs::Mesh mesh = syn::to_mesh(scan);
  // A square ring around the duck, in (u, v), counter-clockwise.
  const double w = scan.spec.width, hgt = scan.spec.height;
  auto at = [&](double fu, double fv) { return scan.nearest_vertex((fu - 0.5) * w, (fv - 0.5) * hgt); };
  const std::vector<int> ring = {at(0.1, 0.1), at(0.9, 0.1), at(0.9, 0.9), at(0.1, 0.9)};
  EXPECT_EQ(error_of(mesh, ring), "");
  EXPECT_EQ(error_of(mesh, {ring[3], ring[2], ring[1], ring[0]}), "");  // clockwise is fine too
  // Figure eight: two corners swapped.
  const std::string eight = error_of(mesh, {ring[0], ring[1], ring[3], ring[2]});
  EXPECT_NE(eight.find("crosses itself"), std::string::npos) << eight;
  EXPECT_NE(eight.find("e.g. as 1, 2, 4, 3"), std::string::npos) << eight;
  EXPECT_EQ(eight.find('\n'), std::string::npos);
  // Collinear picks, and a sliver.
  const std::string line = error_of(mesh, {at(0.1, 0.5), at(0.5, 0.5), at(0.9, 0.5)});
  EXPECT_NE(line.find("almost no area"), std::string::npos) << "'" << line << "'";
  EXPECT_NE(error_of(mesh, {at(0.1, 0.5), at(0.9, 0.5), at(0.5, 0.505)}).find("almost no area"), std::string::npos);
  // A thin but honest triangle (roundness 0.1) is accepted.
  EXPECT_EQ(error_of(mesh, {at(0.1, 0.3), at(0.9, 0.3), at(0.5, 0.45)}), "");
}

TEST(PickOrder, SegmentRefusesAFigureEightWithAdvice) {
  syn::ScanSpec spec;
  spec.triangles = 20000;
  const syn::Scan scan = syn::generate(spec);
  const rs::Mesh mesh = syn::to_mesh(scan);
  std::vector<std::int64_t> picks = scan.picks().vertices;
  ASSERT_GE(picks.size(), 6u);
  std::swap(picks[1], picks[picks.size() / 2 + 1]);
  rs::Options options;
  options.step_height = scan.h;
  try {
    (void)rs::segment(mesh, picks, options);
    ADD_FAILURE() << "a figure-eight pick order was accepted";
  } catch (const rs::Error& e) {
    EXPECT_NE(std::string(e.what()).find("crosses itself"), std::string::npos) << e.what();
  }
}

namespace {

// Picks on a ring of radius r (in the parameter plane) around (u0, v0), n of them from angle a0 to a1.
std::vector<std::int64_t> ring_picks(const syn::Scan& scan, double u0, double v0, double r, int n, double a0 = 0,
                                     double a1 = 2 * M_PI) {
  std::vector<std::int64_t> out;
  for (int k = 0; k < n; ++k) {
    const double a = a0 + (a1 - a0) * k / n;
    out.push_back(scan.nearest_vertex(u0 + r * std::cos(a), v0 + r * std::sin(a)));
  }
  return out;
}

// segment()'s error message, or "" (and the result in *out) when it returns.
std::string segment_error(const rs::Mesh& mesh, const std::vector<std::int64_t>& picks, const rs::Options& options,
                          rs::Result* out) {
  try {
    *out = rs::segment(mesh, picks, options);
  } catch (const rs::Error& e) {
    return e.what();
  }
  return "";
}

double check_value(const rs::Result& r, const std::string& name) {
  for (const auto& [key, value] : r.checks)
    if (key == name) return value;
  ADD_FAILURE() << "no check " << name;
  return -1;
}

const char* kNoRelief = "nothing the picks enclose rises half a step";

}  // namespace

// Picks that all lie on one side of the relief (issue 11, part 6): a disk of radius 12, h = 1.
TEST(PickOrder, PicksOnOneSideOfTheReliefAreNamedAsSuch) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Disk;
  spec.triangles = 20000;
  const syn::Scan scan = syn::generate(spec);
  const rs::Mesh mesh = syn::to_mesh(scan);
  rs::Options options;
  options.step_height = scan.h;
  options.threads = 1;
  const double R = 12;

  // Around the relief: converged, and the check sees the relief (about half the enclosed area).
  rs::Result good;
  ASSERT_EQ(segment_error(mesh, ring_picks(scan, 0, 0, 1.4 * R, 8), options, &good), "");
  EXPECT_EQ(good.status, rs::Status::Converged);
  EXPECT_GT(check_value(good, "enclosed_risen_area"), 100.0);
  EXPECT_GT(check_value(good, "enclosed_risen_share"), 0.3);
  EXPECT_LT(check_value(good, "enclosed_background_residual"), 0.05);

  // A tight cluster beside it, a shallow arc along one side, a cluster on its top: the picks pass
  // check_pick_polygon (they go round something), the snake finds nothing and the error says why.
  const std::vector<std::vector<std::int64_t>> one_side = {
      ring_picks(scan, 1.6 * R, 0, 0.15 * R, 5),       // a cluster on the background beside the relief
      ring_picks(scan, 0, 0, 1.3 * R, 5, -0.5, 0.5),  // an arc along one side (and its chord)
      ring_picks(scan, 0, 0, 0.3 * R, 5),             // a cluster on the relief's top
  };
  for (const auto& picks : one_side) {
    std::vector<int> mesh_picks;
    for (const std::int64_t p : picks) mesh_picks.push_back(mesh.input_to_mesh(static_cast<std::size_t>(p)));
    EXPECT_EQ(error_of(mesh, mesh_picks), "");  // not a figure eight, not collinear
    rs::Result r;
    const std::string error = segment_error(mesh, picks, options, &r);
    EXPECT_NE(error.find(kNoRelief), std::string::npos) << "'" << error << "' status " << rs::to_string(r.status);
    EXPECT_NE(error.find("pick points on the background all around the relief"), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos);
  }
}

// On a noisy scan a ring of picks on the background beside the relief lets the snake settle on
// the noise: the result comes back, doubtful, with the reason (before: only the step share said so).
TEST(PickOrder, ARingBesideTheReliefIsDoubtfulWithTheReason) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Disk;
  spec.triangles = 20000;
  spec.noise = 0.1;
  const syn::Scan scan = syn::generate(spec);
  const rs::Mesh mesh = syn::to_mesh(scan);
  rs::Options options;
  options.step_height = scan.h;
  options.threads = 1;
  const double R = 12;
  rs::Result r;
  const std::string error = segment_error(mesh, ring_picks(scan, 1.9 * R, 0, 0.6 * R, 6), options, &r);
  ASSERT_EQ(error, "");
  EXPECT_EQ(r.status, rs::Status::Doubtful);
  EXPECT_EQ(check_value(r, "enclosed_risen_area"), 0.0);
  bool named = false;
  for (const std::string& reason : r.reasons) named = named || reason.find(kNoRelief) != std::string::npos;
  EXPECT_TRUE(named) << r.message;
  EXPECT_NE(r.message.find(kNoRelief), std::string::npos);
  // A ring around the relief on the same scan: not that reason (the noise may raise others).
  rs::Result good;
  ASSERT_EQ(segment_error(mesh, ring_picks(scan, 0, 0, 1.4 * R, 8), options, &good), "");
  EXPECT_EQ(good.message.find(kNoRelief), std::string::npos) << good.message;
  EXPECT_GT(check_value(good, "enclosed_risen_area"), 100.0);
}

// The measurement itself: what a contour encloses, above the background along it.
TEST(PickOrder, EnclosureSeesTheReliefOnlyWhenEnclosed) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Disk;
  spec.triangles = 20000;
  const syn::Scan scan = syn::generate(spec);
  const rs::Mesh mesh = syn::to_mesh(scan);
  auto enclosure = [&](const std::vector<std::int64_t>& picks) {
    std::vector<int> v;
    for (const std::int64_t p : picks) v.push_back(mesh.input_to_mesh(static_cast<std::size_t>(p)));
    const rs::InitialContour initial = rs::initial_contour(mesh, v, true);
    return rs::measure_enclosure(mesh, initial.path, rs::contour_orientation_left(mesh, initial.path));
  };
  const rs::Enclosure around = enclosure(ring_picks(scan, 0, 0, 16, 8));
  const rs::Enclosure beside = enclosure(ring_picks(scan, 23, 0, 7, 6));
  // The disk (radius 12, area 452) stands h above the plane: all of it counts at h / 2 (its vertex
  // areas take in the step's wall too: +6%).
  EXPECT_NEAR(rs::risen_area(around, 0.5), M_PI * 144, 0.1 * M_PI * 144);
  EXPECT_EQ(rs::enclosure_reason(around, 1.0), "");
  EXPECT_GT(beside.enclosed_area, 100.0);
  EXPECT_EQ(rs::risen_area(beside, 0.5), 0.0);
  EXPECT_NE(rs::enclosure_reason(beside, 1.0).find(kNoRelief), std::string::npos);
  // Judged against the h used: a relief of 1 does not rise half of h = 3 (segment() judges with
  // the h it ended with, after the refit to the step it found).
  EXPECT_NE(rs::enclosure_reason(around, 3.0).find(kNoRelief), std::string::npos);

  // A result's coverage of that risen area: the true disk covers it all (its wall's vertex areas
  // too), a patch of it a share, and nothing risen inside the picks leaves it unmeasured.
  std::vector<char> disk(mesh.n_vertices(), 0), patch(mesh.n_vertices(), 0);
  for (int v = 0; v < mesh.n_vertices(); ++v) {
    const rs::Vec3 p = mesh.position(v);
    disk[v] = std::hypot(p[0], p[1]) < 12;
    patch[v] = std::hypot(p[0] - 4, p[1]) < 3;
  }
  EXPECT_NEAR(rs::covered_share(mesh, around, disk, 1.0, 0), 1.0, 0.1);
  EXPECT_NEAR(rs::covered_share(mesh, around, patch, 1.0, 0), 9.0 / 144, 0.02);
  // Judged at the lower of h and the step found: with h = 3 typed, the step of 1 found still counts.
  EXPECT_NEAR(rs::covered_share(mesh, around, disk, 3.0, 1.0), 1.0, 0.1);
  EXPECT_EQ(rs::covered_share(mesh, around, disk, 3.0, 0), -1.0);
  EXPECT_EQ(rs::covered_share(mesh, beside, patch, 1.0, 0), -1.0);

}

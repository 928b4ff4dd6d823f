// Whole reliefs (issue 13): inner holes and bands between two pick rings, end to end on
// generated scans (hole_scans.hpp), against the truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "hole_scans.hpp"
#include "relief_snake/error.hpp"
#include "relief_snake/holes.hpp"
#include "relief_snake/segment.hpp"
#include "synthetic.hpp"

using namespace relief_snake;
using namespace relief_snake::synthetic;

namespace {

ScanSpec holed(Shape shape, char letter = 'O', std::size_t triangles = 40000) {
  ScanSpec s;
  s.shape = shape;
  s.letter = letter;
  s.triangles = triangles;
  s.step = Step::Blended;
  if (letter == 'B') s.stroke_width = 5;
  return s;
}

double iou(const std::vector<std::int64_t>& a, const std::vector<std::int64_t>& b) {
  std::vector<std::int64_t> both;
  std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
  const double uni = static_cast<double>(a.size() + b.size() - both.size());
  return uni > 0 ? static_cast<double>(both.size()) / uni : 1.0;
}

// Each result hole matched to its nearest truth hole: every truth hole found once, each within
// `edges` average edges (mean distance both ways).
void expect_holes_match(const Result& r, const Scan& scan, double edges) {
  const std::vector<Polyline> truth = hole_boundaries(scan);
  ASSERT_EQ(r.hole_polylines.size(), truth.size());
  std::set<std::size_t> matched;
  for (const std::vector<Vec3>& hole : r.hole_polylines) {
    const std::size_t k = nearest_polyline(hole, truth);
    matched.insert(k);
    const ContourMatch m = match_contour(hole, truth[k], scan.average_edge);
    EXPECT_LT(m.mean_to_truth, edges);
    EXPECT_LT(m.mean_from_truth, edges);
  }
  EXPECT_EQ(matched.size(), truth.size());
}

}  // namespace

TEST(HoleScans, ShapesWithCountersHaveHoleBoundaries) {
  const std::vector<std::pair<char, std::size_t>> letters = {{'O', 1}, {'D', 1}, {'A', 1}, {'B', 2}};
  for (const auto& [letter, holes] : letters) {
    const Scan s = generate(holed(Shape::HoledLetter, letter, 20000));
    EXPECT_EQ(hole_boundaries(s).size(), holes) << letter;
  }
  EXPECT_EQ(hole_boundaries(generate(holed(Shape::Ring, 'O', 20000))).size(), 1u);
  EXPECT_EQ(hole_boundaries(generate(holed(Shape::Disk, 'O', 20000))).size(), 0u);
  ScanSpec bad = holed(Shape::HoledLetter, 'Q', 20000);
  EXPECT_THROW(generate(bad), Error);
}

TEST(HoleScans, TubeIsOneClosedBandRoundTheAxis) {
  TubeSpec spec;
  spec.triangles = 30000;
  const Scan s = generate_tube(spec);
  const Mesh mesh = to_mesh(s);
  EXPECT_EQ(mesh.report().components, 1u);
  EXPECT_EQ(mesh.report().duplicate_vertices_merged, 0u);
  ASSERT_EQ(s.boundary.size(), 2u);
  const double fraction = s.relief_fraction();
  EXPECT_GT(fraction, 0.2);  // the band is 16 of 60 along the axis
  EXPECT_LT(fraction, 0.35);
  const TubePicks picks = tube_picks(s, spec);
  EXPECT_EQ(picks.first.size(), 12u);
  for (const std::int64_t v : picks.first) EXPECT_FALSE(s.relief[v]);
  for (const std::int64_t v : picks.second) EXPECT_FALSE(s.relief[v]);
}

TEST(Holes, RingHoleFoundWithinOneEdge) {
  const Scan scan = generate(holed(Shape::Ring));
  const Mesh mesh = to_mesh(scan);
  Options o;
  o.step_height = 1;
  const Result r = segment(mesh, scan.picks().vertices, o);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  expect_holes_match(r, scan, 1.0);
  EXPECT_GT(iou(r.relief_vertices, scan.relief_vertices()), 0.9);
  ASSERT_EQ(r.hole_checks.size(), 1u);
}

TEST(Holes, LetterBHasTwoHolesAndAutoH) {
  const Scan scan = generate(holed(Shape::HoledLetter, 'B'));
  const Mesh mesh = to_mesh(scan);
  const Result r = segment(mesh, scan.picks().vertices, Options{});
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  expect_holes_match(r, scan, 1.0);
  EXPECT_GT(iou(r.relief_vertices, scan.relief_vertices()), 0.9);
}

TEST(Holes, OffKeepsTheIslandInTheRelief) {
  const Scan scan = generate(holed(Shape::Ring));
  const Mesh mesh = to_mesh(scan);
  Options o;
  o.step_height = 1;
  o.holes = HoleMode::Off;
  const Result off = segment(mesh, scan.picks().vertices, o);
  EXPECT_TRUE(off.holes.empty());
  o.holes = HoleMode::Auto;
  const Result on = segment(mesh, scan.picks().vertices, o);
  ASSERT_EQ(on.holes.size(), 1u);
  // The hole's area (radius 9) is what auto leaves out.
  EXPECT_GT(off.relief_vertices.size(), on.relief_vertices.size() + 500);
}

TEST(Holes, PlainReliefHasNoHoles) {
  ScanSpec spec;
  spec.triangles = 40000;
  spec.detail = 0.3;  // bumps on the top are no holes
  const Scan scan = generate(spec);
  const Mesh mesh = to_mesh(scan);
  const Result r = segment(mesh, scan.picks().vertices, Options{});
  EXPECT_TRUE(r.holes.empty());
  EXPECT_EQ(r.status, Status::Converged) << r.message;
}

TEST(Holes, ReliefDroppingInsideItsEdgeIsNoHole) {
  // The top falls to 0.3 h within 1.5 h of the edge: low, ringed by relief, but not background.
  ScanSpec spec;
  spec.shape = Shape::Disk;
  spec.drop = true;
  spec.noise = 0.05;
  spec.triangles = 40000;
  const Scan scan = generate(spec);
  const Mesh mesh = to_mesh(scan);
  Options o;
  o.step_height = 1;
  const Result r = segment(mesh, scan.picks().vertices, o);
  EXPECT_TRUE(r.holes.empty());
  EXPECT_GT(iou(r.relief_vertices, scan.relief_vertices()), 0.9);
}

TEST(Holes, SmallIslandsAreIgnored) {
  const Scan scan = generate(holed(Shape::Ring));
  const Mesh mesh = to_mesh(scan);
  Options o;
  o.step_height = 1;
  o.min_hole_area = 400;  // the hole is pi 9^2 = 254 h^2
  const Result r = segment(mesh, scan.picks().vertices, o);
  EXPECT_TRUE(r.holes.empty());
  bool noted = false;
  for (const std::string& n : r.notes) noted = noted || n.find("below the minimum hole area") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(Holes, FromPicksOnTheFloor) {
  const Scan scan = generate(holed(Shape::Ring));
  const Mesh mesh = to_mesh(scan);
  Options o;
  o.step_height = 1;
  std::vector<std::int64_t> hole;
  for (int k = 0; k < 8; ++k) {  // a ring of radius 5 in the hole (radius 9)
    const double a = 2 * M_PI * k / 8;
    hole.push_back(scan.nearest_vertex(5 * std::cos(a), 5 * std::sin(a)));
  }
  o.hole_picks = {hole};
  const Result r = segment(mesh, scan.picks().vertices, o);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  expect_holes_match(r, scan, 1.0);
}

TEST(Holes, PickedHoleWithoutAStepIsDoubtful) {
  // Hole picks on the relief's flat top of a plain disk: no hole there, so no step round it.
  ScanSpec spec;
  spec.shape = Shape::Disk;
  spec.triangles = 40000;
  const Scan scan = generate(spec);
  const Mesh mesh = to_mesh(scan);
  Options o;
  o.step_height = 1;
  std::vector<std::int64_t> hole;
  for (int k = 0; k < 6; ++k) {
    const double a = 2 * M_PI * k / 6;
    hole.push_back(scan.nearest_vertex(3 * std::cos(a), 3 * std::sin(a)));
  }
  o.hole_picks = {hole};
  Result r;
  try {
    r = segment(mesh, scan.picks().vertices, o);
  } catch (const Error&) {
    return;  // refusing is also fine: no silent wrong hole
  }
  EXPECT_NE(r.status, Status::Converged);
  bool named = false;
  for (const std::string& reason : r.reasons) named = named || reason.rfind("hole 1:", 0) == 0;
  EXPECT_TRUE(named);
}

TEST(Holes, BadHolePicksAreRefused) {
  const Scan scan = generate(holed(Shape::Ring, 'O', 20000));
  const Mesh mesh = to_mesh(scan);
  Options o;
  o.hole_picks = {{1, 2}};
  EXPECT_THROW(segment(mesh, scan.picks().vertices, o), Error);
  o.hole_picks = {{1, 2, static_cast<std::int64_t>(scan.n_vertices())}};
  EXPECT_THROW(segment(mesh, scan.picks().vertices, o), Error);
}

TEST(Band, FriezeRoundACylinderWithinOneEdgeOnBothSides) {
  TubeSpec spec;
  spec.triangles = 60000;
  const Scan scan = generate_tube(spec);
  const Mesh mesh = to_mesh(scan);
  const TubePicks picks = tube_picks(scan, spec);
  Options o;
  o.step_height = 1;
  o.band_picks = picks.second;
  const Result r = segment(mesh, picks.first, o);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  ASSERT_FALSE(r.band_polyline.empty());
  const ContourMatch first = match_contour(r.polyline, scan.boundary[0], scan.average_edge);
  const ContourMatch second = match_contour(r.band_polyline, scan.boundary[1], scan.average_edge);
  EXPECT_LT(first.mean(), 1.0);
  EXPECT_LT(second.mean(), 1.0);
  EXPECT_GT(iou(r.relief_vertices, scan.relief_vertices()), 0.9);
}

TEST(Band, VaseWithAutoH) {
  TubeSpec spec;
  spec.triangles = 60000;
  spec.vase_amplitude = 0.15;
  spec.seed = 4;
  const Scan scan = generate_tube(spec);
  const Mesh mesh = to_mesh(scan);
  const TubePicks picks = tube_picks(scan, spec);
  Options o;
  o.band_picks = picks.second;
  const Result r = segment(mesh, picks.first, o);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_LT(match_contour(r.polyline, scan.boundary[0], scan.average_edge).mean(), 1.0);
  EXPECT_LT(match_contour(r.band_polyline, scan.boundary[1], scan.average_edge).mean(), 1.0);
}

TEST(Band, CrossingRingsAreRefused) {
  TubeSpec spec;
  spec.triangles = 20000;
  const Scan scan = generate_tube(spec);
  const Mesh mesh = to_mesh(scan);
  const TubePicks picks = tube_picks(scan, spec);
  // The second ring's first half below the first ring, its second half above the band: they cross.
  std::vector<std::int64_t> crossing = picks.second;
  for (std::size_t k = 0; k < crossing.size() / 2; ++k) crossing[k] = picks.first[k] - 3 * scan.grid_u;
  Options o;
  o.step_height = 1;
  o.band_picks = crossing;
  EXPECT_THROW(segment(mesh, picks.first, o), Error);
}

TEST(Band, EngravedGrooveFromRingsOnItsFloor) {
  TubeSpec spec;
  spec.triangles = 60000;
  spec.h = -1;  // cut in by 1
  spec.step = Step::Sharp;  // (blended, the contours sit at the floor, the wall's width inside the top edge)
  spec.seed = 7;
  const Scan scan = generate_tube(spec);
  const Mesh mesh = to_mesh(scan);
  const TubePicks picks = tube_picks(scan, spec);
  Options o;
  o.band_picks = picks.second;
  const Result r = segment(mesh, picks.first, o);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  bool engraved = false;
  for (const auto& [name, value] : r.checks) engraved = engraved || (name == "band_engraved" && value == 1);
  EXPECT_TRUE(engraved);
  EXPECT_LT(match_contour(r.polyline, scan.boundary[0], scan.average_edge).mean(), 1.0);
  EXPECT_LT(match_contour(r.band_polyline, scan.boundary[1], scan.average_edge).mean(), 1.0);
  EXPECT_GT(iou(r.relief_vertices, scan.relief_vertices()), 0.9);
}

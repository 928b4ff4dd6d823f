// Pick sets that cannot enclose a relief (issue 11, part 6): a figure-eight order or collinear
// picks are refused with advice instead of converging to nothing.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "relief_snake/error.hpp"
#include "relief_snake/initial_contour.hpp"
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

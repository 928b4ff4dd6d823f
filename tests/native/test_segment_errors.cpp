// Every bad input of segment() gets a one-line Error, never a crash, a hang or a partial result.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "relief_snake/error.hpp"
#include "relief_snake/segment.hpp"
#include "test_meshes.hpp"

using namespace relief_snake;

namespace {

// Two separate flat squares, 10 x 10 each, side by side (two components).
Mesh two_planes() {
  std::vector<double> V;
  std::vector<std::int64_t> F;
  const int n = 21;
  for (int part = 0; part < 2; ++part) {
    const std::int64_t base = static_cast<std::int64_t>(V.size() / 3);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) V.insert(V.end(), {part * 20.0 + i * 0.5, j * 0.5, 0.0});
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        const std::int64_t a = base + j * n + i, b = a + 1, c = a + n, d = c + 1;
        F.insert(F.end(), {a, b, d, a, d, c});
      }
  }
  return Mesh::from_triangles(V.data(), V.size() / 3, F.data(), F.size() / 3);
}

std::string error_of(const Mesh& mesh, const std::vector<std::int64_t>& picks, const Options& options) {
  try {
    segment(mesh, picks, options);
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
    EXPECT_FALSE(message.empty());
    return message;
  }
  ADD_FAILURE() << "no error";
  return {};
}

Options with_h(double h) {
  Options o;
  o.step_height = h;
  return o;
}

const std::vector<std::int64_t> kRing = {2 * 21 + 2, 2 * 21 + 18, 18 * 21 + 18, 18 * 21 + 2};

}  // namespace

TEST(SegmentErrors, TooFewPicks) {
  const Mesh mesh = two_planes();
  EXPECT_NE(error_of(mesh, {1, 2}, with_h(0.5)).find("at least 3"), std::string::npos);
  Options open = with_h(0.5);
  open.closed = false;
  EXPECT_NE(error_of(mesh, {1}, open).find("at least 2"), std::string::npos);
  EXPECT_NE(error_of(mesh, {}, with_h(0.5)).find("at least 3"), std::string::npos);
}

TEST(SegmentErrors, PicksOutOfRangeRepeatedOrOnDifferentComponents) {
  const Mesh mesh = two_planes();
  EXPECT_NE(error_of(mesh, {1, 2, 5000}, with_h(0.5)).find("not a vertex"), std::string::npos);
  EXPECT_NE(error_of(mesh, {1, -2, 5}, with_h(0.5)).find("not a vertex"), std::string::npos);
  EXPECT_NE(error_of(mesh, {44, 60, 44, 300}, with_h(0.5)).find("repeated"), std::string::npos);
  EXPECT_NE(error_of(mesh, {44, 60, 21 * 21 + 60}, with_h(0.5)).find("different parts"), std::string::npos);
}

TEST(SegmentErrors, BadStepHeight) {
  const Mesh mesh = two_planes();
  for (double h : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()})
    EXPECT_NE(error_of(mesh, kRing, with_h(h)).find("step height"), std::string::npos) << h;
  EXPECT_NE(error_of(mesh, kRing, with_h(1000.0)).find("larger than the whole mesh"), std::string::npos);
  // Far below the mesh's resolution: refused (the snake would need length / h snaxels).
  EXPECT_NE(error_of(mesh, kRing, with_h(1e-4)).find("below a tenth of the mesh's average edge"), std::string::npos);
}

TEST(SegmentErrors, WIntOutsideZeroOne) {
  const Mesh mesh = two_planes();
  // 0 is kAuto (the engine chooses); everything else outside (0, 1] is refused.
  for (double w : {-0.25, 1.5, std::numeric_limits<double>::quiet_NaN()}) {
    Options o = with_h(0.5);
    o.w_int = w;
    EXPECT_NE(error_of(mesh, kRing, o).find("W_int"), std::string::npos) << w;
  }
}

TEST(SegmentErrors, SnakeWithoutAReliefCollapsesWithAHint) {
  // A flat square with no relief: the snake shrinks to nothing.
  const Mesh mesh = two_planes();
  const std::string message = error_of(mesh, kRing, with_h(0.5));
  EXPECT_NE(message.find("collapsed"), std::string::npos) << message;
  EXPECT_NE(message.find("h"), std::string::npos);
}

TEST(SegmentErrors, CancelReturnsNothing) {
  const Mesh mesh = test::plane_mesh(41, 10);
  Options o = with_h(0.5);
  int calls = 0;
  const Result r = segment(mesh, {5 * 41 + 5, 5 * 41 + 35, 35 * 41 + 35, 35 * 41 + 5}, o, [&](const Progress& p) {
    ++calls;
    EXPECT_EQ(static_cast<int>(p.contour().size()), p.snaxels);
    return calls < 3;
  });
  EXPECT_EQ(r.status, Status::Cancelled);
  EXPECT_TRUE(r.contour.empty());
  EXPECT_TRUE(r.relief_vertices.empty());
  EXPECT_EQ(calls, 3);
}

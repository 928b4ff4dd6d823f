// Plane-fit moments and the planarity of a vertex against them (plane_fit.hpp).
#include <gtest/gtest.h>

#include <random>

#include "relief_snake/plane_fit.hpp"

namespace rs = relief_snake;
using rs::Vec3;

TEST(PlaneFit, TriangleMomentsMatchDenseSampling) {
  // Exact area moments against the average over a fine barycentric grid.
  const Vec3 a(0.3, -1.0, 2.0), b(2.5, 0.4, 1.0), c(-0.7, 1.9, 0.2);
  rs::PlaneMoments exact;
  exact.add_triangle(a, b, c);
  const double area = 0.5 * (b - a).cross(c - a).norm();
  EXPECT_NEAR(exact.weight, area, 1e-12);
  // Midpoint rule on the n^2 sub-triangles of a uniform subdivision.
  const int n = 200;
  rs::PlaneMoments sampled;
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j) {
      auto at = [&](double u, double v) { return a + (u / n) * (b - a) + (v / n) * (c - a); };
      sampled.add_point((at(i, j) + at(i + 1, j) + at(i, j + 1)) / 3.0, area / (n * n));
      if (i + j + 1 < n) sampled.add_point((at(i + 1, j) + at(i + 1, j + 1) + at(i, j + 1)) / 3.0, area / (n * n));
    }
  EXPECT_NEAR(sampled.weight, exact.weight, 1e-9);
  EXPECT_LT((sampled.first - exact.first).norm(), 1e-9);
  EXPECT_LT((sampled.second - exact.second).norm(), 1e-3 * exact.second.norm());  // midpoint rule: O(1/n^2)
}

TEST(PlaneFit, ShiftedEqualsMomentsAboutTheNewOrigin) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-5, 5);
  rs::PlaneMoments about_zero, about_o;
  const Vec3 o(1.5, -2.0, 0.25);
  for (int k = 0; k < 20; ++k) {
    const Vec3 x(u(rng), u(rng), u(rng));
    about_zero.add_point(x, 0.5 + k);
    about_o.add_point(x - o, 0.5 + k);
  }
  const rs::PlaneMoments shifted = about_zero.shifted(o);
  EXPECT_NEAR(shifted.weight, about_o.weight, 1e-12);
  EXPECT_LT((shifted.first - about_o.first).norm(), 1e-9);
  EXPECT_LT((shifted.second - about_o.second).norm(), 1e-8);
}

TEST(PlaneFit, PlanarityIsTheSignedHeightBelowTheFittedPlane) {
  // Neighbours on the plane z = 0.3 around v at the origin; v's normal up: v lies 0.3
  // below the plane, so P = +0.3 (the concave sign); with the normal down, P = -0.3.
  rs::PlaneMoments m;
  for (int k = 0; k < 12; ++k) {
    const double t = 2 * M_PI * k / 12;
    m.add_point(Vec3(std::cos(t), std::sin(t), 0.3));
  }
  EXPECT_NEAR(rs::planarity_about_vertex(m, Vec3(0, 0, 1)), 0.3, 1e-12);
  EXPECT_NEAR(rs::planarity_about_vertex(m, Vec3(0, 0, -1)), -0.3, 1e-12);
  // A triangle fan on the same plane gives the same value.
  rs::PlaneMoments fan;
  for (int k = 0; k < 12; ++k) {
    const double t0 = 2 * M_PI * k / 12, t1 = 2 * M_PI * (k + 1) / 12;
    fan.add_triangle(Vec3(0, 0, 0.3), Vec3(std::cos(t0), std::sin(t0), 0.3), Vec3(std::cos(t1), std::sin(t1), 0.3));
  }
  EXPECT_NEAR(rs::planarity_about_vertex(fan, Vec3(0, 0, 1)), 0.3, 1e-12);
}

TEST(PlaneFit, DegenerateSets) {
  rs::PlaneMoments none;
  EXPECT_EQ(rs::planarity_about_vertex(none, Vec3(0, 0, 1)), 0.0);
  rs::PlaneMoments same;  // every point at one place
  for (int k = 0; k < 4; ++k) same.add_point(Vec3(1, 1, 1));
  EXPECT_EQ(rs::planarity_about_vertex(same, Vec3(0, 0, 1)), 0.0);
  rs::PlaneMoments line;  // collinear points at height 0.5: the surface normal is used
  for (int k = -2; k <= 2; ++k) line.add_point(Vec3(k, 0, 0.5));
  EXPECT_NEAR(rs::planarity_about_vertex(line, Vec3(0, 0, 1)), 0.5, 1e-12);
}

// Each energy term against a hand computation (Eqns. 3, 4, 8, 9; Section 7.2.3).
#include <gtest/gtest.h>

#include <cmath>

#include "relief_snake/energy.hpp"
#include "test_meshes.hpp"

using namespace relief_snake;

TEST(Energy, TensionIsQuarterAlphaTimesBothSegments) {
  // Segments of length 3 and 4: E_t = alpha/4 * 7.
  EXPECT_NEAR(tension_energy(2.0, Vec3(-3, 0, 0), Vec3(0, 0, 0), Vec3(0, 4, 0)), 0.5 * 7, 1e-12);
}

TEST(Energy, BendingUsesTurnAngleAndTotalLength) {
  // Right angle: 1 - cos 90 = 1; total length 7 -> beta / 49.
  EXPECT_NEAR(bending_energy(49.0, Vec3(-3, 0, 0), Vec3(0, 0, 0), Vec3(0, 4, 0)), 1.0, 1e-12);
  // Straight: zero.
  EXPECT_NEAR(bending_energy(5.0, Vec3(-1, 0, 0), Vec3(0, 0, 0), Vec3(2, 0, 0)), 0.0, 1e-15);
  // 60 degree turn, unit segments: (1 - 0.5) / 4.
  const Vec3 next(std::cos(M_PI / 3), std::sin(M_PI / 3), 0);
  EXPECT_NEAR(bending_energy(1.0, Vec3(-1, 0, 0), Vec3(0, 0, 0), next), 0.125, 1e-12);
}

TEST(Energy, DeflationMatchesEquation9) {
  const double alpha = 0.8, beta = 0.3, tau = 0.2, l = 1.5, gs2 = 0.01;
  const double expected = -0.5 * alpha * (std::sqrt(1.04) - 1) * l - 2 * beta * 0.04 / (1.04 * 1.04 * l * l) - gs2;
  EXPECT_NEAR(deflation_energy(alpha, beta, tau, l, gs2), expected, 1e-15);
}

TEST(Energy, DeflationOvercomesInternalEnergyOfAStraightSnake) {
  // The paper's purpose for Eqn. 9: moving a snaxel of a straight snake inwards
  // by tau l costs less internal energy than the deflation gains.
  const double l = 1.0, tau = 0.2;
  const double alpha = normalise_alpha(l), beta = normalise_beta(l, 160);
  const Vec3 a(-l, 0, 0), x(0, 0, 0), b(l, 0, 0), moved(0, tau * l, 0);
  const double cost = tension_energy(alpha, a, moved, b) + bending_energy(beta, a, moved, b) -
                      tension_energy(alpha, a, x, b) - bending_energy(beta, a, x, b);
  EXPECT_GT(cost, 0);
  EXPECT_LT(cost + deflation_energy(alpha, beta, tau, l, 0), 0);
}

TEST(Energy, NormalisationBoundsTensionAndBendingToUnitRange) {
  const double l = 0.7;
  const double alpha = normalise_alpha(l), beta = normalise_beta(l, 160);
  // Longest allowed segments give E_t = 1.
  EXPECT_NEAR(tension_energy(alpha, Vec3(-1.5 * l, 0, 0), Vec3(0, 0, 0), Vec3(1.5 * l, 0, 0)), 1.0, 1e-12);
  // Shortest segments with the sharpest allowed turn give E_b = 1.
  const double t = 160 * M_PI / 180;
  const Vec3 prev(-0.5 * l, 0, 0), next(0.5 * l * std::cos(t), 0.5 * l * std::sin(t), 0);
  EXPECT_NEAR(bending_energy(beta, prev, Vec3(0, 0, 0), next), 1.0, 1e-12);
}

TEST(Energy, FeatureEnergyIsZeroOnAFlatBackgroundAndNegativeAtAStepFoot) {
  // A step of height h = 1 along x = 5 on a fine grid (steep one-cell ramp).
  const double h = 1.0;
  const Mesh mesh = test::grid_mesh(101, 41, 10, 4, [&](double u, double v) {
    return Vec3(u, v, u > 5.05 ? h : (u > 4.95 ? h * (u - 4.95) / 0.1 : 0.0));
  });
  PlanarityOptions po;
  po.radius = h;
  PlanarityField field(mesh, po);
  std::vector<int> sample;
  for (int v = 0; v < mesh.n_vertices(); v += 7) sample.push_back(v);
  field.estimate_sigma_s(sample);
  FeatureEnergy feature(field, h, 0.2, 5);
  auto at = [&](double x) {
    int best = 0;
    for (int v = 0; v < mesh.n_vertices(); ++v)
      if ((mesh.position(v) - Vec3(x, 2, 0)).norm() < (mesh.position(best) - Vec3(x, 2, 0)).norm()) best = v;
    return vertex_point(mesh, best);
  };
  const Vec3 inward(1, 0, 0);  // the relief is at larger x
  EXPECT_NEAR(feature.unscaled(at(1.5), inward), 0.0, 1e-9);  // flat, far from the step
  const double foot = feature.unscaled(at(4.9), inward);
  // Its q lies on the top edge: about h along the surface, up the step.
  const Vec3 q = position(mesh, feature.last_q());
  EXPECT_NEAR(q.z(), h, 0.25 * h);
  EXPECT_GT(foot, 0.01 * h * h);                              // deep well at the foot
  EXPECT_GT(foot, 2 * feature.unscaled(at(3.5), inward));     // deeper than 1.4 h outside
  EXPECT_GT(q.x(), 4.95);
  EXPECT_LT(q.x(), 5.05 + 0.5 * h);
  // Facing away from the relief, q lands on the flat background: a much weaker well.
  EXPECT_LT(feature.unscaled(at(4.9), -inward), 0.5 * foot);
}

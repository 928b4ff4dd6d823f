// The background fill on generated scans whose true background is known analytically.
#include <gtest/gtest.h>

#include <cstdio>
#include <numeric>

#include "extraction_truth.hpp"
#include "relief_snake/background.hpp"
#include "relief_snake/surface_point.hpp"
#include "synthetic.hpp"
#include "test_meshes.hpp"

namespace relief_snake {
namespace {

using synthetic::Background;

synthetic::Scan sharp_duck(Background background, std::size_t triangles = 40000, double noise = 0) {
  synthetic::ScanSpec spec;
  spec.shape = synthetic::Shape::Duck;
  spec.background = background;
  spec.triangles = triangles;
  spec.h = 1;
  spec.noise = noise;
  spec.seed = 3;
  return synthetic::generate(spec);
}

std::vector<char> truth_region(const synthetic::Scan& scan) {
  return std::vector<char>(scan.relief.begin(), scan.relief.end());
}

class BackgroundOnAnalyticSurfaces : public ::testing::TestWithParam<Background> {};

TEST_P(BackgroundOnAnalyticSurfaces, BaseAndHeightWithinFiveHundredthsOfH) {
  const synthetic::Scan scan = sharp_duck(GetParam());
  const Mesh mesh = synthetic::to_mesh(scan);
  const BackgroundSolver solver(mesh);
  const BackgroundResult fill = solver.solve(truth_region(scan), scan.h);
  ASSERT_TRUE(fill.ok()) << fill.message;
  const test::FillErrors e = test::fill_errors(scan, fill, 1.0 * scan.h);
  std::printf("[ measured ] %s: base mean %.4f max %.4f, height mean %.4f max %.4f (h = %g, %zu vertices), ring rms %.4g, %.3f s\n",
              synthetic::to_string(GetParam()), e.mean_base, e.max_base, e.mean_height, e.max_height, scan.h,
              e.vertices, fill.ring_rms_residual, fill.seconds);
  ASSERT_GT(e.vertices, 1000u);
  EXPECT_LE(e.mean_base, 0.05 * scan.h);
  EXPECT_LE(e.mean_height, 0.05 * scan.h);
  // A sharp step on a noiseless smooth background: the ring is explained almost exactly.
  EXPECT_LT(fill.ring_rms_residual, 0.05 * scan.h);
}

TEST_P(BackgroundOnAnalyticSurfaces, VerticesOutsideTheRegionKeepTheirPositionsExactly) {
  const synthetic::Scan scan = sharp_duck(GetParam(), 20000);
  const Mesh mesh = synthetic::to_mesh(scan);
  const BackgroundResult fill = BackgroundSolver(mesh).solve(truth_region(scan), scan.h);
  ASSERT_TRUE(fill.ok()) << fill.message;
  std::size_t moved = 0;
  for (int v = 0; v < mesh.n_vertices(); ++v) {
    if (fill.region[v]) {
      moved += fill.base_positions[v] != mesh.position(v);
      continue;
    }
    if (std::binary_search(fill.ring_vertices.begin(), fill.ring_vertices.end(), v)) continue;
    EXPECT_EQ(fill.base_positions[v], mesh.position(v)) << "vertex " << v;
    EXPECT_EQ(fill.height[v], 0.0);
  }
  EXPECT_GT(moved, fill.region_vertices.size() / 2);  // the relief's vertices did move down
}

INSTANTIATE_TEST_SUITE_P(Backgrounds, BackgroundOnAnalyticSurfaces,
                         ::testing::Values(Background::Plane, Background::Cylinder, Background::Sphere,
                                           Background::Saddle),
                         [](const auto& param_info) { return std::string(synthetic::to_string(param_info.param)); });

TEST(Background, FixedRingAndUniformLaplacianAlsoWork) {
  const synthetic::Scan scan = sharp_duck(Background::Cylinder, 20000);
  const Mesh mesh = synthetic::to_mesh(scan);
  for (const BackgroundModel model : {BackgroundModel::HeightField, BackgroundModel::Surface})
  for (const BackgroundLaplacian laplacian : {BackgroundLaplacian::Cotangent, BackgroundLaplacian::Uniform})
    for (const double smoothing : {0.0, 0.5}) {
      BackgroundOptions options;
      options.model = model;
      options.laplacian = laplacian;
      options.smoothing = smoothing;
      const BackgroundResult fill = BackgroundSolver(mesh, options).solve(truth_region(scan), scan.h);
      ASSERT_TRUE(fill.ok()) << fill.message;
      const test::FillErrors e = test::fill_errors(scan, fill, 1.0 * scan.h);
      std::printf("[ measured ] cylinder %s %s smoothing %.1f: base mean %.4f, height mean %.4f, ring rms %.4g\n",
                  model == BackgroundModel::Surface ? "surface" : "height-field", laplacian == BackgroundLaplacian::Uniform ? "uniform" : "cotangent", smoothing, e.mean_base,
                  e.mean_height, fill.ring_rms_residual);
      EXPECT_LE(e.mean_height, 0.1 * scan.h);
      // Without smoothing the ring is fitted exactly (the check has no `if`: gtest's macros inside
      // one trip -Wdangling-else in this nest of loops).
      EXPECT_EQ(smoothing == 0 ? fill.ring_rms_residual : 0.0, 0.0);
    }
}

// fill_background() is one solve with the options given where that solve works (the uniform-weights
// retry is for a singular cotangent system only), and passes a failure through.
TEST(Background, FillBackgroundIsOneSolveWithItsOptions) {
  const synthetic::Scan scan = sharp_duck(Background::Cylinder, 20000);
  const Mesh mesh = synthetic::to_mesh(scan);
  const std::vector<char> region = truth_region(scan);
  for (const BackgroundLaplacian laplacian : {BackgroundLaplacian::Cotangent, BackgroundLaplacian::Uniform}) {
    BackgroundOptions options;
    options.laplacian = laplacian;
    const BackgroundResult direct = BackgroundSolver(mesh, options).solve(region, scan.h);
    const BackgroundResult helper = fill_background(mesh, region, scan.h, options);
    ASSERT_TRUE(direct.ok() && helper.ok()) << direct.message << helper.message;
    EXPECT_EQ(helper.height, direct.height);
  }
  BackgroundOptions cotangent, uniform;
  uniform.laplacian = BackgroundLaplacian::Uniform;
  EXPECT_NE(fill_background(mesh, region, scan.h, cotangent).height,
            fill_background(mesh, region, scan.h, uniform).height);  // the options are used
  const BackgroundResult empty = fill_background(mesh, std::vector<char>(mesh.n_vertices(), 0), scan.h);
  EXPECT_EQ(empty.status, BackgroundStatus::EmptyRegion);
}

TEST(Background, NoiseOnTheRingShowsInTheResidual) {
  const synthetic::Scan clean = sharp_duck(Background::Plane, 20000, 0.0);
  const synthetic::Scan noisy = sharp_duck(Background::Plane, 20000, 0.05);
  const Mesh clean_mesh = synthetic::to_mesh(clean), noisy_mesh = synthetic::to_mesh(noisy);
  const BackgroundResult a = BackgroundSolver(clean_mesh).solve(truth_region(clean), 1.0);
  const BackgroundResult b = BackgroundSolver(noisy_mesh).solve(truth_region(noisy), 1.0);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_LT(a.ring_rms_residual, 1e-9);  // a plane is explained exactly
  EXPECT_GT(b.ring_rms_residual, 0.02);  // sigma 0.05 h of noise, mostly left in the ring
  EXPECT_LT(b.ring_rms_residual, 0.06);
  const test::FillErrors e = test::fill_errors(noisy, b, 1.0);
  EXPECT_LE(e.mean_base, 0.05);  // the fill does not follow the noise
}

TEST(Background, HeightAboveAtSurfacePointsMatchesTheVertices) {
  const synthetic::Scan scan = sharp_duck(Background::Sphere, 20000);
  const Mesh mesh = synthetic::to_mesh(scan);
  const BackgroundResult fill = BackgroundSolver(mesh).solve(truth_region(scan), scan.h);
  ASSERT_TRUE(fill.ok());
  std::vector<SurfacePoint> points;
  std::vector<int> vertices;
  for (int v = 0; v < mesh.n_vertices(); v += 97) {
    points.push_back(vertex_point(mesh, v));
    vertices.push_back(v);
  }
  const std::vector<double> heights = height_above(mesh, fill, points);
  for (std::size_t i = 0; i < points.size(); ++i) EXPECT_NEAR(heights[i], fill.height[vertices[i]], 1e-9);
  // Inside a relief face the height is interpolated between its corners.
  const int f = mesh.faces_begin(fill.region_vertices[fill.region_vertices.size() / 2])[0];
  SurfacePoint centre{f, Vec3(1.0 / 3, 1.0 / 3, 1.0 / 3)};
  const double h = height_above(mesh, fill, {centre})[0];
  EXPECT_GT(h, 0.5 * scan.h);
  EXPECT_LT(h, 1.5 * scan.h);
}

TEST(Background, ErrorsSayWhatIsWrong) {
  const Mesh mesh = test::plane_mesh(21, 10);
  const BackgroundSolver solver(mesh);
  const std::vector<char> none(static_cast<std::size_t>(mesh.n_vertices()), 0);
  BackgroundResult r = solver.solve(none, 1.0);
  EXPECT_EQ(r.status, BackgroundStatus::EmptyRegion);
  EXPECT_NE(r.message.find("empty"), std::string::npos);

  const std::vector<char> all(static_cast<std::size_t>(mesh.n_vertices()), 1);
  r = solver.solve(all, 1.0);
  EXPECT_EQ(r.status, BackgroundStatus::NoRing);
  EXPECT_NE(r.message.find("no background"), std::string::npos);

  r = solver.solve(std::vector<char>(5, 1), 1.0);
  EXPECT_EQ(r.status, BackgroundStatus::SizeMismatch);
  r = solver.solve_vertices({0, mesh.n_vertices()}, 1.0);
  EXPECT_EQ(r.status, BackgroundStatus::SizeMismatch);
  EXPECT_NE(r.message.find("out of range"), std::string::npos);

  std::vector<char> middle = none;
  middle[static_cast<std::size_t>(10 * 21 + 10)] = 1;
  r = solver.solve(middle, 0.0);
  EXPECT_EQ(r.status, BackgroundStatus::BadParameter);
  for (const BackgroundResult& failed : {solver.solve(none, 1.0), solver.solve(all, 1.0)})
    EXPECT_EQ(failed.message.find('\n'), std::string::npos);
}

TEST(Background, SingleVertexBumpOnAPlaneIsRemoved) {
  // A plane with one vertex raised: the fill puts it back on the plane, height = the bump.
  const int n = 21;
  const Mesh mesh = test::grid_mesh(n, n, 10, 10, [](double u, double v) {
    return Vec3(u, v, (std::abs(u - 5) < 1e-9 && std::abs(v - 5) < 1e-9) ? 0.7 : 0.0);
  });
  std::vector<char> region(static_cast<std::size_t>(mesh.n_vertices()), 0);
  region[static_cast<std::size_t>(10 * n + 10)] = 1;
  const BackgroundResult r = BackgroundSolver(mesh).solve(region, 1.0);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_NEAR(r.base_positions[10 * n + 10].z(), 0.0, 1e-9);
  EXPECT_NEAR(r.height[10 * n + 10], 0.7, 1e-9);
}

}  // namespace
}  // namespace relief_snake

namespace relief_snake {
namespace {

TEST(Background, ReliefRunningOffTheMeshBorder) {
  // The open shape: a relief cut by the mesh's right edge, so the region reaches the border
  // (a regression: values along the border were underdetermined without its rows).
  synthetic::ScanSpec spec;
  spec.shape = synthetic::Shape::Open;
  spec.background = synthetic::Background::Cylinder;
  spec.triangles = 30000;
  spec.seed = 4;
  const synthetic::Scan scan = synthetic::generate(spec);
  const Mesh mesh = synthetic::to_mesh(scan);
  const BackgroundResult fill = BackgroundSolver(mesh).solve(std::vector<char>(scan.relief.begin(), scan.relief.end()), scan.h);
  ASSERT_TRUE(fill.ok()) << fill.message;
  bool on_border = false;
  for (const int v : fill.region_vertices) on_border = on_border || mesh.is_boundary_vertex(v);
  ASSERT_TRUE(on_border);
  const test::FillErrors e = test::fill_errors(scan, fill, 1.0 * scan.h);
  std::printf("[ measured ] open relief on a cylinder: base mean %.4f max %.4f, height mean %.4f max %.4f\n", e.mean_base,
              e.max_base, e.mean_height, e.max_height);
  EXPECT_LE(e.mean_base, 0.05 * scan.h);
  EXPECT_LE(e.mean_height, 0.05 * scan.h);
  EXPECT_LE(e.max_height, 0.2 * scan.h);
}

}  // namespace
}  // namespace relief_snake

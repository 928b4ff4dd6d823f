// The moment tree's sphere queries against brute force (moment_tree.hpp).
#include <gtest/gtest.h>

#include <random>

#include "relief_snake/moment_tree.hpp"
#include "test_meshes.hpp"

namespace rs = relief_snake;
using rs::Vec3;

namespace {

// A wavy, jittered sheet: normals vary, so the tree's normal cones matter.
rs::Mesh wavy_mesh() {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  return rs::test::grid_mesh(61, 61, 12, 12, [&](double u, double v) {
    const double x = u + jitter(rng) * 0.2, y = v + jitter(rng) * 0.2;
    return Vec3(x, y, 0.8 * std::sin(x) * std::cos(0.7 * y));
  });
}

rs::PlaneMoments brute_force(const rs::Mesh& mesh, rs::MomentTree::Elements elements,
                             const rs::MomentTree::Query& q) {
  rs::PlaneMoments m;
  const Vec3 facing = q.facing.norm() > 0 ? Vec3(q.facing.normalized()) : Vec3::Zero();
  const bool test_facing = q.facing.norm() > 0 && q.min_facing > -1;
  if (elements == rs::MomentTree::Elements::Faces) {
    for (int f = 0; f < mesh.n_faces(); ++f) {
      if (test_facing && mesh.face_normal(f).dot(facing) < q.min_facing) continue;
      const Vec3 a = mesh.position(mesh.face_vertex(f, 0)), b = mesh.position(mesh.face_vertex(f, 1)),
                 c = mesh.position(mesh.face_vertex(f, 2));
      if (((a + b + c) / 3.0 - q.center).norm() <= q.radius) m.add_triangle(a - q.center, b - q.center, c - q.center);
    }
  } else {
    for (int v = 0; v < mesh.n_vertices(); ++v) {
      if (test_facing && mesh.vertex_normal(v).dot(facing) < q.min_facing) continue;
      if ((mesh.position(v) - q.center).norm() <= q.radius) m.add_point(mesh.position(v) - q.center);
    }
  }
  return m;
}

void expect_same(const rs::PlaneMoments& got, const rs::PlaneMoments& want, const char* what) {
  EXPECT_NEAR(got.weight, want.weight, 1e-9 * (1 + want.weight)) << what;
  EXPECT_LT((got.first - want.first).norm(), 1e-9 * (1 + want.first.norm())) << what;
  EXPECT_LT((got.second - want.second).norm(), 1e-9 * (1 + want.second.norm())) << what;
}

}  // namespace

TEST(MomentTree, SphereSumsEqualBruteForce) {
  const rs::Mesh mesh = wavy_mesh();
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> pick(0, mesh.n_vertices() - 1);
  for (auto elements : {rs::MomentTree::Elements::Faces, rs::MomentTree::Elements::Vertices}) {
    const rs::MomentTree tree(mesh, elements);
    EXPECT_GT(tree.node_count(), 100u);
    for (int trial = 0; trial < 40; ++trial) {
      const int v = pick(rng);
      rs::MomentTree::Query q;
      q.center = mesh.position(v);
      q.radius = 0.3 + 0.1 * (trial % 20);  // from about one edge to a sixth of the sheet
      if (trial % 2) {
        q.facing = mesh.vertex_normal(v);
        q.min_facing = 0.6;  // a real cut on this sheet: its normals turn by up to ~50 degrees
      }
      expect_same(tree.sphere(q), brute_force(mesh, elements, q), trial % 2 ? "with facing" : "plain");
    }
  }
}

TEST(MomentTree, GrainCountsSmallNodesByTheirCentroid) {
  // With a grain, the sum is no longer exact at the sphere's surface but stays close:
  // every element within radius - grain is counted, none beyond radius + grain.
  const rs::Mesh mesh = wavy_mesh();
  const rs::MomentTree tree(mesh, rs::MomentTree::Elements::Faces);
  rs::MomentTree::Query q;
  q.center = mesh.position(mesh.n_vertices() / 2);
  q.radius = 2.0;
  q.grain = 0.5;
  const double got = tree.sphere(q).weight;
  rs::MomentTree::Query inner = q, outer = q;
  inner.radius -= q.grain;
  outer.radius += q.grain;
  EXPECT_GE(got, brute_force(mesh, tree.elements(), inner).weight);
  EXPECT_LE(got, brute_force(mesh, tree.elements(), outer).weight);
}

TEST(MomentTree, ComponentsAreKeptApart) {
  // Two parallel sheets 0.1 apart: a sphere of radius 1 reaches both, the query for one
  // component sees only its own.
  std::vector<double> V;
  std::vector<std::int64_t> F;
  const int n = 11;
  for (int sheet = 0; sheet < 2; ++sheet) {
    const std::int64_t base = static_cast<std::int64_t>(V.size() / 3);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) V.insert(V.end(), {0.2 * i, 0.2 * j, 0.1 * sheet});
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        const std::int64_t a = base + j * n + i;
        F.insert(F.end(), {a, a + 1, a + n + 1, a, a + n + 1, a + n});
      }
  }
  const rs::Mesh mesh = rs::Mesh::from_triangles(V.data(), V.size() / 3, F.data(), F.size() / 3);
  ASSERT_EQ(mesh.report().components, 2u);
  const rs::MomentTree tree(mesh, rs::MomentTree::Elements::Vertices);
  rs::MomentTree::Query q;
  q.center = Vec3(1, 1, 0);
  q.radius = 1.03;  // no lattice point exactly on the sphere
  const double both = tree.sphere(q).weight;
  int near = 0, far = 0;  // vertices of each sheet inside the sphere
  for (int v = 0; v < mesh.n_vertices(); ++v)
    if ((mesh.position(v) - q.center).norm() <= q.radius) ++(mesh.position(v).z() < 0.05 ? near : far);
  ASSERT_GT(near, 0);
  ASSERT_GT(far, 0);
  EXPECT_EQ(both, near + far);
  q.component = mesh.component(mesh.input_to_mesh(0));
  EXPECT_EQ(tree.sphere(q).weight, near);
}

// Mesh intake: validation, merging, triangulation, refusal accounting, adjacency
// arrays and file round trips, on small hand-made meshes with known answers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "relief_snake/error.hpp"
#include "relief_snake/mesh.hpp"

namespace rs = relief_snake;
namespace fs = std::filesystem;

namespace {

/// nx by ny vertices on z = 0 with spacing s; each cell split along its (i,j)-(i+1,j+1)
/// diagonal, counter-clockwise seen from +z.
struct Grid {
  std::vector<double> V;
  std::vector<std::int64_t> F;
  std::size_t nv() const { return V.size() / 3; }
  std::size_t nf() const { return F.size() / 3; }
};

Grid make_grid(int nx, int ny, double s = 1.0, double x0 = 0.0) {
  Grid g;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) g.V.insert(g.V.end(), {x0 + i * s, j * s, 0.0});
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const std::int64_t a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      g.F.insert(g.F.end(), {a, b, d, a, d, c});
    }
  return g;
}

rs::Mesh build(const Grid& g) { return rs::Mesh::from_triangles(g.V.data(), g.nv(), g.F.data(), g.nf()); }

/// Runs f, expects an rs::Error whose message contains every one of `parts`.
template <class F>
void expect_error(F&& f, std::initializer_list<std::string> parts) {
  try {
    f();
    ADD_FAILURE() << "expected relief_snake::Error";
  } catch (const rs::Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << "message must be one line: " << what;
    for (const std::string& p : parts) EXPECT_NE(what.find(p), std::string::npos) << "'" << p << "' not in: " << what;
  }
}

void expect_report_accounts_for_every_face(const rs::MeshReport& r, std::size_t kept_triangles) {
  EXPECT_EQ(r.input_faces, kept_triangles + r.polygons_triangulated + r.degenerate_faces + r.nonmanifold_faces);
}

/// Every neighbour relation is mutual and the shared edge has the same two vertices.
void expect_consistent_neighbors(const rs::Mesh& m) {
  for (int f = 0; f < m.n_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int g = m.face_neighbor(f, k);
      if (g < 0) continue;
      ASSERT_LT(g, m.n_faces());
      const int a = m.face_vertex(f, (k + 1) % 3), b = m.face_vertex(f, (k + 2) % 3);
      int back = -1;
      for (int kk = 0; kk < 3; ++kk)
        if (m.face_neighbor(g, kk) == f) back = kk;
      ASSERT_GE(back, 0) << "face " << g << " does not list " << f << " as a neighbour";
      // Consistent orientation: g walks the shared edge the other way round.
      EXPECT_EQ(m.face_vertex(g, (back + 1) % 3), b);
      EXPECT_EQ(m.face_vertex(g, (back + 2) % 3), a);
    }
  }
}

class TempDir {
 public:
  TempDir() {
    path_ = fs::temp_directory_path() /
            ("relief_snake_test_mesh_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string write(const std::string& name, const std::string& content) const {
    const fs::path p = path_ / name;
    std::ofstream(p, std::ios::binary) << content;
    return p.string();
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

template <class T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

}  // namespace

// --- arrays ------------------------------------------------------------------

TEST(MeshIntake, GridCountsBoundaryAndEdgeLength) {
  const double s = 0.5;
  const rs::Mesh m = build(make_grid(3, 3, s));
  EXPECT_EQ(m.n_vertices(), 9);
  EXPECT_EQ(m.n_faces(), 8);
  const rs::MeshReport& r = m.report();
  EXPECT_EQ(r.triangles, 8u);
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.boundary_edges, 8u);
  EXPECT_EQ(r.degenerate_faces + r.nonmanifold_faces + r.duplicate_vertices_merged + r.unreferenced_vertices, 0u);
  expect_report_accounts_for_every_face(r, 8);
  for (int v = 0; v < 9; ++v) EXPECT_EQ(m.is_boundary_vertex(v), v != 4) << "vertex " << v;
  // 12 axis edges of length s and 4 diagonals of length s*sqrt(2).
  EXPECT_NEAR(m.average_edge_length(), (12 * s + 4 * s * std::sqrt(2.0)) / 16, 1e-12);
  EXPECT_NEAR(m.bbox_diagonal(), 2 * s * std::sqrt(2.0), 1e-12);
  EXPECT_EQ(m.n_faces(), 8);
  EXPECT_EQ(m.n_vertices(), 9);
  // Corner order is the input's (counter-clockwise), and area is s^2/2 per triangle.
  EXPECT_EQ(m.face_vertex(0, 0), 0);
  EXPECT_EQ(m.face_vertex(0, 1), 1);
  EXPECT_EQ(m.face_vertex(0, 2), 4);
  for (int f = 0; f < 8; ++f) EXPECT_NEAR(m.face_area(f), 0.5 * s * s, 1e-12);
}

TEST(MeshIntake, OneRingOfInteriorVertex) {
  const rs::Mesh m = build(make_grid(3, 3));
  // Centre vertex 4: neighbours are all but its two non-diagonal corners 2 and 6.
  const std::set<int> ring(m.neighbors_begin(4), m.neighbors_end(4));
  EXPECT_EQ(static_cast<std::size_t>(m.neighbors_end(4) - m.neighbors_begin(4)), ring.size()) << "duplicates";
  EXPECT_EQ(ring, (std::set<int>{0, 1, 3, 5, 7, 8}));
  EXPECT_EQ(m.faces_end(4) - m.faces_begin(4), 6);
  for (const int* f = m.faces_begin(4); f != m.faces_end(4); ++f) {
    const bool has4 = m.face_vertex(*f, 0) == 4 || m.face_vertex(*f, 1) == 4 || m.face_vertex(*f, 2) == 4;
    EXPECT_TRUE(has4);
  }
  // Corner vertex 2 is in one face only and has two neighbours.
  EXPECT_EQ(m.faces_end(2) - m.faces_begin(2), 1);
  EXPECT_EQ(std::set<int>(m.neighbors_begin(2), m.neighbors_end(2)), (std::set<int>{1, 5}));
}

TEST(MeshIntake, FaceNeighborsAreSymmetricAndOppositeTheirCorner) {
  const rs::Mesh m = build(make_grid(5, 4, 0.3));
  expect_consistent_neighbors(m);
  // Face 0 = (0, 1, 6) on a 5-wide grid: edge opposite corner 0 joins 1 and 6 and is
  // shared with face 3 = (1, 7, 6); the other two edges of face 0 are... (0,1) boundary, (6,0) face 1.
  EXPECT_EQ(m.face_neighbor(0, 2), -1);   // edge 0-1 on the bottom boundary
  EXPECT_EQ(m.face_neighbor(0, 1), 1);    // edge 6-0: face 1 = (0, 6, 5)
  EXPECT_EQ(m.face_neighbor(0, 0), 3);    // edge 1-6: face 3 = (1, 7, 6)
  int boundary = 0;
  for (int f = 0; f < m.n_faces(); ++f)
    for (int k = 0; k < 3; ++k) boundary += m.face_neighbor(f, k) < 0;
  EXPECT_EQ(static_cast<std::size_t>(boundary), m.report().boundary_edges);
  EXPECT_EQ(boundary, 2 * 4 + 2 * 3);
}

TEST(MeshIntake, VertexNormalsFollowFaceOrientation) {
  Grid g = make_grid(4, 4);
  for (std::size_t i = 0; i < g.nv(); ++i) g.V[3 * i + 2] = 0.1 * static_cast<double>(i % 3);  // a little relief
  const rs::Mesh up = build(g);
  for (int v = 0; v < up.n_vertices(); ++v) {
    EXPECT_NEAR(up.vertex_normal(v).norm(), 1.0, 1e-12);
    EXPECT_GT(up.vertex_normal(v).z(), 0.5) << "vertex " << v;
  }
  for (std::size_t f = 0; f < g.nf(); ++f) std::swap(g.F[3 * f + 1], g.F[3 * f + 2]);
  const rs::Mesh down = build(g);
  for (int v = 0; v < down.n_vertices(); ++v) EXPECT_NEAR((down.vertex_normal(v) + up.vertex_normal(v)).norm(), 0.0, 1e-12);
  for (int f = 0; f < down.n_faces(); ++f) EXPECT_LT(down.face_normal(f).z(), 0.0);
}

TEST(MeshIntake, ClosedOctahedronHasOutwardNormalsAndNoBoundary) {
  const std::vector<double> V = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
  const std::vector<std::int64_t> F = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  const rs::Mesh m = rs::Mesh::from_triangles(V.data(), 6, F.data(), 8);
  EXPECT_EQ(m.report().boundary_edges, 0u);
  EXPECT_EQ(m.report().components, 1u);
  for (int v = 0; v < 6; ++v) {
    EXPECT_FALSE(m.is_boundary_vertex(v));
    EXPECT_NEAR(m.vertex_normal(v).dot(m.position(v)), 1.0, 1e-12);  // unit position = outward normal
    EXPECT_EQ(m.neighbors_end(v) - m.neighbors_begin(v), 4);
  }
  expect_consistent_neighbors(m);
  EXPECT_NEAR(m.average_edge_length(), std::sqrt(2.0), 1e-12);
}

TEST(MeshIntake, QuadsAndPentagonAreFanned) {
  // 3 x 2 vertices, two quads, plus a pentagon beside them.
  std::vector<rs::Vec3> V = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0},
                             {3, 0, 0}, {4, 0, 0}, {4.5, 0.5, 0}, {4, 1, 0}, {3, 1, 0}};
  const std::vector<std::int64_t> corners = {0, 1, 4, 3, 1, 2, 5, 4, 6, 7, 8, 9, 10};
  const std::vector<std::size_t> offsets = {0, 4, 8, 13};
  const rs::Mesh m = rs::Mesh::from_polygons(V, corners, offsets);
  EXPECT_EQ(m.n_faces(), 2 + 2 + 3);
  EXPECT_EQ(m.report().polygons_triangulated, 3u);
  EXPECT_EQ(m.report().components, 2u);
  expect_report_accounts_for_every_face(m.report(), 0);
  EXPECT_NE(m.report().summary().find("3 polygons triangulated"), std::string::npos) << m.report().summary();
  double area = 0;
  for (int f = 0; f < m.n_faces(); ++f) area += m.face_area(f);
  EXPECT_NEAR(area, 2.0 + 1.0 + 0.25, 1e-12);  // two unit quads, unit square plus a 0.25 triangle
  expect_consistent_neighbors(m);
}

TEST(MeshIntake, TriangleSoupIsMergedIntoOneComponent) {
  const Grid g = make_grid(4, 3);
  Grid soup;  // every triangle with its own three vertices, as in STL
  for (std::size_t f = 0; f < g.nf(); ++f)
    for (int k = 0; k < 3; ++k) {
      const std::int64_t v = g.F[3 * f + k];
      soup.V.insert(soup.V.end(), {g.V[3 * v], g.V[3 * v + 1], g.V[3 * v + 2]});
      soup.F.push_back(static_cast<std::int64_t>(3 * f + k));
    }
  // A negative zero must merge with zero.
  soup.V[0] = -0.0;
  const rs::Mesh m = build(soup);
  const rs::Mesh reference = build(g);
  EXPECT_EQ(m.n_vertices(), 12);
  EXPECT_EQ(m.n_faces(), 12);
  EXPECT_EQ(m.report().components, 1u);
  EXPECT_EQ(m.report().duplicate_vertices_merged, soup.nv() - 12);
  EXPECT_EQ(m.report().boundary_edges, reference.report().boundary_edges);
  EXPECT_NEAR(m.average_edge_length(), reference.average_edge_length(), 1e-12);
  expect_consistent_neighbors(m);
  // Every soup vertex maps to the mesh vertex at its position; mesh_to_input is the first copy.
  for (std::size_t i = 0; i < soup.nv(); ++i) {
    const int v = m.input_to_mesh(i);
    ASSERT_GE(v, 0);
    EXPECT_EQ(m.position(v), rs::Vec3(soup.V[3 * i] + 0.0, soup.V[3 * i + 1], soup.V[3 * i + 2]));
    EXPECT_LE(m.mesh_to_input(v), i);
    EXPECT_EQ(m.input_to_mesh(m.mesh_to_input(v)), v);
  }
}

TEST(MeshIntake, DegenerateFacesAreSkippedAndCounted) {
  Grid g = make_grid(3, 3);
  g.V.insert(g.V.end(), {0.5, 0.0, 0.0});  // vertex 9 on the segment 0-1: collinear with them
  g.V.insert(g.V.end(), {2.0, 2.0, 0.0});  // vertex 10: an exact duplicate of vertex 8
  g.F.insert(g.F.end(), {0, 1, 1});        // repeated corner
  g.F.insert(g.F.end(), {0, 9, 1});        // zero area
  g.F.insert(g.F.end(), {8, 10, 5});       // repeated after merging
  const rs::Mesh m = build(g);
  const rs::MeshReport& r = m.report();
  EXPECT_EQ(r.degenerate_faces, 3u);
  EXPECT_EQ(r.triangles, 8u);
  EXPECT_EQ(r.input_faces, 11u);
  EXPECT_EQ(r.duplicate_vertices_merged, 1u);
  EXPECT_EQ(r.unreferenced_vertices, 1u);  // vertex 9 is in the zero-area face only
  EXPECT_EQ(m.input_to_mesh(9), -1);
  EXPECT_EQ(m.input_to_mesh(10), m.input_to_mesh(8));
  expect_report_accounts_for_every_face(r, 8);
  EXPECT_NE(r.summary().find("3 degenerate faces skipped"), std::string::npos) << r.summary();
}

TEST(MeshIntake, NonManifoldFinIsRefusedAndCounted) {
  // Two triangles on edge 0-1, and a third "fin" on the same edge.
  const std::vector<double> V = {0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, -1, 0, 0.5, 0, 1};
  const std::vector<std::int64_t> F = {0, 1, 2, 1, 0, 3, 0, 1, 4};
  const rs::Mesh m = rs::Mesh::from_triangles(V.data(), 5, F.data(), 3);
  const rs::MeshReport& r = m.report();
  EXPECT_EQ(r.nonmanifold_faces, 1u);
  EXPECT_EQ(r.triangles, 2u);
  EXPECT_EQ(m.n_vertices(), 4);
  EXPECT_EQ(r.unreferenced_vertices, 1u);  // vertex 4 was only in the fin
  EXPECT_EQ(m.input_to_mesh(4), -1);
  EXPECT_EQ(m.n_vertices(), 4);
  expect_report_accounts_for_every_face(r, 2);
  EXPECT_NE(r.summary().find("1 non-manifold face refused"), std::string::npos) << r.summary();
  expect_consistent_neighbors(m);
}

TEST(MeshIntake, HoleMakesInnerBoundary) {
  Grid g = make_grid(5, 5);
  // Remove the two triangles of the cell (1,1)-(2,2): faces of cell (i=1, j=1) are 2*(1*4+1), +1.
  g.F.erase(g.F.begin() + 3 * 10, g.F.begin() + 3 * 12);
  const rs::Mesh m = build(g);
  EXPECT_EQ(m.report().boundary_edges, 16u + 4u);
  EXPECT_EQ(m.report().components, 1u);
  for (int v : {6, 7, 11, 12}) EXPECT_TRUE(m.is_boundary_vertex(v)) << v;  // the hole's corners
  for (int v : {13, 16, 17, 18}) EXPECT_FALSE(m.is_boundary_vertex(v)) << v;
  expect_consistent_neighbors(m);
}

TEST(MeshIntake, TwoComponents) {
  Grid a = make_grid(3, 3), b = make_grid(2, 2, 1.0, 10.0);
  const std::int64_t shift = static_cast<std::int64_t>(a.nv());
  a.V.insert(a.V.end(), b.V.begin(), b.V.end());
  for (std::int64_t c : b.F) a.F.push_back(c + shift);
  const rs::Mesh m = build(a);
  EXPECT_EQ(m.report().components, 2u);
  for (int v = 0; v < 9; ++v) EXPECT_EQ(m.component(v), m.component(0));
  for (int v = 9; v < 13; ++v) EXPECT_EQ(m.component(v), m.component(9));
  EXPECT_NE(m.component(0), m.component(9));
  EXPECT_NE(m.report().summary().find("2 components"), std::string::npos);
}

TEST(MeshIntake, UnreferencedVertexMapping) {
  Grid g = make_grid(3, 3);
  // Insert an unused vertex at input index 0 by shifting every face index.
  g.V.insert(g.V.begin(), {7.0, 7.0, 7.0});
  for (std::int64_t& c : g.F) ++c;
  const rs::Mesh m = build(g);
  EXPECT_EQ(m.input_vertex_count(), 10u);
  EXPECT_EQ(m.n_vertices(), 9);
  EXPECT_EQ(m.input_to_mesh(0), -1);
  EXPECT_EQ(m.report().unreferenced_vertices, 1u);
  for (std::size_t i = 1; i < 10; ++i) {
    const int v = m.input_to_mesh(i);
    ASSERT_GE(v, 0);
    EXPECT_EQ(m.mesh_to_input(v), i);
    EXPECT_EQ(m.position(v), rs::Vec3(g.V[3 * i], g.V[3 * i + 1], g.V[3 * i + 2]));
  }
  EXPECT_NEAR(m.bbox_diagonal(), 2 * std::sqrt(2.0), 1e-12);  // the unused vertex is not in the box
}

// --- errors --------------------------------------------------------------------

TEST(MeshIntake, ErrorsNameTheProblem) {
  const Grid g = make_grid(3, 3);
  expect_error([&] { rs::Mesh::from_triangles(g.V.data(), 0, g.F.data(), g.nf()); }, {"no vertices"});
  expect_error([&] { rs::Mesh::from_triangles(g.V.data(), g.nv(), g.F.data(), 0); }, {"no faces"});
  expect_error([&] { rs::Mesh::from_polygons({}, {}, {}); }, {"no vertices"});

  Grid bad = g;
  bad.F[3 * 5 + 1] = 9;
  expect_error([&] { build(bad); }, {"face 5", "vertex 9", "0-based"});
  bad = g;
  bad.F[3 * 2] = -1;
  expect_error([&] { build(bad); }, {"face 2", "vertex -1"});

  bad = g;
  bad.V[3 * 4 + 1] = std::numeric_limits<double>::quiet_NaN();
  expect_error([&] { build(bad); }, {"vertex 4", "non-finite"});
  bad = g;
  bad.V[3 * 7 + 2] = -std::numeric_limits<double>::infinity();
  expect_error([&] { build(bad); }, {"vertex 7", "non-finite"});

  // Nothing survives: every face degenerate.
  const std::vector<double> V = {0, 0, 0, 1, 0, 0, 2, 0, 0};
  const std::vector<std::int64_t> F = {0, 1, 2, 0, 0, 1};
  expect_error([&] { rs::Mesh::from_triangles(V.data(), 3, F.data(), 2); }, {"no usable face", "2 degenerate faces"});
}

TEST(MeshIntake, MeasureDistance) {
  Grid g = make_grid(3, 3, 2.0);
  g.V.insert(g.V.end(), {5.0, 5.0, 5.0});  // unreferenced vertex 9
  const rs::Mesh m = build(g);
  EXPECT_NEAR(rs::measure_distance(m, 0, 8), 4 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(rs::measure_distance(m, 3, 3), 0.0, 0.0);
  expect_error([&] { rs::measure_distance(m, 0, 10); }, {"10", "out of range"});
  expect_error([&] { rs::measure_distance(m, -1, 2); }, {"-1", "out of range"});
  expect_error([&] { rs::measure_distance(m, 9, 2); }, {"vertex 9", "no face"});
}

// --- files ---------------------------------------------------------------------

TEST(MeshFiles, ObjWithQuadCommentsAndUnusedVertex) {
  TempDir dir;
  const std::string path = dir.write("quad.obj",
                                     "# two quads and an unused vertex\n"
                                     "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\n"
                                     "v 9 9 9\n"
                                     "vn 0 0 1\nvt 0 0\n"
                                     "f 1 2 5 4\n"
                                     "f 2/1 3/1 6/1 5/1\n");
  const rs::Mesh m = rs::Mesh::load(path);
  EXPECT_EQ(m.input_vertex_count(), 7u);
  EXPECT_EQ(m.n_vertices(), 6);
  EXPECT_EQ(m.n_faces(), 4);
  EXPECT_EQ(m.report().polygons_triangulated, 2u);
  EXPECT_EQ(m.report().unreferenced_vertices, 1u);
  EXPECT_EQ(m.input_to_mesh(6), -1);
  EXPECT_EQ(m.position(m.input_to_mesh(5)), rs::Vec3(2, 1, 0));
  EXPECT_NEAR(rs::measure_distance(m, 0, 5), std::sqrt(5.0), 1e-6);
  for (int v = 0; v < m.n_vertices(); ++v) EXPECT_GT(m.vertex_normal(v).z(), 0.99);
}

TEST(MeshFiles, PlyAsciiAndBinary) {
  TempDir dir;
  const std::string ascii = dir.write("square.ply",
                                      "ply\nformat ascii 1.0\nelement vertex 4\n"
                                      "property float x\nproperty float y\nproperty float z\n"
                                      "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
                                      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
  const rs::Mesh a = rs::Mesh::load(ascii);
  EXPECT_EQ(a.n_vertices(), 4);
  EXPECT_EQ(a.n_faces(), 2);
  EXPECT_EQ(a.report().boundary_edges, 4u);

  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 5\n"
      "property float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const float pts[5][3] = {{0, 0, 0}, {2, 0, 0}, {3, 1, 0}, {1, 2, 0}, {-1, 1, 0}};
  for (const auto& p : pts)
    for (float x : p) put(bin, x);
  put(bin, static_cast<unsigned char>(5));
  for (int i = 0; i < 5; ++i) put(bin, static_cast<std::int32_t>(i));
  const rs::Mesh b = rs::Mesh::load(dir.write("pentagon_binary.ply", bin));
  EXPECT_EQ(b.n_vertices(), 5);
  EXPECT_EQ(b.n_faces(), 3);
  EXPECT_EQ(b.report().polygons_triangulated, 1u);
  EXPECT_EQ(b.position(b.input_to_mesh(3)), rs::Vec3(1, 2, 0));
}

TEST(MeshFiles, StlAsciiAndBinarySoupsConnect) {
  TempDir dir;
  const std::string ascii = dir.write("square.stl",
                                      "solid square\n"
                                      " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
                                      "   vertex 1 1 0\n  endloop\n endfacet\n"
                                      " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 1 0\n"
                                      "   vertex 0 1 0\n  endloop\n endfacet\n"
                                      "endsolid square\n");
  const rs::Mesh a = rs::Mesh::load(ascii);
  EXPECT_EQ(a.n_vertices(), 4);
  EXPECT_EQ(a.n_faces(), 2);
  EXPECT_EQ(a.report().components, 1u);
  EXPECT_EQ(a.report().boundary_edges, 4u);

  std::string bin(80, ' ');
  put(bin, static_cast<std::uint32_t>(2));
  const float tris[2][3][3] = {{{0, 0, 0}, {2, 0, 0}, {2, 2, 0}}, {{0, 0, 0}, {2, 2, 0}, {0, 2, 0}}};
  for (const auto& t : tris) {
    for (float n : {0.0f, 0.0f, 1.0f}) put(bin, n);
    for (const auto& p : t)
      for (float x : p) put(bin, x);
    put(bin, static_cast<std::uint16_t>(0));
  }
  const rs::Mesh b = rs::Mesh::load(dir.write("square_binary.stl", bin));
  EXPECT_EQ(b.n_vertices(), 4);
  EXPECT_EQ(b.n_faces(), 2);
  EXPECT_EQ(b.report().components, 1u);
  expect_consistent_neighbors(b);
  for (int f = 0; f < 2; ++f) EXPECT_NEAR(b.face_normal(f).z(), 1.0, 1e-12);
}

TEST(MeshFiles, OffWithQuad) {
  TempDir dir;
  const std::string path = dir.write("quad.off", "OFF\n# a unit quad\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
  const rs::Mesh m = rs::Mesh::load(path);
  EXPECT_EQ(m.n_vertices(), 4);
  EXPECT_EQ(m.n_faces(), 2);
  EXPECT_EQ(m.report().polygons_triangulated, 1u);
  EXPECT_EQ(m.report().input_faces, 1u);
}

TEST(MeshFiles, BinaryOff) {
  TempDir dir;
  std::string bin = "OFF BINARY\n";
  for (std::int32_t n : {4, 1, 0}) put(bin, n);
  for (float x : {0.f, 0.f, 0.f, 3.f, 0.f, 0.f, 3.f, 3.f, 0.f, 0.f, 3.f, 0.f}) put(bin, x);
  for (std::int32_t n : {4, 0, 1, 2, 3, 0}) put(bin, n);  // quad, then zero colour components
  const rs::Mesh m = rs::Mesh::load(dir.write("quad_binary.off", bin));
  EXPECT_EQ(m.n_faces(), 2);
  EXPECT_NEAR(m.face_area(0) + m.face_area(1), 9.0, 1e-12);
}

TEST(MeshFiles, UpperCaseExtensionLoads) {
  TempDir dir;
  const std::string path = dir.write("TRI.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(rs::Mesh::load(path).n_faces(), 1);
}

TEST(MeshFiles, LoadErrors) {
  TempDir dir;
  expect_error([&] { rs::Mesh::load(dir.file("missing.obj")); }, {"missing.obj", "cannot open"});
  const std::string xyz = dir.write("points.xyz", "0 0 0\n");
  expect_error([&] { rs::Mesh::load(xyz); }, {"points.xyz", "OBJ, PLY, STL or OFF"});
  const std::string noext = dir.write("mesh", "v 0 0 0\n");
  expect_error([&] { rs::Mesh::load(noext); }, {"OBJ, PLY, STL or OFF"});
  const std::string points_only = dir.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  expect_error([&] { rs::Mesh::load(points_only); }, {"points.obj", "no faces"});
  const std::string garbage = dir.write("garbage.ply", "this is not a ply file\n");
  expect_error([&] { rs::Mesh::load(garbage); }, {"garbage.ply"});
  // Headers that announce more than the file holds must fail fast, not allocate or spin.
  const std::string short_off = dir.write("short.off", "OFF\n300000000 1 0\n0 0 0\n");
  expect_error([&] { rs::Mesh::load(short_off); }, {"short.off", "more than the file holds"});
  const std::string no_counts = dir.write("nocounts.off", "OFF\n");
  expect_error([&] { rs::Mesh::load(no_counts); }, {"nocounts.off", "counts"});
  const std::string short_binary_off = dir.write("short_binary.off", "OFF BINARY\n");
  expect_error([&] { rs::Mesh::load(short_binary_off); }, {"short_binary.off", "counts"});
  const std::string short_ply = dir.write("short.ply",
                                          "ply\nformat binary_little_endian 1.0\nelement vertex 300000000\n"
                                          "property float x\nproperty float y\nproperty float z\nend_header\n");
  expect_error([&] { rs::Mesh::load(short_ply); }, {"short.ply", "more elements than the file holds"});
  const std::string bad_index = dir.write("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  expect_error([&] { rs::Mesh::load(bad_index); }, {"bad.off"});
}

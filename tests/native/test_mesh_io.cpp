// Mesh file IO and intake on hostile input (issue 11): header grammar, counts against the
// bytes, per-face counts, truncation, NaN/inf/too-large coordinates, bad indices, partial
// loads, double precision, and the formats' valid corners (ushort list counts, big-endian).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "relief_snake/error.hpp"
#include "relief_snake/mesh.hpp"
#include "relief_snake/mesh_io.hpp"

namespace rs = relief_snake;

namespace {

rs::PolygonSoup read(const std::string& bytes, rs::MeshFormat format, bool partial = false) {
  rs::ReadOptions options;
  options.allow_partial = partial;
  return rs::read_mesh_bytes(bytes.data(), bytes.size(), format, options);
}

rs::Mesh load(const std::string& bytes, rs::MeshFormat format, bool partial = false) {
  rs::IntakeOptions intake;
  intake.allow_partial = partial;
  return rs::Mesh::from_soup(read(bytes, format, partial), intake);
}

/// Expects an rs::Error, one line, containing every one of `parts`.
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

template <class T>
void put(std::string& out, T value, bool big_endian = false) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (big_endian) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

std::string ply_header(const std::string& format, int nv, int nf, const std::string& coord = "float",
                       const std::string& list = "list uchar int vertex_indices") {
  return "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(nv) + "\nproperty " + coord +
         " x\nproperty " + coord + " y\nproperty " + coord + " z\nelement face " + std::to_string(nf) +
         "\nproperty " + list + "\nend_header\n";
}

const std::string kSquareV = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n";
const std::string kSquareF = "3 0 1 2\n3 0 2 3\n";
const auto PLY = rs::MeshFormat::Ply;
const auto OFF = rs::MeshFormat::Off;
const auto OBJ = rs::MeshFormat::Obj;
const auto STL = rs::MeshFormat::Stl;

}  // namespace

// --- the crashes, hangs and runaway allocations of issue 11 ------------------------------

TEST(MeshIO, PlyHeaderGrammarIsCheckedFirst) {
  // Used to segfault inside OpenMesh.
  expect_error([] { read("ply\nformat ascii 1.0\nproperty float x\nelement vertex 1\nend_header\n0\n", PLY); },
               {"line 3", "property comes before any element"});
  // Used to spin forever.
  expect_error([] {
    read("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
         "element face 1\nproperty list uchar int\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", PLY);
  }, {"line 8", "list property needs", "name"});
  expect_error([] { read("ply\nformat ascii 1.0\nelement vertex 3\n", PLY); }, {"end_header"});
  expect_error([] { read("ply\nformat ascii 2.0\nend_header\n", PLY); }, {"line 2", "version"});
  expect_error([] { read("ply\nelement vertex 3\nend_header\n", PLY); }, {"line 2", "before the format"});
  expect_error([] { read(ply_header("ascii", 4, 2, "float128") + kSquareV + kSquareF, PLY); },
               {"line 4", "unknown property type 'float128'"});
  expect_error([] { read(ply_header("ascii", 4, 2, "float", "list float int vertex_indices") + kSquareV, PLY); },
               {"count type", "not an integer"});
  expect_error([] { read("ply\nformat ascii 1.0\nelement thing 1000000000000\nend_header\n", PLY); },
               {"no properties"});
  expect_error([] { read("not a ply\n", PLY); }, {"start with the line 'ply'"});
}

TEST(MeshIO, CountsAreCheckedAgainstTheBytes) {
  expect_error([] { read(ply_header("binary_little_endian", 300000000, 0), PLY); },
               {"more elements than the file holds"});
  expect_error([] {
    read("ply\nformat ascii 1.0\nelement vertex 4611686018427387904\nproperty float x\nproperty float y\n"
         "property float z\nend_header\n", PLY);
  },
               {"more elements than the file holds", "over 2^64"});
  expect_error([] { read("OFF\n300000000 1 0\n0 0 0\n", OFF); }, {"more than the file holds"});
  std::string stl(80, ' ');
  put(stl, std::uint32_t(0xFFFFFFFFu));
  expect_error([&] { read(stl, STL); }, {"4294967295 triangles", "84 bytes"});
  // Partial loads never reserve what the header claims: they keep what is there.
  const rs::PolygonSoup soup = read(stl, STL, true);
  EXPECT_EQ(soup.n_faces(), 0u);
  EXPECT_EQ(soup.notes.size(), 1u);
}

TEST(MeshIO, PerFaceCountsAreBounded) {
  // A face list count larger than the bytes left, negative, or 2^31: refused at once.
  std::string bin = ply_header("binary_little_endian", 3, 1, "float", "list int int vertex_indices");
  for (int i = 0; i < 9; ++i) put(bin, 0.5f * float(i % 3 == i / 3));
  std::string huge = bin, negative = bin;
  put(huge, std::int32_t(1) << 30);
  put(negative, std::int32_t(-3));
  for (int i = 0; i < 3; ++i) {
    put(huge, std::int32_t(i));
    put(negative, std::int32_t(i));
  }
  expect_error([&] { read(huge, PLY); }, {"face 0", "1073741824 items", "more than the file holds"});
  expect_error([&] { read(negative, PLY); }, {"face 0", "-3 items", "negative"});
  expect_error([] { read("OFF\n4 1 0\n" + kSquareV + "-3 0 1 2\n", OFF); }, {"line 7", "-3 corners"});
  expect_error([] { read("OFF\n4 1 0\n" + kSquareV + "2147483647 0 1 2\n", OFF); },
               {"line 7", "2147483647 corners", "lists 3"});
}

// --- silent acceptance of bad data -------------------------------------------------------

TEST(MeshIO, NonFiniteCoordinatesNameTheVertexAndLine) {
  expect_error([] { load(ply_header("ascii", 4, 2) + "0 0 0\nnan 0 0\n1 1 0\n0 1 0\n" + kSquareF, PLY); },
               {"vertex 1 (line 11)", "non-finite"});
  expect_error([] { load("OFF\n4 2 0\n0 0 0\n1 0 0\n1 nan 0\n0 1 0\n" + kSquareF, OFF); },
               {"vertex 2 (line 5)", "non-finite"});
  expect_error([] { load("v 0 0 0\nv 1 0 0\nv inf 1 0\nf 1 2 3\n", OBJ); }, {"vertex 2 (line 3)", "non-finite"});
  std::string stl(80, ' ');
  put(stl, std::uint32_t(1));
  for (float x : {0.f, 0.f, 1.f, 0.f, 0.f, 0.f, NAN, 0.f, 0.f, 0.f, 1.f, 0.f}) put(stl, x);
  put(stl, std::uint16_t(0));
  expect_error([&] { load(stl, STL); }, {"vertex 1", "non-finite"});
  // 1e300 is finite: it is refused for what it is (too large to square), not called non-finite.
  expect_error([] { load("v 0 0 0\nv 1e300 0 0\nv 0 1 0\nf 1 2 3\n", OBJ); },
               {"vertex 1 (line 2)", "too large", "1e150"});
  expect_error([] { load("v 0 0 0\nv 1e400 0 0\nv 0 1 0\nf 1 2 3\n", OBJ); }, {"line 2", "outside the range of a double"});
}

TEST(MeshIO, TruncatedAndMiscountedFilesAreErrorsUnlessPartial) {
  const std::string ply = ply_header("ascii", 4, 2) + kSquareV + "3 0 1 2\n3 0";
  expect_error([&] { read(ply, PLY); }, {"line 15", "face 1", "fewer values"});
  const rs::Mesh m = load(ply, PLY, true);
  EXPECT_EQ(m.n_faces(), 1);
  ASSERT_EQ(m.report().notes.size(), 1u);
  EXPECT_NE(m.report().summary().find("partial load: line 15"), std::string::npos) << m.report().summary();
  EXPECT_TRUE(m.report().partial());

  // A vertex count that is too large reads a face line as a vertex: caught by the value count.
  expect_error([] { read(ply_header("ascii", 5, 2) + kSquareV + kSquareF, PLY); },
               {"line 14", "vertex 4 has more values", "count match"});
  expect_error([] { read(ply_header("ascii", 3, 2) + kSquareV + kSquareF, PLY); }, {"line 13", "face 0"});
  expect_error([] { read(ply_header("ascii", 4, 1) + kSquareV + kSquareF, PLY); }, {"data after the last element"});
  expect_error([] { read("OFF\n4 2 0\n" + kSquareV + "3 0 1 2\n", OFF); }, {"ends after 1 of 2 faces"});
  expect_error([] { read("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2", OBJ); }, {"line 4", "at least 3 corners"});
  expect_error([] { read("v 0 0 0\nv 1 0 0\nv 1 1", OBJ); }, {"line 3", "x, y and z"});
  expect_error([] { read("solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n", STL); }, {"endsolid"});

  std::string bin = ply_header("binary_little_endian", 4, 2);
  for (float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 1.f, 1.f, 0.f, 0.f, 1.f, 0.f}) put(bin, x);
  for (int f = 0; f < 2; ++f) {
    put(bin, std::uint8_t(3));
    for (int i : {0, 1 + f, 2 + f}) put(bin, std::int32_t(i));
  }
  EXPECT_EQ(load(bin, PLY).n_faces(), 2);
  const std::string cut = bin.substr(0, bin.size() - 5);
  expect_error([&] { read(cut, PLY); }, {"face 1", "3 items, more than the file holds"});
  EXPECT_EQ(load(cut, PLY, true).n_faces(), 1);
  expect_error([&] { read(bin + "junk", PLY); }, {"4 bytes after the last element"});
}

TEST(MeshIO, BadIndicesAreRefusedAlikeInEveryFormatAndCountedWhenPartial) {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 9\nf 1 3 4\n";
  expect_error([&] { load(obj, OBJ); }, {"face 0 (line 5)", "vertex 9", "OBJ indices count from 1"});
  expect_error([] { load("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 x\n", OBJ); }, {"line 4", "'x'"});
  expect_error([] { load("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 0 1 2\n", OBJ); }, {"line 4", "start at 1"});
  expect_error([] { load(ply_header("ascii", 4, 2) + kSquareV + "3 0 1 9\n3 0 2 3\n", PLY); },
               {"face 0 (line 14)", "vertex 9", "0-based"});
  expect_error([] { load("OFF\n4 2 0\n" + kSquareV + "3 0 1 2\n3 0 -2 3\n", OFF); }, {"face 1 (line 8)", "vertex -2"});
  const rs::Mesh m = load(obj, OBJ, true);
  EXPECT_EQ(m.report().invalid_faces, 1u);
  EXPECT_EQ(m.n_faces(), 1);
  EXPECT_NE(m.report().summary().find("1 invalid face skipped"), std::string::npos);
  // Every input face accounted for, the invalid one included.
  const rs::MeshReport& r = m.report();
  EXPECT_EQ(r.input_faces, r.triangles + r.degenerate_faces + r.nonmanifold_faces + r.invalid_faces);
  // Relative (negative) OBJ indices count back from the last vertex defined.
  EXPECT_EQ(load("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n", OBJ).n_faces(), 1);
}

TEST(MeshIO, PartialNonFiniteVertexSkipsOnlyItsFaces) {
  const std::string ply = ply_header("ascii", 5, 3) + "0 0 0\n1 0 0\n1 1 0\n0 1 0\nnan 5 5\n" +
                          "3 0 1 2\n3 0 2 3\n3 2 3 4\n";
  const rs::Mesh m = load(ply, PLY, true);
  EXPECT_EQ(m.n_faces(), 2);
  EXPECT_EQ(m.report().invalid_vertices, 1u);
  EXPECT_EQ(m.report().invalid_faces, 1u);
  EXPECT_EQ(m.input_to_mesh(4), -1);
}

// --- valid files -------------------------------------------------------------------------

TEST(MeshIO, ValidCornersOfTheFormatsLoad) {
  // ushort face-list counts (refused before), comments, CRLF line ends, extra properties.
  EXPECT_EQ(load(ply_header("ascii", 4, 2, "float", "list ushort int vertex_indices") + kSquareV + kSquareF, PLY).n_faces(), 2);
  std::string crlf = "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nelement vertex 3\r\nproperty float x\r\n"
                     "property float y\r\nproperty float z\r\nproperty uchar red\r\nelement face 1\r\n"
                     "property list uint8 uint32 vertex_index\r\nend_header\r\n0 0 0 255\r\n1 0 0 0\r\n0 1 0 9\r\n3 0 1 2\r\n";
  EXPECT_EQ(load(crlf, PLY).n_faces(), 1);
  // Big-endian binary with double coordinates and a ushort count.
  std::string be = ply_header("binary_big_endian", 3, 1, "double", "list ushort uint vertex_indices");
  for (double x : {0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0, 0.0}) put(be, x, true);
  put(be, std::uint16_t(3), true);
  for (std::uint32_t i : {0u, 1u, 2u}) put(be, i, true);
  const rs::Mesh m = load(be, PLY);
  EXPECT_EQ(m.n_faces(), 1);
  EXPECT_NEAR(m.face_area(0), 2.0, 1e-15);
  // OFF variants: keyword and counts on one line, colours after the corners, COFF colours per vertex.
  EXPECT_EQ(load("OFF 4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 255 0 0\n", OFF).n_faces(), 2);
  EXPECT_EQ(load("COFF\n3 1 0\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n0 1 0 1 1 1 1\n3 0 1 2\n", OFF).n_faces(), 1);
  // ASCII STL with two solids; a binary STL whose header starts with "solid".
  EXPECT_EQ(load("solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
                 "endfacet\nendsolid a\nsolid b\nfacet normal 0 0 1\nouter loop\nvertex 5 0 0\nvertex 6 0 0\n"
                 "vertex 5 1 0\nendloop\nendfacet\nendsolid b\n", STL).n_faces(), 2);
  std::string stl = "solid but binary";
  stl.resize(80, ' ');
  put(stl, std::uint32_t(1));
  for (float x : {0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put(stl, x);
  put(stl, std::uint16_t(0));
  EXPECT_EQ(load(stl, STL).n_faces(), 1);
}

TEST(MeshIO, DoublesStayDoubleAtGeoreferencedOffsets) {
  // 1e6 + 0.001 steps are lost in float32 (spacing 0.0625 there): every vertex must stay distinct.
  const double x0 = 1e6;
  std::string ply = ply_header("ascii", 4, 2, "double");
  char line[128];
  for (int i = 0; i < 4; ++i) {
    std::snprintf(line, sizeof line, "%.17g %.17g %.17g\n", x0 + 0.001 * (i % 2), x0 + 0.001 * (i / 2), 0.0);
    ply += line;
  }
  ply += "3 0 1 3\n3 0 3 2\n";
  const rs::Mesh m = load(ply, PLY);
  EXPECT_EQ(m.n_vertices(), 4) << m.report().summary();
  EXPECT_EQ(m.report().duplicate_vertices_merged, 0u);
  // Positions are relative to the local origin (here the box centre, 1e6 + 0.0005 on x and y); in the
  // file's coordinates the double comes back bit for bit.
  EXPECT_EQ(m.to_file(m.position(m.input_to_mesh(3))).x(), x0 + 0.001);
  EXPECT_EQ(m.origin().z(), 0.0);
  EXPECT_NEAR(m.average_edge_length(), (4 * 0.001 + 0.001 * std::sqrt(2.0)) / 5, 1e-9);
  const rs::Mesh o = load("v 1000000 1000000 0\nv 1000000.001 1000000 0\nv 1000000 1000000.001 0\nf 1 2 3\n", OBJ);
  EXPECT_EQ(o.n_vertices(), 3);
  EXPECT_NEAR(o.face_area(0), 0.5e-6, 1e-12);
}

TEST(MeshIO, FormatFromPath) {
  EXPECT_EQ(rs::format_from_path("a/b.PLY"), PLY);
  EXPECT_EQ(rs::format_from_path("x.obj"), OBJ);
  expect_error([] { rs::format_from_path("dir.ply/mesh"); }, {"unsupported file type"});
  expect_error([] { rs::read_mesh_file("/nonexistent/mesh.ply"); }, {"cannot open"});
  expect_error([] { rs::read_mesh_file("/"); }, {"unsupported"});
  expect_error([] { read("", OBJ); }, {"empty"});
}

// The fuzzed entry points (fuzz_entries.hpp).
#include "fuzz_entries.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "relief_snake/error.hpp"
#include "relief_snake/mesh.hpp"
#include "relief_snake/mesh_io.hpp"
#include "relief_snake/segment.hpp"

namespace relief_snake::fuzz {

void mesh_intake(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return;
  static const MeshFormat formats[4] = {MeshFormat::Obj, MeshFormat::Ply, MeshFormat::Off, MeshFormat::Stl};
  const MeshFormat format = formats[data[0] & 3];
  ReadOptions read;
  read.allow_partial = (data[0] & 4) != 0;
  IntakeOptions intake;
  intake.allow_partial = read.allow_partial;
  try {
    const PolygonSoup soup = read_mesh_bytes(reinterpret_cast<const char*>(data + 1), size - 1, format, read);
    const Mesh mesh = Mesh::from_soup(soup, intake);
    // Touch what the engine reads, so a bad array shows up here and not later.
    double sum = mesh.average_edge_length();
    for (int v = 0; v < mesh.n_vertices(); ++v) sum += mesh.vertex_area(v) + mesh.vertex_normal(v).x();
    for (int f = 0; f < mesh.n_faces(); ++f)
      for (int k = 0; k < 3; ++k) sum += mesh.face_neighbor(f, k) + mesh.face_vertex(f, k);
    (void)mesh.report().summary();
    volatile double sink = sum;
    (void)sink;
  } catch (const Error&) {
    // A refusal with a message: the expected outcome for bad bytes.
  }
}

namespace {

/// Reads the bytes in order; past the end it yields zeros.
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t byte() { return i_ < size_ ? data_[i_++] : 0; }
  std::uint16_t u16() { return static_cast<std::uint16_t>(byte() | byte() << 8); }

 private:
  const std::uint8_t* data_;
  std::size_t size_, i_ = 0;
};

}  // namespace

namespace {

/// A height field of nx by ny unit cells (two triangles each), z from `height(i, j)`.
template <class Height>
Mesh height_field(int nx, int ny, Height height) {
  std::vector<double> V;
  std::vector<std::int64_t> F;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) V.insert(V.end(), {double(i), double(j), height(i, j)});
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const std::int64_t a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      F.insert(F.end(), {a, b, d, a, d, c});
    }
  return Mesh::from_triangles(V.data(), V.size() / 3, F.data(), F.size() / 3);
}

/// The fixed meshes, built once (intake is not what this target fuzzes: fuzz_mesh_intake does
/// that): 10 x 10 vertices each (a relief and a ring of picks around it fit; every vertex more
/// costs time in each profile of the self-check), a relief of height 1 or none.
const std::vector<Mesh>& fixed_meshes() {
  static const std::vector<Mesh> meshes = [] {
    std::vector<Mesh> out;
    const auto r = [](int i, int j) { return std::hypot(i - 4.5, j - 4.5); };
    out.push_back(height_field(10, 10, [&](int i, int j) { return r(i, j) < 2.6 ? 1.0 : 0.0; }));  // sharp disk
    out.push_back(height_field(10, 10, [&](int i, int j) {  // blended disk
      return std::clamp(3.2 - r(i, j), 0.0, 1.0);
    }));
    out.push_back(height_field(10, 10, [&](int i, int j) {  // ring: a disk with a hole
      return r(i, j) < 3.6 && r(i, j) > 1.4 ? 1.0 : 0.0;
    }));
    out.push_back(height_field(10, 10, [](int i, int) { return i >= 6 ? 1.0 : 0.0; }));  // a step to the boundary
    out.push_back(height_field(10, 10, [&](int i, int j) {  // a disk on a tilted, wavy background
      return 0.1 * i + 0.15 * std::sin(1.7 * j) + (r(i, j) < 2.6 ? 1.0 : 0.0);
    }));
    out.push_back(height_field(10, 10, [](int i, int j) { return 0.01 * ((i * 7 + j * 3) % 5); }));  // flat
    return out;
  }();
  return meshes;
}

}  // namespace

void segment_small(const std::uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  // Byte 0: one of the fixed meshes (6 in 8), or a small height field whose heights are the
  // next bytes (3..8 by 3..8 vertices).
  const std::uint8_t which = in.byte() % 8;
  std::unique_ptr<Mesh> own;
  const Mesh* mesh = nullptr;
  try {
    if (which < fixed_meshes().size()) {
      mesh = &fixed_meshes()[which];
    } else {
      const int nx = 3 + in.byte() % 6, ny = 3 + in.byte() % 6;
      std::vector<std::uint8_t> heights(static_cast<std::size_t>(nx * ny));
      for (std::uint8_t& z : heights) z = in.byte();
      own = std::make_unique<Mesh>(height_field(nx, ny, [&](int i, int j) { return (heights[j * nx + i] % 16) * 0.125; }));
      mesh = own.get();
    }
  } catch (const Error&) {
    return;  // a height field that is all degenerate: intake refuses it
  }
  const int n = static_cast<int>(mesh->input_vertex_count());
  auto read_picks = [&](int count) {
    std::vector<std::int64_t> picks;
    for (int k = 0; k < count; ++k) picks.push_back(static_cast<std::int64_t>(in.u16() % (n + 2)) - 1);
    return picks;
  };
  const std::vector<std::int64_t> picks = read_picks(2 + in.byte() % 6);
  Options options;
  const std::uint8_t flags = in.byte(), more = in.byte();
  options.closed = (flags & 1) == 0;
  options.relief_side = (flags & 6) == 2 ? ReliefSide::Right : (flags & 6) == 4 ? ReliefSide::Auto : ReliefSide::Left;
  options.foot_snap = (flags & 8) != 0;
  options.holes = (flags & 16) ? HoleMode::Off : HoleMode::Auto;
  options.refit_step_height = (flags & 32) == 0;
  options.threads = 1;
  options.neighbourhood = (more & 3) == 1 ? Neighbourhood::Geodesic : (more & 3) == 2 ? Neighbourhood::Euclidean
                                                                                         : Neighbourhood::Sphere;
  options.plane_fit = (more & 12) == 4 ? PlaneFit::Vertices : (more & 12) == 8 ? PlaneFit::Area : PlaneFit::VertexAreas;
  options.refine_levels = (more >> 4) % 4;  // 0 (auto), 1 (the paper's), 2, 3
  options.exact_q = (more & 64) != 0;
  options.convex_barrier = (more & 128) != 0;
  // Step heights from 0.05 to ~60 edges (the engine refuses those below a tenth of an edge or above
  // the mesh's size), the odd bad value it must refuse, and auto (flags bit 6).
  const std::uint8_t h = in.byte();
  options.step_height = (flags & 64) ? kAuto : h == 255 ? std::nan("") : h == 254 ? -1.0 : 0.05 * std::pow(1.03, h);
  // W_int auto (up to three refinements) in 1 of 16 inputs: each refinement is the bulk of the time.
  const std::uint8_t w = in.byte();
  options.w_int = w < 16 ? kAuto : (1 + w) / 256.0;
  // A few iterations per phase: the phases, their hand-overs and the self-check run on every
  // input, and a long evolution on a 10 x 10 mesh adds time, not paths.
  options.max_iterations = 1 + in.byte() % 5;
  // Cancel after this many progress calls (0: let it run, up to a cap), to reach the cancel paths.
  const int cancel_at = in.byte() % 48;
  // Bit 7 of the flags and then 1 in 4: a band (a second ring; two snakes), or hole picks.
  const std::uint8_t extras = in.byte();
  if ((flags & 128) && extras % 4 == 0) options.band_picks = read_picks(3 + in.byte() % 4);
  if ((flags & 128) && extras % 4 == 1) options.hole_picks = {read_picks(3 + in.byte() % 3)};
  try {
    int calls = 0;
    const int limit = cancel_at > 0 ? cancel_at : 60;
    (void)segment(*mesh, picks, options, [&](const Progress& p) {
      if (calls % 16 == 0) (void)p.contour();  // the snake's polyline, as front ends draw it
      return ++calls < limit;
    });
  } catch (const Error&) {
    // Refused picks or parameters: expected.
  }
}

}  // namespace relief_snake::fuzz

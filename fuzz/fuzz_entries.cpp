// The fuzzed entry points (fuzz_entries.hpp).
#include "fuzz_entries.hpp"

#include <cmath>
#include <cstring>
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

void segment_small(const std::uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  const int nx = 3 + in.byte() % 10, ny = 3 + in.byte() % 10;
  std::vector<double> V;
  std::vector<std::int64_t> F;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) V.insert(V.end(), {double(i), double(j), (in.byte() % 16) * 0.125});
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const std::int64_t a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      F.insert(F.end(), {a, b, d, a, d, c});
    }
  const int n_picks = 2 + in.byte() % 5;
  std::vector<std::int64_t> picks;
  for (int k = 0; k < n_picks; ++k) picks.push_back(static_cast<std::int64_t>(in.u16() % (nx * ny + 2)) - 1);
  Options options;
  const std::uint8_t flags = in.byte();
  options.closed = (flags & 1) == 0;
  options.relief_side = (flags & 2) ? ReliefSide::Right : ReliefSide::Left;
  options.foot_snap = (flags & 4) != 0;
  options.threads = 1;
  // Step heights from 0.05 to ~60 edges, and the odd bad value the engine must refuse. (Below
  // 0.05 edges the snake has length / h snaxels and one input costs seconds under ASan: the
  // fuzzer would only time out; tiny h is reported in the issue instead.)
  const std::uint8_t h = in.byte();
  options.step_height = h == 255 ? std::nan("") : h == 254 ? -1.0 : 0.05 * std::pow(1.03, h);
  options.w_int = (1 + in.byte()) / 256.0;
  options.max_iterations = 1 + in.byte() % 40;
  try {
    const Mesh mesh = Mesh::from_triangles(V.data(), V.size() / 3, F.data(), F.size() / 3);
    int calls = 0;
    (void)segment(mesh, picks, options, [&calls](const Progress&) { return ++calls < 400; });
  } catch (const Error&) {
    // Refused picks or parameters: expected.
  }
}

}  // namespace relief_snake::fuzz

// Mesh intake: validation, vertex merging, triangulation, OpenMesh construction
// and the flat adjacency arrays the snake reads in its inner loops.
//
// MeshIO.hh must come before any mesh kernel header in this translation unit: it
// registers OpenMesh's readers.
#if defined(__GNUC__) && !defined(__clang__)
// OpenMesh's property templates trip GCC's -Wmaybe-uninitialized at instantiation; not our code.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <OpenMesh/Core/IO/MeshIO.hh>

#include "relief_snake/mesh.hpp"

#include <OpenMesh/Core/IO/importer/ImporterT.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <numeric>
#include <sstream>

#include "relief_snake/error.hpp"

namespace relief_snake {

namespace {

const char* kSupportedFormats = "OBJ, PLY, STL or OFF";

/// Silences one OpenMesh stream for a scope (restores its previous state).
class StreamSilencer {
 public:
  explicit StreamSilencer(OpenMesh::mostream& stream) : stream_(stream), was_enabled_(stream.is_enabled()) {
    stream_.disable();
  }
  ~StreamSilencer() {
    if (was_enabled_) stream_.enable();
  }
  StreamSilencer(const StreamSilencer&) = delete;
  StreamSilencer& operator=(const StreamSilencer&) = delete;

 private:
  OpenMesh::mostream& stream_;
  bool was_enabled_;
};

/// Open-addressing hash table mapping exact coordinates to the first input vertex
/// that has them. Flat storage: one int per slot, no per-vertex allocation.
class CoordinateMerger {
 public:
  CoordinateMerger(const double* V, std::size_t nv) : V_(V) {
    std::size_t capacity = 16;
    while (capacity < 2 * nv) capacity <<= 1;
    slots_.assign(capacity, -1);
    mask_ = capacity - 1;
  }
  /// Index of the first vertex inserted with exactly v's coordinates (v itself if new).
  std::int64_t insert(std::int64_t v) {
    const double* p = V_ + 3 * v;
    std::size_t h = hash(p) & mask_;
    while (true) {
      const std::int64_t s = slots_[h];
      if (s < 0) {
        slots_[h] = v;
        return v;
      }
      const double* q = V_ + 3 * s;
      if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) return s;
      h = (h + 1) & mask_;
    }
  }

 private:
  static std::uint64_t bits(double x) {
    x += 0.0;  // -0.0 and 0.0 compare equal, so they must hash equal
    std::uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
  }
  static std::size_t hash(const double* p) {
    std::uint64_t h = bits(p[0]) * 0x9E3779B97F4A7C15ULL;
    h ^= bits(p[1]) + 0x7F4A7C159E3779B9ULL + (h << 6) + (h >> 2);
    h ^= bits(p[2]) + 0x94D049BB133111EBULL + (h << 6) + (h >> 2);
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ULL;
    h ^= h >> 29;
    return static_cast<std::size_t>(h);
  }
  const double* V_;
  std::vector<std::int64_t> slots_;
  std::size_t mask_ = 0;
};

/// Twice the area of triangle (a, b, c), and whether it is too thin to have a normal.
bool zero_area(const double* a, const double* b, const double* c) {
  const Vec3 pa(a[0], a[1], a[2]), pb(b[0], b[1], b[2]), pc(c[0], c[1], c[2]);
  const Vec3 e1 = pb - pa, e2 = pc - pa, e3 = pc - pb;
  const double longest2 = std::max({e1.squaredNorm(), e2.squaredNorm(), e3.squaredNorm()});
  // Relative test: exactly or numerically collinear corners give no usable normal.
  return e1.cross(e2).norm() <= 1e-12 * longest2;
}

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

}  // namespace

// ---------------------------------------------------------------------------
// Report
// ---------------------------------------------------------------------------

std::string MeshReport::summary() const {
  std::ostringstream s;
  s << plural(triangles, "triangle", "triangles") << ", " << plural(components, "component", "components") << ", "
    << plural(boundary_edges, "boundary edge", "boundary edges");
  std::vector<std::string> parts;
  if (duplicate_vertices_merged) parts.push_back(plural(duplicate_vertices_merged, "duplicate vertex", "duplicate vertices") + " merged");
  if (polygons_triangulated) parts.push_back(plural(polygons_triangulated, "polygon", "polygons") + " triangulated");
  if (degenerate_faces) parts.push_back(plural(degenerate_faces, "degenerate face", "degenerate faces") + " skipped");
  if (nonmanifold_faces) parts.push_back(plural(nonmanifold_faces, "non-manifold face", "non-manifold faces") + " refused");
  if (unreferenced_vertices) parts.push_back(plural(unreferenced_vertices, "unreferenced vertex", "unreferenced vertices") + " ignored");
  for (std::size_t i = 0; i < parts.size(); ++i) s << (i == 0 ? "; " : ", ") << parts[i];
  return s.str();
}

// ---------------------------------------------------------------------------
// Construction: every entry point ends in from_polygons
// ---------------------------------------------------------------------------

Mesh Mesh::from_triangles(const double* V, std::size_t nv, const std::int64_t* F, std::size_t nf) {
  if (nv == 0 || V == nullptr) throw Error("the mesh has no vertices; give at least three vertices and one face");
  if (nf == 0 || F == nullptr)
    throw Error("the mesh has no faces (a point cloud cannot be segmented); give a triangle mesh");
  std::vector<Vec3> points(nv);
  std::memcpy(static_cast<void*>(points.data()), V, 3 * nv * sizeof(double));  // Vec3 is 3 packed doubles
  std::vector<std::int64_t> corners(F, F + 3 * nf);
  std::vector<std::size_t> offsets(nf + 1);
  for (std::size_t k = 0; k <= nf; ++k) offsets[k] = 3 * k;
  return from_polygons(std::move(points), corners, offsets);
}

Mesh Mesh::from_polygons(std::vector<Vec3> V, const std::vector<std::int64_t>& corners,
                         const std::vector<std::size_t>& offsets) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 must be three packed doubles");
  const std::size_t nv = V.size();
  const std::size_t nf = offsets.empty() ? 0 : offsets.size() - 1;
  if (nv == 0) throw Error("the mesh has no vertices; give at least three vertices and one face");
  if (nf == 0) throw Error("the mesh has no faces (a point cloud cannot be segmented); give a triangle mesh");

  // --- validation ---------------------------------------------------------
  for (std::size_t k = 0; k < nf; ++k) {
    if (offsets[k + 1] < offsets[k] || offsets[k + 1] > corners.size())
      throw Error("polygon offsets are inconsistent at face " + std::to_string(k) +
                  "; offsets must be non-decreasing and end at the number of corners");
  }
  for (std::size_t i = 0; i < nv; ++i) {
    const Vec3& p = V[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      std::ostringstream s;
      s << "vertex " << i << " has a non-finite coordinate (" << p[0] << ", " << p[1] << ", " << p[2]
        << "); repair or remove it before loading";
      throw Error(s.str());
    }
  }
  for (std::size_t k = 0; k < nf; ++k) {
    for (std::size_t c = offsets[k]; c < offsets[k + 1]; ++c) {
      const std::int64_t idx = corners[c];
      if (idx < 0 || static_cast<std::size_t>(idx) >= nv)
        throw Error("face " + std::to_string(k) + " refers to vertex " + std::to_string(idx) + ", but the mesh has " +
                    std::to_string(nv) + " vertices (indices are 0-based); fix the face list");
    }
  }

  Mesh mesh;
  MeshReport& report = mesh.report_;
  report.input_vertices = nv;
  report.input_faces = nf;

  // --- merge vertices with exactly equal coordinates (STL-style soups) -----
  const double* coords = V.data()->data();
  std::vector<std::int64_t> rep(nv);
  {
    CoordinateMerger merger(coords, nv);
    for (std::size_t i = 0; i < nv; ++i) {
      rep[i] = merger.insert(static_cast<std::int64_t>(i));
      if (rep[i] != static_cast<std::int64_t>(i)) ++report.duplicate_vertices_merged;
    }
  }

  // --- candidate triangles: fan n-gons, skip repeated corners and zero area -
  // cand: 3 representative input vertices per triangle; cand_face: its input face.
  std::vector<std::int64_t> cand;
  std::vector<std::size_t> cand_face;
  cand.reserve(3 * nf + (corners.size() > 3 * nf ? corners.size() - 3 * nf : 0) * 3);
  cand_face.reserve(nf);
  std::vector<std::int64_t> scratch;  // reused for large polygons' duplicate test
  for (std::size_t k = 0; k < nf; ++k) {
    const std::size_t b = offsets[k], n = offsets[k + 1] - offsets[k];
    if (n < 3) {
      ++report.degenerate_faces;
      continue;
    }
    bool repeated = false;
    if (n <= 16) {
      for (std::size_t i = 0; i < n && !repeated; ++i)
        for (std::size_t j = i + 1; j < n; ++j)
          if (rep[corners[b + i]] == rep[corners[b + j]]) {
            repeated = true;
            break;
          }
    } else {
      scratch.clear();
      for (std::size_t i = 0; i < n; ++i) scratch.push_back(rep[corners[b + i]]);
      std::sort(scratch.begin(), scratch.end());
      repeated = std::adjacent_find(scratch.begin(), scratch.end()) != scratch.end();
    }
    if (repeated) {
      ++report.degenerate_faces;
      continue;
    }
    const std::int64_t a = rep[corners[b]];
    bool any = false;
    for (std::size_t j = 1; j + 1 < n; ++j) {
      const std::int64_t c1 = rep[corners[b + j]], c2 = rep[corners[b + j + 1]];
      if (zero_area(coords + 3 * a, coords + 3 * c1, coords + 3 * c2)) continue;
      cand.push_back(a);
      cand.push_back(c1);
      cand.push_back(c2);
      cand_face.push_back(k);
      any = true;
    }
    if (!any) ++report.degenerate_faces;
  }
  const std::size_t ncand = cand_face.size();

  // --- OpenMesh: add the candidates; refused faces are non-manifold ---------
  // Vertices are numbered in input order among those used; a second pass drops
  // vertices that only refused faces used.
  std::vector<int> mesh_id(nv, -1);
  std::vector<char> added(ncand, 0);
  auto build_openmesh = [&](bool only_added) {
    std::fill(mesh_id.begin(), mesh_id.end(), -1);
    for (std::size_t t = 0; t < ncand; ++t)
      if (!only_added || added[t])
        for (int c = 0; c < 3; ++c) mesh_id[cand[3 * t + c]] = 0;
    int next = 0;
    for (std::size_t i = 0; i < nv; ++i)
      if (mesh_id[i] == 0) mesh_id[i] = next++;
    mesh.om_ = TriMesh();
    mesh.om_.reserve(static_cast<size_t>(next), 3 * ncand / 2 + static_cast<size_t>(next) / 8 + 16, ncand);
    for (std::size_t i = 0; i < nv; ++i)
      if (mesh_id[i] >= 0) mesh.om_.add_vertex(TriMesh::Point(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]));
    StreamSilencer quiet(::omerr());  // OpenMesh reports refused faces on omerr; we count them instead
    std::size_t refused = 0;
    for (std::size_t t = 0; t < ncand; ++t) {
      if (only_added && !added[t]) continue;
      const OpenMesh::FaceHandle fh = mesh.om_.add_face(OpenMesh::VertexHandle(mesh_id[cand[3 * t]]),
                                                         OpenMesh::VertexHandle(mesh_id[cand[3 * t + 1]]),
                                                         OpenMesh::VertexHandle(mesh_id[cand[3 * t + 2]]));
      if (fh.is_valid()) {
        added[t] = 1;
      } else {
        added[t] = 0;
        ++refused;
      }
    }
    return refused;
  };
  const std::size_t refused = build_openmesh(false);
  if (refused > 0) {
    // Rebuild only if a vertex was used by refused faces alone (rare): the same
    // faces in the same order are accepted again.
    std::vector<char> used(nv, 0);
    for (std::size_t t = 0; t < ncand; ++t)
      if (added[t])
        for (int c = 0; c < 3; ++c) used[cand[3 * t + c]] = 1;
    bool orphan = false;
    for (std::size_t i = 0; i < nv && !orphan; ++i) orphan = mesh_id[i] >= 0 && !used[i];
    if (orphan) build_openmesh(true);
  }

  // --- account for every input face -----------------------------------------
  for (std::size_t t = 0; t < ncand;) {
    const std::size_t k = cand_face[t];
    bool any_added = false;
    for (; t < ncand && cand_face[t] == k; ++t) any_added = any_added || added[t];
    const bool polygon = offsets[k + 1] - offsets[k] > 3;
    if (!any_added)
      ++report.nonmanifold_faces;
    else if (polygon)
      ++report.polygons_triangulated;
  }

  // --- flat arrays -----------------------------------------------------------
  const int n_mesh_vertices = static_cast<int>(mesh.om_.n_vertices());
  mesh.input_to_mesh_.resize(nv);
  mesh.mesh_to_input_.resize(static_cast<std::size_t>(n_mesh_vertices));
  mesh.positions_.resize(static_cast<std::size_t>(n_mesh_vertices));
  for (std::size_t i = 0; i < nv; ++i) {
    const int id = mesh_id[rep[i]];
    mesh.input_to_mesh_[i] = id;
    if (id < 0) {
      ++report.unreferenced_vertices;
    } else if (rep[i] == static_cast<std::int64_t>(i)) {
      mesh.mesh_to_input_[id] = i;
      mesh.positions_[id] = V[i];
    }
  }
  mesh.face_vertices_.clear();
  mesh.face_vertices_.reserve(3 * mesh.om_.n_faces());
  for (std::size_t t = 0; t < ncand; ++t)
    if (added[t])
      for (int c = 0; c < 3; ++c) mesh.face_vertices_.push_back(mesh_id[cand[3 * t + c]]);

  if (mesh.face_vertices_.empty()) {
    report.triangles = 0;
    throw Error("no usable face in the mesh (" + report.summary() + "); repair the mesh and load it again");
  }
  mesh.build_arrays();
  return mesh;
}

// ---------------------------------------------------------------------------
// Adjacency arrays
// ---------------------------------------------------------------------------

void Mesh::build_arrays() {
  const int nv = static_cast<int>(positions_.size());
  const int nf = static_cast<int>(face_vertices_.size() / 3);

  // Face neighbours from OpenMesh's halfedges; edge k of f joins corners k+1 and k+2.
  face_neighbors_.assign(3 * static_cast<std::size_t>(nf), -1);
  for (int f = 0; f < nf; ++f) {
    const OpenMesh::FaceHandle fh(f);
    for (const OpenMesh::HalfedgeHandle heh : om_.fh_range(fh)) {
      const int a = om_.from_vertex_handle(heh).idx();
      int j = 0;
      while (j < 3 && face_vertices_[3 * f + j] != a) ++j;
      const int k = (j + 2) % 3;  // corner a is k+1
      const OpenMesh::FaceHandle other = om_.opposite_face_handle(heh);
      face_neighbors_[3 * f + k] = other.is_valid() ? other.idx() : -1;
    }
  }

  // Face normals and areas; area-weighted vertex normals (sum of cross products).
  face_normals_.resize(nf);
  face_areas_.resize(nf);
  vertex_areas_.assign(nv, 0.0);
  vertex_normals_.assign(nv, Vec3::Zero());
  for (int f = 0; f < nf; ++f) {
    const int* c = &face_vertices_[3 * f];
    const Vec3 cross = (positions_[c[1]] - positions_[c[0]]).cross(positions_[c[2]] - positions_[c[0]]);
    const double norm = cross.norm();
    face_areas_[f] = 0.5 * norm;
    face_normals_[f] = norm > 0 ? Vec3(cross / norm) : Vec3(Vec3::UnitZ());
    for (int k = 0; k < 3; ++k) {
      vertex_normals_[c[k]] += cross;
      vertex_areas_[c[k]] += face_areas_[f] / 3.0;
    }
  }

  // One-ring faces (CSR).
  ring_face_offsets_.assign(nv + 1, 0);
  for (int c : face_vertices_) ++ring_face_offsets_[c + 1];
  for (int v = 0; v < nv; ++v) ring_face_offsets_[v + 1] += ring_face_offsets_[v];
  ring_faces_.resize(face_vertices_.size());
  {
    std::vector<std::size_t> fill(ring_face_offsets_.begin(), ring_face_offsets_.end() - 1);
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) ring_faces_[fill[face_vertices_[3 * f + k]]++] = f;
  }

  for (int v = 0; v < nv; ++v) {
    const double norm = vertex_normals_[v].norm();
    if (norm > 0) {
      vertex_normals_[v] /= norm;
    } else {
      // Incident normals cancel (a fold): fall back to one incident face's normal.
      vertex_normals_[v] = face_normals_[ring_faces_[ring_face_offsets_[v]]];
    }
  }

  // Unique edges (each counted from the face with the smaller index, or once on
  // the boundary): one-ring vertices, boundary flags, average edge length.
  auto unique_edge = [&](int f, int k) {
    const int g = face_neighbors_[3 * f + k];
    return g < 0 || g > f;
  };
  ring_vertex_offsets_.assign(nv + 1, 0);
  boundary_vertex_.assign(nv, 0);
  std::size_t boundary_edges = 0, n_edges = 0;
  double edge_sum = 0;
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      if (!unique_edge(f, k)) continue;
      const int a = face_vertices_[3 * f + (k + 1) % 3], b = face_vertices_[3 * f + (k + 2) % 3];
      ++ring_vertex_offsets_[a + 1];
      ++ring_vertex_offsets_[b + 1];
      ++n_edges;
      edge_sum += (positions_[a] - positions_[b]).norm();
      if (face_neighbors_[3 * f + k] < 0) {
        ++boundary_edges;
        boundary_vertex_[a] = boundary_vertex_[b] = 1;
      }
    }
  }
  for (int v = 0; v < nv; ++v) ring_vertex_offsets_[v + 1] += ring_vertex_offsets_[v];
  ring_vertices_.resize(ring_vertex_offsets_[nv]);
  {
    std::vector<std::size_t> fill(ring_vertex_offsets_.begin(), ring_vertex_offsets_.end() - 1);
    for (int f = 0; f < nf; ++f) {
      for (int k = 0; k < 3; ++k) {
        if (!unique_edge(f, k)) continue;
        const int a = face_vertices_[3 * f + (k + 1) % 3], b = face_vertices_[3 * f + (k + 2) % 3];
        ring_vertices_[fill[a]++] = b;
        ring_vertices_[fill[b]++] = a;
      }
    }
  }
  average_edge_length_ = n_edges ? edge_sum / static_cast<double>(n_edges) : 0;

  // Components: union-find over faces joined by an edge.
  std::vector<int> parent(nf);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];  // path halving
      x = parent[x];
    }
    return x;
  };
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const int g = face_neighbors_[3 * f + k];
      if (g > f) {
        const int ra = find(f), rb = find(g);
        if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
      }
    }
  std::vector<int> label(nf, -1);
  int n_components = 0;
  for (int f = 0; f < nf; ++f) {
    const int r = find(f);
    if (label[r] < 0) label[r] = n_components++;
    label[f] = label[r];
  }
  component_.resize(nv);
  for (int v = 0; v < nv; ++v) component_[v] = label[ring_faces_[ring_face_offsets_[v]]];

  // Bounding box diagonal.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : positions_) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  bbox_diagonal_ = nv ? (hi - lo).norm() : 0;

  report_.triangles = static_cast<std::size_t>(nf);
  report_.components = static_cast<std::size_t>(n_components);
  report_.boundary_edges = boundary_edges;
}

// ---------------------------------------------------------------------------
// Files
// ---------------------------------------------------------------------------

namespace {

using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<>;

/// Records the file's raw vertices and faces in file order, before OpenMesh's
/// own non-manifold handling, so intake treats files and arrays alike.
class RecordingImporter : public OpenMesh::IO::ImporterT<PolyMesh> {
 public:
  using Base = OpenMesh::IO::ImporterT<PolyMesh>;
  explicit RecordingImporter(PolyMesh& mesh) : Base(mesh), poly_(mesh) { offsets.push_back(0); }

  OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3f& p) override {
    points.emplace_back(p[0], p[1], p[2]);
    return Base::add_vertex(p);
  }
  OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3d& p) override {
    points.emplace_back(p[0], p[1], p[2]);
    return Base::add_vertex(p);
  }
  OpenMesh::VertexHandle add_vertex() override {
    // The PLY reader adds vertices first and sets their points later (set_point);
    // a vertex whose point is never set stays NaN and is reported as non-finite.
    points.emplace_back(Vec3::Constant(std::numeric_limits<double>::quiet_NaN()));
    return Base::add_vertex();
  }
  void set_point(OpenMesh::VertexHandle vh, const OpenMesh::Vec3f& p) override {
    if (vh.is_valid() && static_cast<std::size_t>(vh.idx()) < points.size())
      points[static_cast<std::size_t>(vh.idx())] = Vec3(p[0], p[1], p[2]);
    Base::set_point(vh, p);
  }
  OpenMesh::FaceHandle add_face(const VHandles& indices) override {
    for (const OpenMesh::VertexHandle vh : indices) corners.push_back(vh.idx());
    offsets.push_back(corners.size());
    // An unconnected face keeps per-face properties the readers set valid.
    return poly_.new_face();
  }
  // The recorded faces have no halfedges: texture data has nowhere to go.
  void add_face_texcoords(OpenMesh::FaceHandle, OpenMesh::VertexHandle, const std::vector<OpenMesh::Vec2f>&) override {}
  void add_face_texcoords(OpenMesh::FaceHandle, OpenMesh::VertexHandle, const std::vector<OpenMesh::Vec3f>&) override {}
  void set_face_texindex(OpenMesh::FaceHandle, int) override {}

  std::vector<Vec3> points;
  std::vector<std::int64_t> corners;
  std::vector<std::size_t> offsets;

 private:
  PolyMesh& poly_;
};

/// For an ASCII OFF file, its text with '#' comments removed (true); false for binary OFF.
bool read_ascii_off_without_comments(const std::string& path, std::string* text) {
  std::ifstream in(path, std::ios::binary);
  std::string header;
  std::getline(in, header);
  if (header.find("BINARY") != std::string::npos) return false;
  in.seekg(0);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text->clear();
  text->reserve(all.size());
  bool comment = false;
  for (const char c : all) {
    if (c == '#') comment = true;
    if (c == '\n') comment = false;
    if (!comment) text->push_back(c);
  }
  return true;
}

/// OpenMesh's OFF and PLY readers trust the element counts in the header (a truncated
/// or garbage header makes them allocate wildly or spin): check the counts fit the file.
void check_header_counts(const std::string& path, const std::string& ext, const std::string* off_text) {
  const auto fail = [&](const std::string& why) {
    throw Error("cannot read '" + path + "': " + why + "; give a valid " + kSupportedFormats + " file");
  };
  std::ifstream in(path, std::ios::binary);
  in.seekg(0, std::ios::end);
  const std::uint64_t size = static_cast<std::uint64_t>(std::max<std::streamoff>(0, in.tellg()));
  in.seekg(0);
  if (ext == "off") {
    if (off_text) {
      std::istringstream tokens(*off_text);
      std::string word;
      tokens >> word;
      if (word.size() < 3 || word.compare(word.size() - 3, 3, "OFF") != 0) fail("the OFF header keyword is missing");
      if (word.find('n') != std::string::npos) {
        long long dimension = 0;
        tokens >> dimension;
      }
      long long nv = -1, nf = -1, ne = -1;
      if (!(tokens >> nv >> nf >> ne) || nv < 0 || nf < 0 || ne < 0)
        fail("the OFF header must give the vertex, face and edge counts");
      // At least "x y z" per vertex and "n a b c" per face.
      if (static_cast<std::uint64_t>(nv) * 5 + static_cast<std::uint64_t>(nf) * 7 > size)
        fail("the OFF header announces " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
             " faces, more than the file holds");
    } else {
      std::string header;
      std::getline(in, header);
      std::int32_t counts[3] = {-1, -1, -1};
      in.read(reinterpret_cast<char*>(counts), sizeof counts);  // OpenMesh writes and reads them little-endian
      if (!in || counts[0] < 0 || counts[1] < 0)
        fail("the binary OFF header must give the vertex, face and edge counts");
      const std::uint64_t needed = header.size() + 1 + 12 + static_cast<std::uint64_t>(counts[0]) * 12 +
                                   static_cast<std::uint64_t>(counts[1]) * 16;
      if (needed > size)
        fail("the OFF header announces " + std::to_string(counts[0]) + " vertices and " +
             std::to_string(counts[1]) + " faces, more than the file holds");
    }
  } else if (ext == "ply") {
    std::string line;
    std::uint64_t header_bytes = 0, needed = 0, count = 0;
    bool ended = false;
    for (int lines = 0; lines < 100000 && std::getline(in, line); ++lines) {
      header_bytes += line.size() + 1;
      std::istringstream words(line);
      std::string word;
      words >> word;
      if (word == "element") {
        std::string name;
        long long n = -1;
        if (!(words >> name >> n) || n < 0) fail("a PLY element has no valid count");
        count = static_cast<std::uint64_t>(n);
      } else if (word == "property") {
        needed += count;  // every property of every element takes at least one byte
      } else if (word == "end_header") {
        ended = true;
        break;
      }
    }
    if (!ended) fail("the PLY header has no end_header line");
    if (needed > size - std::min(size, header_bytes) + 1)
      fail("the PLY header announces more elements than the file holds");
  }
}

}  // namespace

Mesh Mesh::load(const std::string& path) {
  std::string ext;
  const std::size_t dot = path.find_last_of('.');
  const std::size_t slash = path.find_last_of("/\\");
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != "obj" && ext != "ply" && ext != "stl" && ext != "off")
    throw Error("cannot load '" + path + "': unsupported file type" + (ext.empty() ? "" : " '." + ext + "'") +
                "; give an " + kSupportedFormats + " file");
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw Error("cannot open '" + path + "': no such file or not readable; check the path");
  }

  PolyMesh poly;
  RecordingImporter importer(poly);
  OpenMesh::IO::Options options;
  std::string off_text;
  const bool ascii_off = ext == "off" && read_ascii_off_without_comments(path, &off_text);
  check_header_counts(path, ext, ascii_off ? &off_text : nullptr);
  bool ok = false;
  try {
    StreamSilencer quiet_errors(::omerr());
    StreamSilencer quiet_log(::omlog());
    if (ascii_off) {
      // OpenMesh's OFF reader does not skip '#' comments (common in OFF files): feed it the text without them.
      std::istringstream stream(off_text);
      ok = OpenMesh::IO::IOManager().read(stream, "off", importer, options);
    } else {
      // OpenMesh picks the reader by the file's extension and detects ASCII or binary itself.
      ok = OpenMesh::IO::IOManager().read(path, importer, options);
    }
  } catch (const std::exception&) {
    ok = false;  // e.g. std::bad_alloc from counts that slipped past the checks
  }
  if (!ok)
    throw Error("cannot read '" + path + "' as a ." + ext + " mesh: the file is malformed or empty; give a valid " +
                kSupportedFormats + " file");
  try {
    return from_polygons(std::move(importer.points), importer.corners, importer.offsets);
  } catch (const Error& e) {
    throw Error("'" + path + "': " + e.what());
  }
}

// ---------------------------------------------------------------------------

double measure_distance(const Mesh& mesh, std::int64_t input_i, std::int64_t input_j) {
  const std::int64_t n = static_cast<std::int64_t>(mesh.input_vertex_count());
  for (const std::int64_t i : {input_i, input_j}) {
    if (i < 0 || i >= n)
      throw Error("vertex index " + std::to_string(i) + " is out of range: the mesh file has " + std::to_string(n) +
                  " vertices (indices are 0-based)");
    if (mesh.input_to_mesh(static_cast<std::size_t>(i)) < 0)
      throw Error("vertex " + std::to_string(i) + " is in no face of the mesh; pick a vertex on the surface");
  }
  return (mesh.position(mesh.input_to_mesh(static_cast<std::size_t>(input_i))) -
          mesh.position(mesh.input_to_mesh(static_cast<std::size_t>(input_j))))
      .norm();
}

}  // namespace relief_snake

// Mesh intake: validation, vertex merging, triangulation and the non-manifold test
// (OpenMesh's add_face, on a temporary mesh that is dropped before intake returns).
// Every entry point (arrays, polygons, files) ends in Mesh::build with the same rules.
#if defined(__GNUC__) && !defined(__clang__)
// OpenMesh's property templates trip GCC's -Wmaybe-uninitialized at instantiation; not our code.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include "relief_snake/mesh.hpp"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "relief_snake/error.hpp"

namespace relief_snake {

namespace {

struct MeshTraits : public OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec3d Normal;
};
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<MeshTraits>;

constexpr const char* kPartialHint = "or allow a partial load (--allow-partial, allow_partial=True) to skip it";

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
/// that has them. Flat storage: one index per slot, no per-vertex allocation.
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

/// Whether triangle (a, b, c) is too thin to have a normal.
bool zero_area(const double* a, const double* b, const double* c) {
  const Vec3 pa(a[0], a[1], a[2]), pb(b[0], b[1], b[2]), pc(c[0], c[1], c[2]);
  const Vec3 e1 = pb - pa, e2 = pc - pa, e3 = pc - pb;
  const double longest2 = std::max({e1.squaredNorm(), e2.squaredNorm(), e3.squaredNorm()});
  // Relative test: exactly or numerically collinear corners give no usable normal.
  return e1.cross(e2).norm() <= 1e-12 * longest2;
}

bool usable_coordinate(double x) { return std::isfinite(x) && std::abs(x) <= kMaxCoordinate; }

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

}  // namespace

/// What Mesh::build reads: coordinates and corners in place, offsets optional (triangles).
struct Mesh::Input {
  const double* coords = nullptr;  ///< V #V by 3
  std::size_t nv = 0;
  const std::int64_t* corners = nullptr;
  std::size_t n_corners = 0;
  const std::size_t* offsets = nullptr;  ///< #F + 1, or nullptr: face k is corners[3k .. 3k+3)
  std::size_t nf = 0;
  const PolygonSoup* names = nullptr;  ///< for "face 3 (line 9)" in messages; may be null
  std::size_t begin(std::size_t k) const { return offsets ? offsets[k] : 3 * k; }
  std::size_t end(std::size_t k) const { return offsets ? offsets[k + 1] : 3 * k + 3; }
  std::string face_name(std::size_t k) const { return names ? names->face_name(k) : "face " + std::to_string(k); }
  std::string vertex_name(std::size_t i) const { return names ? names->vertex_name(i) : "vertex " + std::to_string(i); }
};

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
  if (invalid_faces) parts.push_back("partial load: " + plural(invalid_faces, "invalid face", "invalid faces") + " skipped");
  if (invalid_vertices) parts.push_back("partial load: " + plural(invalid_vertices, "invalid vertex", "invalid vertices") + " ignored");
  for (const std::string& note : notes) parts.push_back("partial load: " + note);
  for (std::size_t i = 0; i < parts.size(); ++i) s << (i == 0 ? "; " : ", ") << parts[i];
  return s.str();
}

// ---------------------------------------------------------------------------
// Entry points
// ---------------------------------------------------------------------------

Mesh Mesh::from_triangles(const double* V, std::size_t nv, const std::int64_t* F, std::size_t nf,
                          const IntakeOptions& options) {
  if (nv == 0 || V == nullptr) throw Error("the mesh has no vertices; give at least three vertices and one face");
  if (nf == 0 || F == nullptr)
    throw Error("the mesh has no faces (a point cloud cannot be segmented); give a triangle mesh");
  Input in;
  in.coords = V;
  in.nv = nv;
  in.corners = F;
  in.n_corners = 3 * nf;
  in.nf = nf;
  return build(in, options);
}

Mesh Mesh::from_polygons(const std::vector<Vec3>& V, const std::vector<std::int64_t>& corners,
                         const std::vector<std::size_t>& offsets, const IntakeOptions& options) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 must be three packed doubles");
  Input in;
  in.coords = V.empty() ? nullptr : V.data()->data();
  in.nv = V.size();
  in.corners = corners.data();
  in.n_corners = corners.size();
  in.offsets = offsets.data();
  in.nf = offsets.empty() ? 0 : offsets.size() - 1;
  return build(in, options);
}

Mesh Mesh::from_soup(const PolygonSoup& soup, const IntakeOptions& options) {
  Input in;
  in.coords = soup.positions.data();
  in.nv = soup.n_vertices();
  in.corners = soup.corners.data();
  in.n_corners = soup.corners.size();
  in.offsets = soup.offsets.data();
  in.nf = soup.n_faces();
  in.names = &soup;
  try {
    Mesh mesh = build(in, options);
    mesh.report_.notes = soup.notes;
    return mesh;
  } catch (const Error& e) {
    if (soup.notes.empty()) throw;
    std::string partial;
    for (const std::string& note : soup.notes) partial += "; partial load: " + note;
    throw Error(e.what() + partial);
  }
}

Mesh Mesh::load(const std::string& path, const IntakeOptions& options) {
  ReadOptions read;
  read.allow_partial = options.allow_partial;
  const PolygonSoup soup = read_mesh_file(path, read);
  try {
    return from_soup(soup, options);
  } catch (const Error& e) {
    throw Error("'" + path + "': " + e.what());
  }
}

// ---------------------------------------------------------------------------
// Construction
// ---------------------------------------------------------------------------

Mesh Mesh::build(const Input& in, const IntakeOptions& options) {
  const std::size_t nv = in.nv, nf = in.nf;
  const double* coords = in.coords;
  if (nv == 0) throw Error("the mesh has no vertices; give at least three vertices and one face");
  if (nf == 0) throw Error("the mesh has no faces (a point cloud cannot be segmented); give a triangle mesh");
  if (nv > kMaxMeshElements || nf > kMaxMeshElements)
    throw Error("the mesh has " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                " faces; at most 2^31 - 1 of each are supported, decimate or split the mesh");

  // --- validation ---------------------------------------------------------
  if (in.offsets) {
    if (in.offsets[0] != 0) throw Error("polygon offsets must start at 0");
    for (std::size_t k = 0; k < nf; ++k)
      if (in.offsets[k + 1] < in.offsets[k] || in.offsets[k + 1] > in.n_corners)
        throw Error("polygon offsets are inconsistent at face " + std::to_string(k) +
                    "; offsets must be non-decreasing and end at the number of corners");
  }
  Mesh mesh;
  MeshReport& report = mesh.report_;
  report.input_vertices = nv;
  report.input_faces = nf;

  // Vertices intake cannot use: non-finite, or so large that squared lengths overflow.
  std::vector<char> bad_vertex;
  for (std::size_t i = 0; i < nv; ++i) {
    const double* p = coords + 3 * i;
    if (usable_coordinate(p[0]) && usable_coordinate(p[1]) && usable_coordinate(p[2])) continue;
    if (!options.allow_partial) {
      std::ostringstream s;
      s.precision(17);
      const bool finite = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
      s << in.vertex_name(i) << " has " << (finite ? "a coordinate too large to compute with" : "a non-finite coordinate")
        << " (" << p[0] << ", " << p[1] << ", " << p[2] << ")"
        << (finite ? "; coordinates must be within +-1e150, rescale the mesh, " : "; repair or remove it, ")
        << kPartialHint;
      throw Error(s.str());
    }
    if (bad_vertex.empty()) bad_vertex.assign(nv, 0);
    bad_vertex[i] = 1;
    ++report.invalid_vertices;
  }
  std::vector<char> bad_face;
  for (std::size_t k = 0; k < nf; ++k) {
    for (std::size_t c = in.begin(k); c < in.end(k); ++c) {
      const std::int64_t idx = in.corners[c];
      const bool out_of_range = idx < 0 || static_cast<std::uint64_t>(idx) >= nv;
      if (!out_of_range && (bad_vertex.empty() || !bad_vertex[static_cast<std::size_t>(idx)])) continue;
      if (!options.allow_partial) {
        const int base = in.names ? in.names->index_base : 0;
        throw Error(in.face_name(k) + " refers to vertex " + std::to_string(idx + base) + ", but the mesh has " +
                    std::to_string(nv) + (base == 1 ? " vertices (OBJ indices count from 1)" : " vertices (indices are 0-based)") +
                    "; fix the face list, " + kPartialHint);
      }
      if (bad_face.empty()) bad_face.assign(nf, 0);
      bad_face[k] = 1;
      ++report.invalid_faces;
      break;
    }
  }

  // --- merge vertices with exactly equal coordinates (STL-style soups) -----
  std::vector<std::int64_t> rep(nv);
  {
    CoordinateMerger merger(coords, nv);
    for (std::size_t i = 0; i < nv; ++i) {
      if (!bad_vertex.empty() && bad_vertex[i]) {
        rep[i] = static_cast<std::int64_t>(i);  // never merged: no valid face uses it
        continue;
      }
      rep[i] = merger.insert(static_cast<std::int64_t>(i));
      if (rep[i] != static_cast<std::int64_t>(i)) ++report.duplicate_vertices_merged;
    }
  }

  // --- candidate triangles: fan n-gons, skip repeated corners and zero area -
  // cand: 3 representative input vertices per triangle; cand_face: its input face.
  std::vector<std::int64_t> cand;
  std::vector<std::size_t> cand_face;
  const std::size_t n_corners = in.end(nf - 1);
  cand.reserve(3 * nf + (n_corners > 3 * nf ? n_corners - 3 * nf : 0) * 3);
  cand_face.reserve(nf);
  std::vector<std::int64_t> scratch;  // reused for large polygons' duplicate test
  for (std::size_t k = 0; k < nf; ++k) {
    if (!bad_face.empty() && bad_face[k]) continue;
    const std::size_t b = in.begin(k), n = in.end(k) - in.begin(k);
    const std::int64_t* corners = in.corners;
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
  if (ncand > kMaxMeshElements)
    throw Error("the mesh triangulates into " + std::to_string(ncand) +
                " triangles; at most 2^31 - 1 are supported, decimate or split the mesh");

  // --- OpenMesh: add the candidates; refused faces are non-manifold ---------
  // Vertices are numbered in input order among those used; a second pass drops
  // vertices that only refused faces used.
  std::vector<int> mesh_id(nv, -1);
  std::vector<char> added(ncand, 0);
  TriMesh om;
  auto build_openmesh = [&](bool only_added) {
    std::fill(mesh_id.begin(), mesh_id.end(), -1);
    for (std::size_t t = 0; t < ncand; ++t)
      if (!only_added || added[t])
        for (int c = 0; c < 3; ++c) mesh_id[cand[3 * t + c]] = 0;
    int next = 0;
    for (std::size_t i = 0; i < nv; ++i)
      if (mesh_id[i] == 0) mesh_id[i] = next++;
    om = TriMesh();
    om.reserve(static_cast<size_t>(next), 3 * ncand / 2 + static_cast<size_t>(next) / 8 + 16, ncand);
    for (std::size_t i = 0; i < nv; ++i)
      if (mesh_id[i] >= 0) om.add_vertex(TriMesh::Point(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]));
    StreamSilencer quiet(::omerr());  // OpenMesh reports refused faces on omerr; we count them instead
    std::size_t refused = 0;
    for (std::size_t t = 0; t < ncand; ++t) {
      if (only_added && !added[t]) continue;
      const OpenMesh::FaceHandle fh = om.add_face(OpenMesh::VertexHandle(mesh_id[cand[3 * t]]),
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
    const bool polygon = in.end(k) - in.begin(k) > 3;
    if (!any_added)
      ++report.nonmanifold_faces;
    else if (polygon)
      ++report.polygons_triangulated;
  }

  // --- flat arrays -----------------------------------------------------------
  if (options.local_origin != LocalOrigin::Off) {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::size_t i = 0; i < nv; ++i)
      if (mesh_id[rep[i]] >= 0) {
        const Vec3 p(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]);
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
    for (int k = 0; k < 3 && lo[k] <= hi[k]; ++k) {
      const double c = 0.5 * lo[k] + 0.5 * hi[k];  // no overflow near kMaxCoordinate
      // Auto: only where every coordinate x of the axis lies in [c / 2, 2 c] (or [2 c, c / 2]):
      // then x - c is exact, and adding c back gives x.
      const bool exact = c > 0 ? lo[k] >= 0.5 * c && hi[k] <= 2 * c : c < 0 && hi[k] <= 0.5 * c && lo[k] >= 2 * c;
      if (options.local_origin == LocalOrigin::On || exact) mesh.origin_[k] = c;
    }
  }
  const int n_mesh_vertices = static_cast<int>(om.n_vertices());
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
      mesh.positions_[id] = Vec3(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]) - mesh.origin_;
    }
  }
  mesh.face_vertices_.clear();
  mesh.face_vertices_.reserve(3 * om.n_faces());
  for (std::size_t t = 0; t < ncand; ++t)
    if (added[t])
      for (int c = 0; c < 3; ++c) mesh.face_vertices_.push_back(mesh_id[cand[3 * t + c]]);

  if (mesh.face_vertices_.empty()) {
    report.triangles = 0;
    std::string why = "no usable face in the mesh (" + report.summary() + ")";
    if (report.invalid_faces == nf) why += "; every face was invalid";
    throw Error(why + "; repair the mesh and load it again");
  }

  // Face neighbours from OpenMesh's halfedges (edge k of f joins corners k+1 and k+2),
  // then OpenMesh is released: the engine reads only the flat arrays.
  const int n_faces = static_cast<int>(mesh.face_vertices_.size() / 3);
  mesh.face_neighbors_.assign(3 * static_cast<std::size_t>(n_faces), -1);
  for (int f = 0; f < n_faces; ++f) {
    for (const OpenMesh::HalfedgeHandle heh : om.fh_range(OpenMesh::FaceHandle(f))) {
      const int a = om.from_vertex_handle(heh).idx();
      int j = 0;
      while (j < 3 && mesh.face_vertices_[3 * f + j] != a) ++j;
      const int k = (j + 2) % 3;  // corner a is k+1
      const OpenMesh::FaceHandle other = om.opposite_face_handle(heh);
      mesh.face_neighbors_[3 * f + k] = other.is_valid() ? other.idx() : -1;
    }
  }
  om = TriMesh();
  mesh.build_arrays();
  return mesh;
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

#pragma once
// Mesh intake: arrays or files in, a validated triangle mesh out, with a report of
// everything that was merged, split or refused (nothing is dropped silently).
// Files are parsed by mesh_io.hpp; OpenMesh is used inside intake only (to find the
// faces that would make the surface non-manifold) and is gone once the Mesh exists.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "relief_snake/mesh_io.hpp"

namespace relief_snake {

using Vec3 = Eigen::Vector3d;

/// IntakeOptions::local_origin: whether the mesh stores positions relative to a local origin
/// (Mesh::origin()) instead of the file's. The engine's sums of squares (plane fits, moments)
/// lose detail when coordinates are large against the mesh (georeferenced scans, 1e6 mm);
/// relative to the bounding-box centre they keep it. Every result (polylines, progress
/// contours, outlines, extraction meshes and frames) comes back in file coordinates.
enum class LocalOrigin {
  /// Per axis, the bounding-box centre c where the box lies within [c / 2, 2 c] (it is at least
  /// its own extent away from zero): there x - c is exact (Sterbenz), so file coordinates come
  /// back bit for bit; elsewhere nothing is gained and the axis is left as it is.
  Auto,
  On,   ///< the bounding-box centre on every axis (not always exact: x - c rounds)
  Off,  ///< positions are the file's coordinates
};

/// How strict intake is.
struct IntakeOptions {
  /// Skip (and count) faces with out-of-range corners or non-finite / too-large corner coordinates,
  /// and keep the readable part of a truncated or inconsistent file (MeshReport::notes says what
  /// was skipped). Off: any of these is an error that names the face, vertex or line.
  bool allow_partial = false;
  /// Where positions are measured from (origin()): see LocalOrigin.
  LocalOrigin local_origin = LocalOrigin::Auto;
};

/// Coordinates beyond this magnitude are refused: squared distances would overflow a double.
constexpr double kMaxCoordinate = 1e150;
/// Vertex and triangle counts must stay below 2^31: the adjacency arrays index with int.
constexpr std::size_t kMaxMeshElements = (std::size_t(1) << 31) - 1;

/// What intake did with the input. Every input face is accounted for:
/// input_faces = faces_kept_as_triangles + polygons_triangulated + degenerate_faces + nonmanifold_faces
///               + invalid_faces.
struct MeshReport {
  std::size_t input_vertices = 0;
  std::size_t input_faces = 0;
  std::size_t triangles = 0;                   ///< triangles in the resulting mesh
  std::size_t polygons_triangulated = 0;       ///< input faces with more than 3 corners, fanned into triangles
  std::size_t duplicate_vertices_merged = 0;   ///< input vertices with exactly the coordinates of an earlier one
  std::size_t unreferenced_vertices = 0;       ///< input vertices used by no kept face
  std::size_t degenerate_faces = 0;            ///< repeated corners or zero area: skipped
  std::size_t nonmanifold_faces = 0;           ///< would make an edge or vertex non-manifold: refused
  /// allow_partial only: faces with an out-of-range corner or a corner whose coordinates are
  /// non-finite or beyond kMaxCoordinate, skipped.
  std::size_t invalid_faces = 0;
  std::size_t invalid_vertices = 0;            ///< allow_partial only: non-finite or too-large vertices ignored
  /// allow_partial only: what the file reader skipped (truncation, count mismatches), one sentence each.
  std::vector<std::string> notes;
  bool partial() const { return invalid_faces > 0 || invalid_vertices > 0 || !notes.empty(); }
  std::size_t components = 0;                  ///< connected components (by faces)
  std::size_t boundary_edges = 0;
  /// One line, e.g. "120000 triangles, 2 components; 3 degenerate faces skipped, 1 non-manifold face refused".
  std::string summary() const;
};

/// A triangle mesh with the flat adjacency arrays the snake's inner loops need.
/// Vertex and face indices are the mesh's own (0-based, dense). Input (file or
/// array) vertex indices map to mesh vertices through input_to_mesh().
class Mesh {
 public:
  /// V: nv by 3 row-major coordinates; F: nf by 3 zero-based corner indices. Read in place (no copy).
  /// Throws Error on empty input, out-of-range indices or non-finite coordinates (unless allow_partial).
  static Mesh from_triangles(const double* V, std::size_t nv, const std::int64_t* F, std::size_t nf,
                             const IntakeOptions& options = {});
  /// Polygons of any size: face k has corners[offsets[k] .. offsets[k+1]); offsets has nf+1 entries.
  static Mesh from_polygons(const std::vector<Vec3>& V, const std::vector<std::int64_t>& corners,
                            const std::vector<std::size_t>& offsets, const IntakeOptions& options = {});
  /// A file's (or a caller's) polygon soup; messages name the soup's lines where it has them.
  static Mesh from_soup(const PolygonSoup& soup, const IntakeOptions& options = {});
  /// OBJ, PLY, STL or OFF (read_mesh_file). Throws Error, naming the path and the line or element.
  static Mesh load(const std::string& path, const IntakeOptions& options = {});

  int n_vertices() const { return static_cast<int>(positions_.size()); }
  int n_faces() const { return static_cast<int>(face_vertices_.size() / 3); }

  /// Position of vertex v, relative to origin(): the engine works in these coordinates.
  const Vec3& position(int v) const { return positions_[v]; }
  /// What was subtracted from the input's coordinates (IntakeOptions::local_origin; zero for a
  /// scan around the file's origin): file coordinates are position(v) + origin().
  const Vec3& origin() const { return origin_; }
  /// A point in the mesh's coordinates (position(), position(mesh, SurfacePoint)) in the file's.
  Vec3 to_file(const Vec3& p) const { return p + origin_; }
  /// Corner k (0..2) of face f, counter-clockwise seen from the normal.
  int face_vertex(int f, int k) const { return face_vertices_[3 * f + k]; }
  /// All corners, 3 per face (F #F by 3, row-major), for inner loops.
  const int* face_vertices() const { return face_vertices_.data(); }
  /// Face across the edge opposite corner k of f (that edge joins corners k+1 and k+2), -1 on a boundary.
  int face_neighbor(int f, int k) const { return face_neighbors_[3 * f + k]; }
  const Vec3& face_normal(int f) const { return face_normals_[f]; }
  double face_area(int f) const { return face_areas_[f]; }
  /// A third of the area of the faces around v (its share of the surface).
  double vertex_area(int v) const { return vertex_areas_[v]; }
  /// Area-weighted average of the incident face normals, unit length.
  const Vec3& vertex_normal(int v) const { return vertex_normals_[v]; }

  /// One-ring: vertices adjacent to v, and faces incident to v (CSR storage).
  const int* neighbors_begin(int v) const { return ring_vertices_.data() + ring_vertex_offsets_[v]; }
  const int* neighbors_end(int v) const { return ring_vertices_.data() + ring_vertex_offsets_[v + 1]; }
  const int* faces_begin(int v) const { return ring_faces_.data() + ring_face_offsets_[v]; }
  const int* faces_end(int v) const { return ring_faces_.data() + ring_face_offsets_[v + 1]; }

  bool is_boundary_vertex(int v) const { return boundary_vertex_[v] != 0; }
  /// Connected component (by shared edges) of vertex v, 0-based.
  int component(int v) const { return component_[v]; }

  double average_edge_length() const { return average_edge_length_; }
  double bbox_diagonal() const { return bbox_diagonal_; }

  /// Number of vertices of the original input (file or arrays).
  std::size_t input_vertex_count() const { return input_to_mesh_.size(); }
  /// Mesh vertex of input vertex i, or -1 if that vertex is in no kept face.
  int input_to_mesh(std::size_t i) const { return input_to_mesh_[i]; }
  /// Input index of mesh vertex v (the first input vertex merged into it).
  std::size_t mesh_to_input(int v) const { return mesh_to_input_[v]; }

  const MeshReport& report() const { return report_; }

 private:
  struct Input;  // the validated view intake works on (mesh_intake.cpp)
  static Mesh build(const Input& input, const IntakeOptions& options);
  /// Everything but positions_, face_vertices_ and face_neighbors_ (mesh_adjacency.cpp).
  void build_arrays();

  MeshReport report_;
  std::vector<Vec3> positions_, face_normals_, vertex_normals_;
  std::vector<double> face_areas_, vertex_areas_;
  std::vector<int> face_vertices_, face_neighbors_;
  std::vector<int> ring_vertices_, ring_faces_;
  std::vector<std::size_t> ring_vertex_offsets_, ring_face_offsets_;
  std::vector<char> boundary_vertex_;
  std::vector<int> component_;
  std::vector<int> input_to_mesh_;
  std::vector<std::size_t> mesh_to_input_;
  double average_edge_length_ = 0, bbox_diagonal_ = 0;
  Vec3 origin_ = Vec3::Zero();
};

/// Straight-line (Euclidean) distance between two input vertices: the paper's
/// tool for estimating the step height h. Throws Error on bad indices.
double measure_distance(const Mesh& mesh, std::int64_t input_i, std::int64_t input_j);

}  // namespace relief_snake

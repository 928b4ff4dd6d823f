#pragma once
// Mesh file IO: OBJ, PLY, OFF and STL bytes in, a polygon soup out, with nothing
// trusted. Every count is checked against the bytes that can hold it before
// anything is reserved, every number is parsed as a double (a double PLY stays
// double), and every refusal names the line (text) or element (binary) it is at.
// The readers are the project's own (docs/design.md, "Mesh intake": why not OpenMesh's).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace relief_snake {

/// What a reader may do with a file that is not entirely valid.
struct ReadOptions {
  /// Keep what is readable of a truncated file or one whose counts do not match its
  /// contents (elements after the problem are skipped and the skip is reported in notes);
  /// faces with bad indices and vertices with non-finite coordinates are then skipped by
  /// intake and counted. Off: any of these is an error naming the line or element.
  bool allow_partial = false;
};

/// Vertices and polygons exactly as the file has them, before any repair.
struct PolygonSoup {
  std::vector<double> positions;       ///< V #V by 3, row-major (x, y, z per vertex)
  std::vector<std::int64_t> corners;   ///< all faces' corner indices, 0-based, face after face
  std::vector<std::size_t> offsets;    ///< #F + 1: face k has corners[offsets[k] .. offsets[k+1])
  std::vector<std::uint32_t> face_lines;  ///< text formats: 1-based line of face k (empty for binary)
  /// Text formats: 1-based line of vertex i (empty for binary), for messages about bad coordinates.
  std::vector<std::uint32_t> vertex_lines;
  /// What a partial read skipped (only with ReadOptions::allow_partial), one sentence each.
  std::vector<std::string> notes;
  /// How the file numbers vertices (OBJ: from 1), for messages about bad indices.
  int index_base = 0;

  std::size_t n_vertices() const { return positions.size() / 3; }
  std::size_t n_faces() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  /// "face 12 (line 40)" or "face 12": how messages name face k.
  std::string face_name(std::size_t k) const;
  std::string vertex_name(std::size_t i) const;
};

/// The file formats read_mesh_* understand.
enum class MeshFormat { Obj, Ply, Off, Stl };

/// The format named by a path's extension (case-insensitive). Throws Error for any other.
MeshFormat format_from_path(const std::string& path);

/// Parses a whole file's bytes (data[0 .. size)). Throws Error with a one-line message that
/// names the line or element of the first problem (without the file name: callers add it).
/// Memory used is bounded by a small multiple of `size`, whatever the header claims.
PolygonSoup read_mesh_bytes(const char* data, std::size_t size, MeshFormat format, const ReadOptions& options = {});

/// Maps the file and parses it (read_mesh_bytes); messages start with the path.
PolygonSoup read_mesh_file(const std::string& path, const ReadOptions& options = {});

}  // namespace relief_snake

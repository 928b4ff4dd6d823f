#pragma once
// Relief extraction: from a scan and its relief region to the base surface, the relief's
// heights above it, a height map, the relief on its own and the scan without it.
//
//   ExtractResult x = extract(mesh, region, h);        // region: #V flags (mesh vertices)
//   write_extraction(mesh, x, "out/");                 // background.ply, relief.ply, height.{exr,png,json}
#include <cstdint>
#include <string>
#include <vector>

#include "relief_snake/background.hpp"
#include "relief_snake/height_map.hpp"
#include "relief_snake/mesh.hpp"

namespace relief_snake {

struct ExtractOptions {
  BackgroundOptions background;
  HeightMapOptions height_map;
};

/// A segmentation result's relief as mesh-vertex flags (#V). input_indices: 0-based file
/// vertex indices (Result::relief_vertices, the CLI's "relief_vertices"). expected_vertices:
/// the file's vertex count recorded with the result, or -1 if unknown. Throws Error when the
/// result does not belong to the mesh (another vertex count, an index out of range) or the
/// region is empty. Indices of vertices intake dropped (in no face) are skipped with a note.
std::vector<char> region_from_input_indices(const Mesh& mesh, const std::vector<std::int64_t>& input_indices,
                                            std::int64_t expected_vertices, std::vector<std::string>* notes);

struct ExtractResult {
  double step_height = 0;
  BackgroundResult background;  ///< the base surface, normals and heights (#V each)

  /// The relief on its own: every face with a corner in the region (so its wall down to the
  /// background is included), over the mesh vertices of those faces in mesh order.
  std::vector<int> relief_mesh_vertices;  ///< #R: mesh vertex of each relief vertex
  std::vector<int> relief_triangles;      ///< 3 per face, indices into relief_mesh_vertices
  std::vector<double> relief_heights;     ///< #R: height above the base
  std::vector<Vec2> relief_uv;            ///< #R: where each relief vertex lies in the height map's frame

  HeightMap height_map;  ///< its frame's origin in file coordinates
  double background_seconds = 0, height_map_seconds = 0;
  /// The stages' wall times beyond background.timings and height_map.frame.timings (seconds).
  double weights_seconds = 0;    ///< the mesh's Laplacian weights (BackgroundSolver; 0 when one was given)
  double relief_seconds = 0;     ///< the relief's faces and the patch over the base
  double rasterise_seconds = 0;  ///< the height map's raster
  std::vector<std::string> notes;

  /// Positions of the scan with the relief removed (#V), in file coordinates (Mesh::to_file):
  /// region vertices on the base, every other vertex its own position (bit for bit unless the
  /// mesh was read with LocalOrigin::On).
  std::vector<Vec3> background_positions(const Mesh& mesh) const;
  /// One line: region size, residual, height range, map size and flattening, times.
  std::string summary() const;
  /// One line of every stage's time: "weights 0.031 s, ring 0.012 s, ...".
  std::string timings_text() const;
};

/// Throws Error with a one-line message on an empty region, a region with no background
/// around it, a size mismatch or a height map that cannot be made.
ExtractResult extract(const Mesh& mesh, const std::vector<char>& region, double step_height,
                      const ExtractOptions& options = {});
/// The same with a solver already built for the mesh (its options are used for the background).
ExtractResult extract(const BackgroundSolver& solver, const std::vector<char>& region, double step_height,
                      const HeightMapOptions& height_map = {});

struct ExtractionFiles {
  std::string background_ply, relief_ply, height_exr, height_png, height_json;
  double png_scale = 0, png_offset = 0;
};
/// (native/src/io: link relief_snake_io.) Writes DIR/background.ply, DIR/relief.ply, DIR/height.exr, DIR/height.png and DIR/height.json
/// (creating DIR if needed). All five are written under temporary names and renamed only when
/// every one succeeded. Throws Error.
ExtractionFiles write_extraction(const Mesh& mesh, const ExtractResult& result, const std::string& directory);

}  // namespace relief_snake

#pragma once
// Files of an extraction: height maps as 32-bit float OpenEXR and 16-bit PNG (with
// readers, so tests and tools can check what was written), binary PLY meshes with
// per-vertex float properties, and staged writing: every file goes to a temporary
// name first and is renamed into place only when all of them were written.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "relief_snake/height_map.hpp"
#include "relief_snake/mesh.hpp"

namespace relief_snake {

/// Files written under temporary names in their final directory, renamed by commit().
/// Destroying it before commit() removes the temporary files: nothing half-written is left.
class StagedFiles {
 public:
  StagedFiles() = default;
  StagedFiles(const StagedFiles&) = delete;
  StagedFiles& operator=(const StagedFiles&) = delete;
  ~StagedFiles();
  /// A temporary path beside `final_path` to write to.
  std::string stage(const std::string& final_path);
  /// Renames every staged file onto its final name. Throws Error if a rename fails.
  void commit();

 private:
  std::vector<std::pair<std::string, std::string>> files_;  // (temporary, final)
  bool committed_ = false;
};

/// RGBA 32-bit float OpenEXR: R = G = B = height, A = 1 inside the relief and 0 outside.
void write_height_exr(const HeightMap& map, const std::string& path);
/// 16-bit grey + alpha PNG: grey = round((height - offset) / scale), alpha 65535 inside, 0 outside.
/// scale = (max - min) / 65535 (1 / 65535 for a flat map), offset = min.
void write_height_png(const HeightMap& map, const std::string& path, double* scale, double* offset);

struct HeightImage {
  int width = 0, height = 0;
  std::vector<float> values;  ///< row-major from the top row (EXR: R; PNG: the raw 16-bit grey)
  std::vector<float> alpha;   ///< EXR: A; PNG: alpha / 65535
};
/// Reads back an EXR written by write_height_exr (channels R and A). Throws Error.
HeightImage read_height_exr(const std::string& path);
/// Reads back a 16-bit grey + alpha PNG. Throws Error.
HeightImage read_height_png(const std::string& path);

/// A triangle mesh for write_ply: V (#V by 3) in double precision (so unchanged vertices
/// stay bit-identical), T (#T by 3), and named per-vertex float properties.
struct PlyMesh {
  std::vector<Vec3> positions;
  std::vector<int> triangles;  ///< 3 per triangle
  std::vector<std::pair<std::string, std::vector<float>>> vertex_properties;  ///< each #V long
};
/// Binary little-endian PLY ("property double x", "property float height", ...). Throws Error.
void write_ply(const PlyMesh& mesh, const std::string& path);

}  // namespace relief_snake

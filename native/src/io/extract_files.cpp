// write_extraction(): the five files of an extraction (extract.hpp), kept apart from the
// engine so only the CLI and tests link OpenEXR and libpng.
#include <filesystem>
#include <fstream>
#include <system_error>

#include <nlohmann/json.hpp>

#include "relief_snake/error.hpp"
#include "relief_snake/extract.hpp"
#include "relief_snake/extract_io.hpp"

namespace relief_snake {

namespace {

nlohmann::json vec_json(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

ExtractionFiles write_extraction(const Mesh& mesh, const ExtractResult& result, const std::string& directory) {
  namespace fs = std::filesystem;
  if (result.background.base_positions.size() != static_cast<std::size_t>(mesh.n_vertices()))
    throw Error("the extraction does not belong to this mesh");
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (ec || !fs::is_directory(directory))
    throw Error("cannot create the output directory '" + directory + "': " +
                (ec ? ec.message() : std::string("a file of that name exists")));
  ExtractionFiles files;
  const fs::path dir(directory);
  files.background_ply = (dir / "background.ply").string();
  files.relief_ply = (dir / "relief.ply").string();
  files.height_exr = (dir / "height.exr").string();
  files.height_png = (dir / "height.png").string();
  files.height_json = (dir / "height.json").string();

  StagedFiles staged;
  {  // the scan without its relief: the same vertices and faces
    PlyMesh ply;
    ply.positions = result.background_positions(mesh);
    ply.triangles.assign(mesh.face_vertices(), mesh.face_vertices() + 3 * mesh.n_faces());
    write_ply(ply, staged.stage(files.background_ply));
  }
  {  // the relief with its heights and height-map coordinates
    PlyMesh ply;
    ply.triangles = result.relief_triangles;
    std::vector<float> height, u, v;
    for (std::size_t i = 0; i < result.relief_mesh_vertices.size(); ++i) {
      ply.positions.push_back(mesh.to_file(mesh.position(result.relief_mesh_vertices[i])));
      height.push_back(static_cast<float>(result.relief_heights[i]));
      u.push_back(static_cast<float>(result.relief_uv[i].x()));
      v.push_back(static_cast<float>(result.relief_uv[i].y()));
    }
    ply.vertex_properties = {{"height", height}, {"u", u}, {"v", v}};
    write_ply(ply, staged.stage(files.relief_ply));
  }
  const HeightMap& map = result.height_map;
  write_height_exr(map, staged.stage(files.height_exr));
  write_height_png(map, staged.stage(files.height_png), &files.png_scale, &files.png_offset);

  const Flattened& frame = map.frame;
  const Distortion& d = frame.distortion;
  const BackgroundResult& b = result.background;
  const nlohmann::json sidecar = {
      {"units", "mesh units (the scan's own)"},
      {"step_height", result.step_height},
      {"width", map.width},
      {"height", map.height},
      {"pixel_size", map.pixel_size},
      {"u_left", map.u_left},
      {"v_top", map.v_top},
      {"pixel_centre", "u = u_left + (i + 0.5) * pixel_size, v = v_top - (j + 0.5) * pixel_size; i column, j row from the top"},
      {"frame",
       {{"flattening", to_string(frame.method)},
        {"origin", vec_json(frame.origin)},
        {"axis_u", vec_json(frame.axis_u)},
        {"axis_v", vec_json(frame.axis_v)},
        {"normal", vec_json(frame.normal)},
        {"meaning", "plane: a uv point lies at origin + u axis_u + v axis_v; conformal: uv is the flattened base, "
                    "aligned with and scaled to that plane"},
        {"distortion",
         {{"angle_mean", d.angle_mean}, {"angle_max", d.angle_max}, {"area_mean", d.area_mean}, {"area_max", d.area_max},
          {"flipped_faces", d.flipped_faces}}},
        {"note", frame.note}}},
      {"height_range", {map.min_height, map.max_height}},
      {"covered_pixels", map.covered_pixels()},
      {"exr", {{"file", "height.exr"}, {"channels", "R = G = B = height (32-bit float), A = 1 inside the relief, 0 outside"}}},
      {"png",
       {{"file", "height.png"},
        {"bits", 16},
        {"scale", files.png_scale},
        {"offset", files.png_offset},
        {"formula", "height = offset + value * scale (grey channel); alpha 65535 inside the relief, 0 outside"}}},
      {"background",
       {{"region_vertices", b.region_vertices.size()},
        {"ring_vertices", b.ring_vertices.size()},
        {"ring_rms_residual", b.ring_rms_residual},
        {"ring_max_residual", b.ring_max_residual}}},
      {"meshes",
       {{"background", "background.ply: the scan's mesh vertices in order, the relief's moved onto the base"},
        {"relief", "relief.ply: the faces touching the relief, per-vertex float height, u, v"}}},
      {"notes", result.notes}};
  {
    const std::string path = staged.stage(files.height_json);
    std::ofstream out(path, std::ios::binary);
    if (!out) throw Error("cannot write '" + path + "'; check the directory is writable");
    out << sidecar.dump(2) << "\n";
    out.close();
    if (!out) throw Error("writing '" + path + "' failed; check the free disk space");
  }
  staged.commit();
  return files;
}

}  // namespace relief_snake

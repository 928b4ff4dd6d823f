// Extraction end to end on generated scans: meshes, height map, files read back.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "extraction_truth.hpp"
#include "relief_snake/error.hpp"
#include "relief_snake/extract.hpp"
#include "relief_snake/extract_io.hpp"
#include "synthetic.hpp"
#include "test_meshes.hpp"

namespace relief_snake {
namespace {

namespace fs = std::filesystem;
using synthetic::Background;

synthetic::Scan duck(Background background, std::size_t triangles = 30000) {
  synthetic::ScanSpec spec;
  spec.background = background;
  spec.triangles = triangles;
  spec.seed = 5;
  return synthetic::generate(spec);
}

std::vector<char> truth_region(const synthetic::Scan& scan) { return {scan.relief.begin(), scan.relief.end()}; }

fs::path fresh_directory(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("relief_snake_test_extract_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

TEST(Extract, FlatteningFollowsTheBackground) {
  for (const Background background : {Background::Plane, Background::Cylinder, Background::Sphere, Background::Saddle}) {
    const synthetic::Scan scan = duck(background);
    const Mesh mesh = synthetic::to_mesh(scan);
    const ExtractResult x = extract(mesh, truth_region(scan), scan.h);
    const Distortion& d = x.height_map.frame.distortion;
    std::printf("[ measured ] %s: %s, angle distortion mean %.4f max %.4f, area mean %.4f max %.4f, %d x %d px, %.3f + %.3f s\n",
                synthetic::to_string(background), to_string(x.height_map.frame.method), d.angle_mean, d.angle_max,
                d.area_mean, d.area_max, x.height_map.width, x.height_map.height, x.background_seconds,
                x.height_map_seconds);
    EXPECT_EQ(x.height_map.frame.method, background == Background::Plane ? Flattening::Plane : Flattening::Conformal);
    EXPECT_EQ(d.flipped_faces, 0);
    EXPECT_LT(d.angle_mean, 0.05);
    // The map's interior reads h (the relief's top) and its pixel size is half an edge.
    EXPECT_NEAR(x.height_map.pixel_size, 0.5 * mesh.average_edge_length(), 1e-12);
    EXPECT_NEAR(x.height_map.max_height, scan.h, 0.1 * scan.h);
    EXPECT_GT(x.height_map.covered_pixels(), 1000u);
  }
}

TEST(Extract, ConformalMapKeepsLengthsOnACylinder) {
  // A cylinder unrolls isometrically: the conformal map's scale is the surface's.
  const synthetic::Scan scan = duck(Background::Cylinder);
  const Mesh mesh = synthetic::to_mesh(scan);
  ExtractOptions options;
  options.height_map.flattening = Flattening::Conformal;
  const ExtractResult x = extract(mesh, truth_region(scan), scan.h, options);
  EXPECT_LT(x.height_map.frame.distortion.area_mean, 0.02);
  // Distances in the map are those in the unrolled cylinder (the scan's u, v), not chords.
  const std::size_t n = x.relief_mesh_vertices.size();
  double worst = 0;
  for (std::size_t i = 0; i < n; i += 37) {
    const std::size_t j = (i * 7919 + n / 2) % n;
    const int a = x.relief_mesh_vertices[i], b = x.relief_mesh_vertices[j];
    const double truth = std::hypot(scan.UV[2 * a] - scan.UV[2 * b], scan.UV[2 * a + 1] - scan.UV[2 * b + 1]);
    if (truth < 10) continue;
    worst = std::max(worst, std::abs((x.relief_uv[i] - x.relief_uv[j]).norm() / truth - 1));
  }
  std::printf("[ measured ] cylinder conformal: worst relative distance error %.4f\n", worst);
  EXPECT_LT(worst, 0.01);
}

/// Vertex positions of a binary PLY written by write_ply (double x, y, z first).
std::vector<Vec3> read_ply_positions(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::size_t count = 0, properties = 0;
  bool in_vertex = false;
  while (std::getline(in, line) && line != "end_header") {
    if (line.rfind("element vertex ", 0) == 0) {
      count = std::stoul(line.substr(15));
      in_vertex = true;
    } else if (line.rfind("element", 0) == 0) {
      in_vertex = false;
    } else if (in_vertex && line.rfind("property float", 0) == 0) {
      ++properties;
    }
  }
  std::vector<Vec3> positions(count);
  std::vector<char> record(24 + 4 * properties);
  for (Vec3& p : positions) {
    in.read(record.data(), static_cast<std::streamsize>(record.size()));
    std::memcpy(p.data(), record.data(), 24);
  }
  return in ? positions : std::vector<Vec3>{};
}

TEST(Extract, FilesReadBackWithTheSidecarsScale) {
  const synthetic::Scan scan = duck(Background::Sphere, 20000);
  const Mesh mesh = synthetic::to_mesh(scan);
  const ExtractResult x = extract(mesh, truth_region(scan), scan.h);
  const fs::path dir = fresh_directory("files");
  const ExtractionFiles files = write_extraction(mesh, x, dir.string());
  for (const char* name : {"background.ply", "relief.ply", "height.exr", "height.png", "height.json"})
    EXPECT_TRUE(fs::exists(dir / name)) << name;
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find("partial"), std::string::npos) << entry.path();

  std::ifstream in(dir / "height.json");
  const nlohmann::json sidecar = nlohmann::json::parse(in);
  const HeightMap& map = x.height_map;
  EXPECT_EQ(sidecar["width"], map.width);
  EXPECT_EQ(sidecar["height"], map.height);
  EXPECT_DOUBLE_EQ(sidecar["pixel_size"].get<double>(), map.pixel_size);
  const double scale = sidecar["png"]["scale"], offset = sidecar["png"]["offset"];

  const HeightImage exr = read_height_exr(files.height_exr);
  const HeightImage png = read_height_png(files.height_png);
  ASSERT_EQ(exr.width, map.width);
  ASSERT_EQ(png.height, map.height);
  std::size_t inside = 0;
  double worst_exr = 0, worst_png = 0;
  for (std::size_t k = 0; k < map.values.size(); ++k) {
    EXPECT_EQ(exr.alpha[k], map.mask[k] ? 1.0f : 0.0f);
    EXPECT_EQ(png.alpha[k], map.mask[k] ? 1.0f : 0.0f);
    if (!map.mask[k]) continue;
    ++inside;
    worst_exr = std::max(worst_exr, std::abs(static_cast<double>(exr.values[k]) - map.values[k]));
    worst_png = std::max(worst_png, std::abs(offset + png.values[k] * scale - map.values[k]));
  }
  EXPECT_GT(inside, 1000u);
  EXPECT_EQ(worst_exr, 0.0);               // 32-bit float: exact
  EXPECT_LE(worst_png, 0.5 * scale + 1e-7);  // 16 bits: half a step
  EXPECT_LT(scale, scan.h / 10000);        // no visible stepping

  // background.ply: the same vertices in the same order; outside the relief bit for bit.
  const Mesh background = Mesh::load(files.background_ply);
  ASSERT_EQ(background.n_vertices(), mesh.n_vertices());
  ASSERT_EQ(background.n_faces(), mesh.n_faces());
  const std::vector<Vec3> written = read_ply_positions(files.background_ply);  // OpenMesh reads floats
  ASSERT_EQ(written.size(), static_cast<std::size_t>(mesh.n_vertices()));
  std::size_t moved = 0, changed_outside = 0, off_base = 0;
  for (int v = 0; v < mesh.n_vertices(); ++v) {
    if (x.background.region[v]) {
      moved += written[v] != mesh.position(v);
      off_base += test::distance_to_background(scan, written[v]) > 0.1 * scan.h;
    } else {
      changed_outside += written[v] != mesh.position(v);
    }
  }
  EXPECT_EQ(changed_outside, 0u);
  EXPECT_EQ(off_base, 0u);
  EXPECT_GT(moved, x.background.region_vertices.size() / 2);
  const Mesh relief = Mesh::load(files.relief_ply);
  EXPECT_EQ(relief.n_vertices(), static_cast<int>(x.relief_mesh_vertices.size()));
  EXPECT_EQ(relief.n_faces(), static_cast<int>(x.relief_triangles.size() / 3));
  // The PLY header declares the height property.
  std::ifstream ply(files.relief_ply, std::ios::binary);
  std::string header((std::istreambuf_iterator<char>(ply)), std::istreambuf_iterator<char>());
  header = header.substr(0, header.find("end_header"));
  EXPECT_NE(header.find("property float height"), std::string::npos);
  fs::remove_all(dir);
}

TEST(Extract, AResultForAnotherMeshIsRefused) {
  const Mesh mesh = test::plane_mesh(11, 10);
  std::vector<std::string> notes;
  try {
    region_from_input_indices(mesh, {1, 2, 3}, mesh.n_vertices() + 5, &notes);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("vertices but this mesh has"), std::string::npos) << e.what();
  }
  try {
    region_from_input_indices(mesh, {1, 2, 500}, -1, &notes);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos) << e.what();
  }
  EXPECT_THROW(region_from_input_indices(mesh, {}, -1, &notes), Error);
  const std::vector<char> all(static_cast<std::size_t>(mesh.n_vertices()), 1);
  try {
    extract(mesh, all, 1.0);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no background"), std::string::npos) << e.what();
  }
}

TEST(Extract, NothingIsLeftWhenWritingFails) {
  const synthetic::Scan scan = duck(Background::Plane, 10000);
  const Mesh mesh = synthetic::to_mesh(scan);
  const ExtractResult x = extract(mesh, truth_region(scan), scan.h);
  const fs::path dir = fresh_directory("fail");
  fs::create_directories(dir);
  fs::create_directory(dir / "height.json");  // the last rename cannot replace a directory
  EXPECT_THROW(write_extraction(mesh, x, dir.string()), Error);
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    ++files;
    EXPECT_EQ(entry.path().filename().string().find("partial"), std::string::npos) << entry.path();
  }
  EXPECT_LE(files, 5u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace relief_snake

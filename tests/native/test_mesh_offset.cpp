// Double precision end to end (issue 11): a scan moved by +1e6 in x, y and z (georeferenced
// coordinates), written as a binary double PLY and read back, keeps every vertex distinct
// and segments like the scan at the origin; the contour comes back in file coordinates.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "relief_snake/mesh.hpp"
#include "relief_snake/mesh_io.hpp"
#include "relief_snake/segment.hpp"
#include "synthetic.hpp"

namespace rs = relief_snake;
namespace syn = relief_snake::synthetic;

namespace {

std::string double_ply(const syn::Scan& scan, double offset) {
  std::string out = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(scan.n_vertices()) +
                    "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
                    std::to_string(scan.n_faces()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (double x : scan.V) {
    const double shifted = x + offset;
    out.append(reinterpret_cast<const char*>(&shifted), sizeof shifted);
  }
  for (std::size_t f = 0; f < scan.n_faces(); ++f) {
    out.push_back(3);
    for (int k = 0; k < 3; ++k) {
      const auto i = static_cast<std::int32_t>(scan.F[3 * f + k]);
      out.append(reinterpret_cast<const char*>(&i), sizeof i);
    }
  }
  return out;
}

}  // namespace

TEST(MeshOffset, GeoreferencedScanSegmentsLikeTheOriginal) {
  syn::ScanSpec spec;  // the end-to-end suite's default case (test_segment.cpp)
  spec.shape = syn::Shape::Disk;
  spec.step = syn::Step::Blended;
  spec.triangles = 60000;
  const syn::Scan scan = syn::generate(spec);
  const syn::Picks picks = scan.picks();
  rs::Options options;
  options.step_height = scan.h;
  options.threads = 1;

  const double offset = std::getenv("RELIEF_SNAKE_TEST_OFFSET") ? std::atof(std::getenv("RELIEF_SNAKE_TEST_OFFSET")) : 1e6;
  const std::string bytes = double_ply(scan, offset);
  const rs::PolygonSoup soup = rs::read_mesh_bytes(bytes.data(), bytes.size(), rs::MeshFormat::Ply);
  const rs::Mesh shifted = rs::Mesh::from_soup(soup);
  const rs::Mesh original = syn::to_mesh(scan);
  // Nothing merged: in float32 the grid's ~0.5 spacing at 1e6 rounds to 0.0625 steps and jittered
  // vertices collide ("pick N is repeated").
  ASSERT_EQ(shifted.n_vertices(), original.n_vertices());
  EXPECT_EQ(shifted.report().duplicate_vertices_merged, 0u);
  EXPECT_NEAR(shifted.average_edge_length(), original.average_edge_length(), 1e-9 * original.average_edge_length());

  const rs::Result a = rs::segment(original, picks.vertices, options);
  ASSERT_EQ(a.status, rs::Status::Converged);
  const syn::Score sa = syn::score(syn::Polyline{a.polyline, a.closed}, a.relief_vertices, scan);
  ASSERT_GE(sa.iou, 0.95);

  // In file coordinates: doubles keep the detail at 1e6 (in float32 the scan merged and broke).
  const rs::Result raw = rs::segment(shifted, picks.vertices, options);
  EXPECT_EQ(raw.status, a.status);
  std::vector<rs::Vec3> raw_back;
  for (const rs::Vec3& p : raw.polyline) raw_back.push_back(p - rs::Vec3::Constant(offset));
  const syn::Score sr = syn::score(syn::Polyline{raw_back, raw.closed}, raw.relief_vertices, scan);
  RecordProperty("iou_original", std::to_string(sa.iou));
  RecordProperty("iou_file_coordinates", std::to_string(sr.iou));
  EXPECT_NEAR(sr.iou, sa.iou, 0.01);
  EXPECT_NEAR(sr.mean_to_truth, sa.mean_to_truth, 0.05);

  // With the local origin (IoU within 0.005 and the region identical, measured).
  rs::IntakeOptions local;
  local.local_origin = true;
  const rs::Mesh centred = rs::Mesh::from_soup(soup, local);
  EXPECT_GT(centred.origin().x(), offset - 50);
  EXPECT_LT(centred.position(0).norm(), 100.0);
  EXPECT_EQ(centred.n_vertices(), original.n_vertices());
  const rs::Result b = rs::segment(centred, picks.vertices, options);
  EXPECT_EQ(b.status, a.status);
  // Back to file coordinates (origin() added), then to the scan's for scoring.
  std::vector<rs::Vec3> back;
  for (const rs::Vec3& p : b.polyline) back.push_back(p + centred.origin() - rs::Vec3::Constant(offset));
  const syn::Score sb = syn::score(syn::Polyline{back, b.closed}, b.relief_vertices, scan);
  EXPECT_GE(sb.iou, 0.95);
  EXPECT_NEAR(sb.iou, sa.iou, 0.005);
  EXPECT_NEAR(sb.mean_to_truth, sa.mean_to_truth, 0.05);
  std::size_t common = 0;
  for (std::int64_t v : b.relief_vertices)
    common += std::binary_search(a.relief_vertices.begin(), a.relief_vertices.end(), v) ? 1 : 0;
  EXPECT_GE(common, a.relief_vertices.size() * 99 / 100);
  RecordProperty("identical_region_local_origin", a.relief_vertices == b.relief_vertices ? "yes" : "no");
  RecordProperty("identical_region_file_coordinates", a.relief_vertices == raw.relief_vertices ? "yes" : "no");
}

// Double precision end to end (issue 11): a scan moved by +1e6 in x, y and z (georeferenced
// coordinates), written as a binary double PLY and read back, keeps every vertex distinct
// and segments like the scan at the origin; the contour comes back in file coordinates.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "relief_snake/extract.hpp"
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

namespace {

// The largest distance between corresponding points of two polylines (of the same length), the
// second moved by -shift.
double max_gap(const std::vector<rs::Vec3>& a, const std::vector<rs::Vec3>& b, const rs::Vec3& shift) {
  double gap = 0;
  for (std::size_t k = 0; k < a.size() && k < b.size(); ++k) gap = std::max(gap, (b[k] - shift - a[k]).norm());
  return gap;
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
  const rs::Vec3 shift = rs::Vec3::Constant(offset);
  const std::string bytes = double_ply(scan, offset);
  const rs::PolygonSoup soup = rs::read_mesh_bytes(bytes.data(), bytes.size(), rs::MeshFormat::Ply);
  const rs::Mesh shifted = rs::Mesh::from_soup(soup);  // LocalOrigin::Auto
  const rs::Mesh original = syn::to_mesh(scan);
  // Nothing merged: in float32 the grid's ~0.5 spacing at 1e6 rounds to 0.0625 steps and jittered
  // vertices collide ("pick N is repeated").
  ASSERT_EQ(shifted.n_vertices(), original.n_vertices());
  EXPECT_EQ(shifted.report().duplicate_vertices_merged, 0u);
  EXPECT_NEAR(shifted.average_edge_length(), original.average_edge_length(), 1e-9 * original.average_edge_length());

  // Auto: the scan around the origin keeps the file's coordinates; the moved one is measured from
  // its bounding-box centre, exactly: every vertex comes back to the file's value bit for bit.
  EXPECT_EQ(original.origin(), rs::Vec3::Zero());
  EXPECT_GT(shifted.origin().minCoeff(), offset - 50);
  EXPECT_LT(shifted.position(0).norm(), 100.0);
  std::size_t exact = 0;
  for (int v = 0; v < shifted.n_vertices(); ++v) {
    const std::size_t i = shifted.mesh_to_input(v);
    const rs::Vec3 file(soup.positions[3 * i], soup.positions[3 * i + 1], soup.positions[3 * i + 2]);
    exact += shifted.to_file(shifted.position(v)) == file ? 1 : 0;
  }
  EXPECT_EQ(exact, static_cast<std::size_t>(shifted.n_vertices()));

  const rs::Result a = rs::segment(original, picks.vertices, options);
  ASSERT_EQ(a.status, rs::Status::Converged);
  const syn::Score sa = syn::score(syn::Polyline{a.polyline, a.closed}, a.relief_vertices, scan);
  ASSERT_GE(sa.iou, 0.95);

  // Relative to the local origin the engine sees the scan at the origin, translated by the original's
  // own bounding-box centre (0, 0, 0.5) and up to the file's rounding at 1e6 (half an ulp, 6e-11, a
  // billionth of an edge). The snake's choices are discrete (candidate positions, locks, splits), so
  // such rounding moves a few snaxels by a movement step (tau l: 0.1 edge in refinement): the
  // translation alone, without the file's rounding, moves 4 of 348 by 0.002 edges. So: the same
  // region, the same snaxel count, at least 95% of the contour within 1e-6 edges of the original's
  // + offset (measured: 342 of 348) and every point within half an edge (measured: 0.12).
  const rs::Result b = rs::segment(shifted, picks.vertices, options);
  EXPECT_EQ(b.status, a.status);
  EXPECT_EQ(b.relief_vertices, a.relief_vertices);
  ASSERT_EQ(b.polyline.size(), a.polyline.size());
  const double edge = original.average_edge_length();
  const double gap = max_gap(a.polyline, b.polyline, shift);
  std::size_t apart = 0;
  for (std::size_t k = 0; k < a.polyline.size(); ++k) apart += (b.polyline[k] - shift - a.polyline[k]).norm() > 1e-6 * edge;
  EXPECT_LE(apart, a.polyline.size() / 20);
  EXPECT_LT(gap, 0.5 * edge);
  RecordProperty("max_contour_gap_in_edges", std::to_string(gap / edge));
  RecordProperty("contour_points_apart", std::to_string(apart) + " of " + std::to_string(a.polyline.size()));
  // The progress callback's contours are in file coordinates too.
  double progress_far = 0;
  (void)rs::segment(shifted, picks.vertices, options, [&](const rs::Progress& p) {
    for (const rs::Vec3& q : p.contour()) progress_far = std::max(progress_far, (q - shift).norm());
    return true;
  });
  EXPECT_GT(progress_far, 1.0);  // contours were seen
  EXPECT_LT(progress_far, original.bbox_diagonal());  // and near the scan in file coordinates

  // Without the local origin (LocalOrigin::Off) doubles still segment like the original at 1e6,
  // in file coordinates (the plane fits' sums of squares lose a few digits).
  rs::IntakeOptions off;
  off.local_origin = rs::LocalOrigin::Off;
  const rs::Mesh raw_mesh = rs::Mesh::from_soup(soup, off);
  EXPECT_EQ(raw_mesh.origin(), rs::Vec3::Zero());
  const rs::Result raw = rs::segment(raw_mesh, picks.vertices, options);
  EXPECT_EQ(raw.status, a.status);
  std::vector<rs::Vec3> raw_back;
  for (const rs::Vec3& p : raw.polyline) raw_back.push_back(p - shift);
  const syn::Score sr = syn::score(syn::Polyline{raw_back, raw.closed}, raw.relief_vertices, scan);
  RecordProperty("iou_original", std::to_string(sa.iou));
  RecordProperty("iou_file_coordinates", std::to_string(sr.iou));
  EXPECT_NEAR(sr.iou, sa.iou, 0.01);
  EXPECT_NEAR(sr.mean_to_truth, sa.mean_to_truth, 0.05);
}

TEST(MeshOffset, ExtractionOfAMovedScanIsInFileCoordinates) {
  syn::ScanSpec spec;
  spec.shape = syn::Shape::Disk;
  spec.triangles = 20000;
  const syn::Scan scan = syn::generate(spec);
  const double offset = 1e6;
  const rs::Vec3 shift = rs::Vec3::Constant(offset);
  const std::string bytes = double_ply(scan, offset);
  const rs::Mesh shifted = rs::Mesh::from_soup(rs::read_mesh_bytes(bytes.data(), bytes.size(), rs::MeshFormat::Ply));
  const rs::Mesh original = syn::to_mesh(scan);
  ASSERT_NE(shifted.origin(), rs::Vec3::Zero());
  std::vector<char> region(original.n_vertices(), 0);
  for (const std::int64_t i : scan.relief_vertices()) region[original.input_to_mesh(static_cast<std::size_t>(i))] = 1;
  std::vector<char> region_shifted(shifted.n_vertices(), 0);
  for (const std::int64_t i : scan.relief_vertices()) region_shifted[shifted.input_to_mesh(static_cast<std::size_t>(i))] = 1;
  const rs::ExtractResult a = rs::extract(original, region, scan.h);
  const rs::ExtractResult b = rs::extract(shifted, region_shifted, scan.h);
  // The same solve up to the file's rounding at 1e6 (6e-11): positions within 1e-6 edges, heights
  // and the map within 1e-6 h.
  const double edge = original.average_edge_length();
  const std::vector<rs::Vec3> pa = a.background_positions(original), pb = b.background_positions(shifted);
  ASSERT_EQ(pa.size(), pb.size());
  EXPECT_LT(max_gap(pa, pb, shift), 1e-6 * edge);
  EXPECT_LT((b.height_map.frame.origin - shift - a.height_map.frame.origin).norm(), 1e-6 * edge);
  ASSERT_EQ(a.relief_heights.size(), b.relief_heights.size());
  for (std::size_t i = 0; i < a.relief_heights.size(); ++i) ASSERT_NEAR(a.relief_heights[i], b.relief_heights[i], 1e-6 * scan.h);
  ASSERT_EQ(a.height_map.values.size(), b.height_map.values.size());
  for (std::size_t i = 0; i < a.height_map.values.size(); ++i)
    ASSERT_NEAR(a.height_map.values[i], b.height_map.values[i], 1e-6 * scan.h);
}

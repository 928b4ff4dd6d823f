#pragma once
// Synthetic scans with exact ground truth: a relief silhouette lifted by a step of
// height h above a smooth background, on an irregular triangulation, plus the true
// boundary, suggested picks and a scorer. Used by the engine's end-to-end tests, the
// make-scan tool (Python/Blender tests, demo) and the benchmark.
//
// Geometry is in absolute units ("mm"): the parameter domain is u in [-width/2, width/2],
// v in [-height/2, height/2]; silhouettes have fixed sizes in those units (the duck is
// about 38 x 27), so changing h changes the step, not the outline. A surface point is
// background(u, v) + height(u, v) * background_normal(u, v): the step is measured along
// the normal. Seen from the +normal side, +u points right and +v up (right-handed).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "relief_snake/mesh.hpp"
#include "relief_snake/segment.hpp"

namespace relief_snake {
namespace synthetic {

enum class Shape {
  Duck,       ///< body + head + beak + tail; deep concavity (about 3.5..8 wide, 10 deep) under the beak
  Disk,       ///< radius 12
  Rectangle,  ///< 32 x 20, sharp corners
  Slots,      ///< 48 x 18 rectangle with one slot per ScanSpec::slot_widths cut into its top edge
  Open,       ///< union of two disks clipped by the right edge of the domain: an open boundary
};
enum class Background {
  Plane,     ///< z = 0
  Cylinder,  ///< axis along v, radius R (u is arc length): zero Gaussian curvature
  Sphere,    ///< radius R (u, v = R * longitude, R * latitude): positive Gaussian curvature
  Saddle,    ///< z = (u^2 - v^2) / (2R): negative Gaussian curvature
};
enum class Step {
  Sharp,    ///< height h if sd < 0 else 0, per vertex: the step falls across one triangle
  Blended,  ///< smoothstep from 0 at sd = 0 to h at sd = -blend_width * h
};
enum class Start {
  Near,    ///< ring on the level set sd = distance
  Far,     ///< ring on the level set sd = far distance (as far as the domain allows)
  Zigzag,  ///< alternating between the near and far level sets
};

/// Parse/print the enums by their lower-case names ("duck", "saddle", "blended", "zigzag").
/// parse_* throw Error on an unknown name.
Shape parse_shape(const std::string& name);
Background parse_background(const std::string& name);
Step parse_step(const std::string& name);
Start parse_start(const std::string& name);
const char* to_string(Shape shape);
const char* to_string(Background background);
const char* to_string(Step step);
const char* to_string(Start start);

struct ScanSpec {
  Shape shape = Shape::Duck;
  Background background = Background::Plane;
  std::size_t triangles = 100000;  ///< target triangle count (10k .. 2M); the result is within 1%
  double h = 1.0;                  ///< step height
  double width = 80, height = 56;  ///< parameter domain size
  double radius = 40;              ///< R for cylinder, sphere and saddle
  Step step = Step::Sharp;
  double blend_width = 0.5;        ///< Blended: width of the rising profile, in units of h
  double detail = 0;               ///< amplitude of bumps on the relief top, fraction of h (0: none);
                                   ///< they fade out within 3 h of the boundary
  bool drop = false;               ///< the relief rises by h at the boundary, then falls to 0.3 h
                                   ///< within 1.5 h inside
  double noise = 0;                ///< Gaussian displacement along the normal, sigma as a fraction of h
  double jitter = 0.3;             ///< vertex jitter, fraction of the grid spacing (< 0.35)
  std::vector<double> slot_widths = {3, 5, 8, 12};  ///< Slots: mouth widths, in nominal average edges
  double slot_depth = 5;           ///< Slots: depth of every slot, in units of h
  std::uint64_t seed = 1;          ///< same spec and seed: bit-identical scan
};

/// A 3D polyline; a closed one does not repeat its first point at the end.
struct Polyline {
  std::vector<Vec3> points;
  bool closed = true;
};

struct PickSpec {
  Start start = Start::Near;
  int count = 8;          ///< picks on the ring (open case: including both ends); more are inserted
                          ///< where a straight chord between two picks would come closer to the
                          ///< relief than half the near distance
  double distance = 3;    ///< near distance from the relief, in units of h
  double far_distance = 0;  ///< far distance in units of h; <= 0: as far as the domain allows
  bool reverse = false;   ///< reverse the pick order (the relief side flips)
};

/// Picks are mesh vertex indices (the same as input indices: Scan vertices are never merged).
struct Picks {
  std::vector<std::int64_t> vertices;
  bool closed = true;
  /// Side of the relief seen from outside (background normal towards the viewer) along the
  /// pick order. Closed rings are counter-clockwise unless reversed: relief on the Left.
  ReliefSide relief_side = ReliefSide::Left;
  double near_distance = 0, far_distance = 0;  ///< the level sets used, absolute units
};

/// A generated scan. V, F are ready for Mesh::from_triangles (see to_mesh()).
struct Scan {
  ScanSpec spec;
  std::vector<double> V;        ///< #V by 3, row-major
  std::vector<std::int64_t> F;  ///< #F by 3, counter-clockwise seen from the +normal side
  std::vector<double> UV;       ///< #V by 2: parameter coordinates of each vertex
  std::vector<std::uint8_t> relief;  ///< #V: 1 where sd(u, v) < 0
  std::vector<Polyline> boundary;    ///< true boundary at the foot of the step (height 0), dense
                                     ///< (spacing <= average_edge / 8); relief on the left
  double h = 1;
  double average_edge = 0;     ///< mean length of the unique 3D mesh edges
  double nominal_edge = 0;     ///< mean length of the unique edges in the (u, v) plane
  double spacing_u = 0, spacing_v = 0;  ///< grid spacing
  int grid_u = 0, grid_v = 0;  ///< vertices per row / column: vertex (i, j) has index j * grid_u + i
  bool open = false;           ///< the boundary ends on the mesh boundary
  std::vector<double> slots;   ///< Slots: (center u, width) pairs of the cut slots, absolute units

  std::size_t n_vertices() const { return V.size() / 3; }
  std::size_t n_faces() const { return F.size() / 3; }
  Vec3 vertex(std::size_t v) const { return Vec3(V[3 * v], V[3 * v + 1], V[3 * v + 2]); }
  std::vector<std::int64_t> relief_vertices() const;  ///< sorted indices with relief == 1
  double relief_fraction() const;

  /// The silhouette's signed distance (negative inside; exact outside, a 1-Lipschitz bound inside).
  double signed_distance(double u, double v) const;
  /// background(u, v) + height * background_normal(u, v).
  Vec3 surface(double u, double v, double height = 0) const;
  Vec3 background_normal(double u, double v) const;
  /// Nearest mesh vertex to (u, v) in the parameter plane.
  int nearest_vertex(double u, double v) const;

  /// Suggested picks; throws Error if the requested ring does not fit in the domain.
  Picks picks(const PickSpec& pick_spec = {}) const;
};

/// Generates a scan. Throws Error on bad parameters. Deterministic for a spec.
Scan generate(const ScanSpec& spec);

/// The engine mesh of a scan (inline, so the synthetic library does not need mesh.cpp).
inline Mesh to_mesh(const Scan& scan) {
  return Mesh::from_triangles(scan.V.data(), scan.n_vertices(), scan.F.data(), scan.n_faces());
}

// --- scoring -------------------------------------------------------------------------

/// Fast distance from points to a set of polylines (uniform hash grid of segments).
class PolylineDistance {
 public:
  /// cell: grid cell size; <= 0: the mean segment length times 2.
  explicit PolylineDistance(const std::vector<Polyline>& polylines, double cell = 0);
  double operator()(const Vec3& p) const;
  bool empty() const { return segments_.empty(); }

 private:
  std::vector<std::pair<Vec3, Vec3>> segments_;
  double cell_ = 1;
  std::vector<std::int64_t> keys_;   // sorted cell keys, one per (cell, segment) entry
  std::vector<int> entries_;         // segment index, parallel to keys_
  Vec3 origin_ = Vec3::Zero();
  int max_ring_ = 0;
};

/// Points along a polyline at arc-length spacing <= step (ends and corners kept).
std::vector<Vec3> resample(const Polyline& polyline, double step);

struct Score {
  double iou = 0;                 ///< |A and B| / |A or B| of relief vertex sets (1 if both empty)
  std::size_t result_vertices = 0, truth_vertices = 0, common_vertices = 0;
  /// Distances from the contour (resampled every average_edge / 4) to the truth boundary,
  /// and back, in average edges.
  double mean_to_truth = 0, p95_to_truth = 0, max_to_truth = 0;
  double mean_from_truth = 0, p95_from_truth = 0, max_from_truth = 0;
};

/// Scores a segmentation against the truth. contour: the result's 3D polyline;
/// relief_vertices: the result's vertex indices. Throws Error on an empty contour.
Score score(const Polyline& contour, const std::vector<std::int64_t>& relief_vertices,
            const std::vector<Polyline>& truth_boundary, const std::vector<std::int64_t>& truth_relief,
            double average_edge);
inline Score score(const Polyline& contour, const std::vector<std::int64_t>& relief_vertices, const Scan& truth) {
  return score(contour, relief_vertices, truth.boundary, truth.relief_vertices(), truth.average_edge);
}

// --- files ---------------------------------------------------------------------------

/// Binary little-endian PLY (float coordinates, int indices). Throws Error if unwritable.
void write_ply(const Scan& scan, const std::string& path);
/// Wavefront OBJ (full double precision).
void write_obj(const Scan& scan, const std::string& path);
/// Truth JSON: {h, average_edge, triangles, vertices, relief_vertices, boundary (list of
/// polylines, each a list of [x, y, z]), boundary_closed, picks, picks_closed, open,
/// relief_side ("left"/"right"), spec {...}}.
void write_truth_json(const Scan& scan, const Picks& picks, const std::string& path);

}  // namespace synthetic
}  // namespace relief_snake

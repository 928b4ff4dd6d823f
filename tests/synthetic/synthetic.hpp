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

#include <nlohmann/json.hpp>

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
  // The random family's shapes (ScanSpec::shape_params sizes them; make-scan --random draws them):
  Gear,       ///< disk of radius gear_radius with radial slots (mouths ScanSpec::slot_widths, in nominal edges)
  CShape,     ///< ring (c_radius, c_half_thickness) with a gap of c_gap_width cut through it
  Ellipse,    ///< ellipse with semi-axes ellipse_a, ellipse_b
  RoundedBox, ///< box of half sizes box_half_u, box_half_v with corners rounded by box_corner
  Letter,     ///< block letter `letter` (L, T, E, H, U) of half sizes letter_half_u/v, strokes stroke_width wide
  Band,       ///< band of half width band_half_width along an arc entering from a domain edge (open boundary)
  // Reliefs with inner holes (hole_scans.cpp):
  Ring,         ///< annulus of centre radius c_radius and half thickness c_half_thickness: one hole
  HoledLetter,  ///< block letter `letter` with counters (O, D, A, B), half sizes letter_half_u/v, strokes stroke_width
};
enum class Background {
  Plane,     ///< z = 0
  Cylinder,  ///< axis along v, radius R (u is arc length): zero Gaussian curvature
  Sphere,    ///< radius R (u, v = R * longitude, R * latitude): positive Gaussian curvature
  Saddle,    ///< z = (u^2 - v^2) / (2R): negative Gaussian curvature
  Vase,      ///< surface of revolution about v: radius R (1 + vase_amplitude sin(2 pi v / vase_period + vase_phase)),
             ///< angle u / R
  Wavy,      ///< z = wavy_amplitude sin(2 pi u / wavy_period_u + phase) cos(2 pi v / wavy_period_v)
};
enum class Texture {
  None,
  Striations,  ///< texture_amplitude h sin(2 pi s / (texture_period h)), s along texture_angle
  Dots,        ///< bumps of radius dot_radius h (sign: texture_amplitude) on a jittered lattice of texture_period h
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
struct ScanSpec;
/// Signed distance of the shapes with holes (Ring, HoledLetter; hole_scans.cpp), in the shape's frame.
double holed_shape_distance(const ScanSpec& spec, double u, double v);
Background parse_background(const std::string& name);
Step parse_step(const std::string& name);
Start parse_start(const std::string& name);
Texture parse_texture(const std::string& name);
const char* to_string(Shape shape);
const char* to_string(Texture texture);
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

  // --- the random family's axes (make-scan --random). Their defaults change nothing: a spec that
  // leaves them alone generates exactly the scan it generated before they existed.
  double shape_rotation = 0;       ///< radians, counter-clockwise, about shape_center (closed shapes)
  double shape_center_u = 0, shape_center_v = 0;
  double gear_radius = 14, gear_slot_depth = 4;      ///< Gear: radius, slot depth (absolute units)
  double c_radius = 13, c_half_thickness = 4, c_gap_width = 4, c_gap_angle = 0;  ///< CShape (absolute)
  double ellipse_a = 15, ellipse_b = 10;             ///< Ellipse semi-axes
  double box_half_u = 14, box_half_v = 9, box_corner = 0;  ///< RoundedBox
  char letter = 'E';                                 ///< Letter: one of L T E H U
  double letter_half_u = 13, letter_half_v = 17, stroke_width = 7;
  int band_edge = 0;               ///< Band: entering through the left (0), right (1), bottom (2), top (3) edge
  double band_offset = 0;          ///< Band: entry point along that edge (absolute, from its middle)
  double band_angle = 0;           ///< Band: direction at entry, radians from the inward normal
  double band_length = 35, band_curvature = 0, band_half_width = 6;  ///< Band centreline length inside, 1/radius
  double vase_amplitude = 0.1, vase_period = 60, vase_phase = 0;     ///< Vase (amplitude: fraction of R)
  double wavy_amplitude = 1.5, wavy_period_u = 40, wavy_period_v = 50, wavy_phase = 0;  ///< Wavy
  Texture texture = Texture::None;
  double texture_amplitude = 0.2;  ///< fraction of h; Dots: negative = stamped in, positive = raised
  double texture_period = 2;       ///< in h
  double texture_angle = 0;        ///< Striations: direction across the ridges, radians
  double dot_radius = 0.6;         ///< Dots: in h
  double dome = 0;                 ///< relief top rises by dome h towards the middle (0: none)
  double dome_width = 5;           ///< ... reaching it dome_width h inside the edge
  double grooves = 0;              ///< depth of straight grooves across the relief, fraction of h (0: none)
  double groove_spacing = 4, groove_width = 0.3, groove_angle = 0;  ///< in h, in h (sigma), radians
  double edge_groove = 0;          ///< depth of a groove following the outline, fraction of h (0: none)
  double edge_groove_distance = 1.5;  ///< ... at this distance inside the edge, in h
  double bump_inset = 2;           ///< detail bumps fade in from this distance inside the edge, in h
  double grade_u = 0, grade_v = 0; ///< graded triangulation: local spacing varies by (1 +- grade) across
                                   ///< the domain (< 0.9; 0: uniform)
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
  std::vector<Polyline> boundary;    ///< true boundary at the foot of the step (on the background's texture, noise left out), dense
                                     ///< (spacing <= average_edge / 8); relief on the left
  double h = 1;
  double average_edge = 0;     ///< mean length of the unique 3D mesh edges
  double nominal_edge = 0;     ///< mean length of the unique edges in the (u, v) plane
  double spacing_u = 0, spacing_v = 0;  ///< grid spacing
  int grid_u = 0, grid_v = 0;  ///< vertices per row / column: vertex (i, j) has index j * grid_u + i
  bool open = false;           ///< the boundary ends on the mesh boundary
  std::vector<double> slots;   ///< Slots: (center u, width) pairs of the cut slots, absolute units;
                               ///< Gear: (angle, width) pairs
  std::vector<double> band;    ///< Band: centreline points, (u, v) pairs, starting outside the domain
  /// Per vertex (#V each): the offset along the background normal that is relief (step and interior
  /// detail), texture (background texture) and noise; their sum is the vertex's height above
  /// surface(u, v, 0).
  std::vector<double> relief_height, texture_height, noise_height;

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
  /// Fractional grid column / row of the vertices near u / v (undoes the graded warp).
  double grid_column(double u) const;
  double grid_row(double v) const;

  /// Suggested picks; throws Error if the requested ring does not fit in the domain.
  Picks picks(const PickSpec& pick_spec = {}) const;
};

/// Generates a scan. Throws Error on bad parameters. Deterministic for a spec.
Scan generate(const ScanSpec& spec);

/// The height the relief stands at just inside its edge: where the edge profile alone (the step's
/// rise, the drop, the edge groove; not the dome, bumps or grooves further in) first stops rising.
/// It is h unless a drop or an edge groove keeps the rim below h: a blended step into a drop tops
/// out near 0.5 h, and a blended step whose edge groove starts before it has risen leaves a rim
/// lower than the top beyond the groove. A step measured at the contour's edge reads the rim.
double edge_step_height(const ScanSpec& spec);

// --- the random family -----------------------------------------------------------------

/// One draw of the random family: every axis drawn from seeded distributions (docs in
/// bench/README.md, "Random suite"). `axes` names each drawn value for the per-axis breakdown.
struct RandomDraw {
  ScanSpec spec;
  PickSpec picks;
  double typed_factor = 1;     ///< the h a user types = true step * typed_factor (x0.5 .. x2.0)
  bool picks_on_texture = false;  ///< some picks moved onto texture features (Dots: a dot; Striations: a crest)
  nlohmann::json axes;         ///< {axis name: drawn value}
};
/// Draws attempt `attempt` of seed `seed` (a draw that does not fit is redrawn with attempt + 1).
RandomDraw draw_random(std::uint64_t seed, int attempt = 0);

struct RandomScan {
  RandomDraw draw;
  Scan scan;
  Picks picks;
  int attempts = 1;            ///< draws tried until one fitted
};
/// Draws, generates and picks until a draw fits (at most 50 attempts; throws Error otherwise).
/// Deterministic for a seed.
RandomScan generate_random(std::uint64_t seed);

/// Truth JSON of a random scan (truth_json() plus true/typed step height, closed, axes, the one-edge
/// IoU floor, the background file's name and columns).
nlohmann::json random_truth_json(const RandomScan& random, const std::string& background_file);
/// Per vertex #V by 9 float32 .npy: base x y z (surface(u, v, 0)), background normal x y z, relief
/// height, texture height, noise height (see Scan::relief_height).
void write_background_npy(const Scan& scan, const std::string& path);

/// The vertex at the texture feature nearest (u, v): a dot's centre (Dots) or a ridge crest
/// (Striations); -1 without texture.
std::int64_t texture_feature_vertex(const Scan& scan, double u, double v);

/// IoU floors of a truth region: IoU of the region against itself grown by one average edge
/// (every vertex within `average_edge` (3D) of the boundary added), by vertex count and by vertex area.
struct IouFloor {
  double vertices = 1, area = 1;
};
IouFloor one_edge_floor(const Scan& scan);

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
  /// Whether some segment lies within distance r of p (visits only the cells within r: fast for
  /// points far from every polyline, where operator() falls back to brute force).
  bool within(const Vec3& p, double r) const;
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
/// The object write_truth_json writes.
nlohmann::json truth_json(const Scan& scan, const Picks& picks);
/// Writes j to path (via a temporary name, renamed when complete).
void write_json(const nlohmann::json& j, const std::string& path);

}  // namespace synthetic
}  // namespace relief_snake

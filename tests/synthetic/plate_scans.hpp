#pragma once
// Plates with several reliefs (issue 13, part 2): disks, ellipses and rounded boxes of their
// own step heights on one scan, some touching (two boxes of different heights sharing a side),
// on a plane or curved background (the triangulation and backgrounds of synthetic.hpp), with
// the truth per relief. Used by test_detect, `make-scan --plate` and bench/detect_suite.py.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "synthetic.hpp"

namespace relief_snake {
namespace synthetic {

enum class PlateShape { Disk, Ellipse, Box };

struct PlateRelief {
  PlateShape shape = PlateShape::Disk;
  double center_u = 0, center_v = 0;
  double size_u = 6, size_v = 6;   ///< radius (disk), semi-axes (ellipse), half sizes (box)
  double rotation = 0;             ///< radians (ellipse, box)
  double corner = 0;               ///< box corner radius
  double h = 1;                    ///< step height
  /// Index of the relief it shares a side with (-1: none). The lower of the two runs on under the
  /// taller one, so a step of their height difference separates them.
  int touches = -1;
  /// Signed distance in the parameter plane (negative inside; exact for disks and boxes,
  /// a 1-Lipschitz bound for ellipses).
  double signed_distance(double u, double v) const;
};

struct PlateSpec {
  Background background = Background::Plane;
  double radius = 120;             ///< cylinder / sphere / saddle radius
  std::size_t triangles = 100000;
  double width = 80, height = 56;
  Step step = Step::Blended;
  double blend_width = 0.5;        ///< in units of each relief's h
  double noise = 0;                ///< Gaussian displacement along the normal, absolute units (sigma)
  double jitter = 0.3;
  std::uint64_t seed = 1;          ///< triangulation jitter and noise
  std::vector<PlateRelief> reliefs;  ///< may be empty: a plate without relief
};

/// A random layout (deterministic for a seed): 3 to 5 reliefs of h in [0.6, 2] and sizes 4 .. 10,
/// apart from each other by at least 6 (at least 3 h of the taller), one pair of boxes touching
/// along a side with heights differing by at least x1.6, and one small disk (radius 1.5, below
/// the default minimum area of detect on 100k triangles).
std::vector<PlateRelief> random_plate_layout(std::uint64_t seed, double width = 80, double height = 56);

struct PlateScan {
  PlateSpec spec;
  Scan scan;  ///< V, F, UV, average_edge of the plate (its relief / boundary fields are not the plate's)
  /// Per relief: sorted vertex indices inside it (its signed distance < 0), and its true area (vertex areas).
  std::vector<std::vector<std::int64_t>> truth;
  std::vector<double> truth_area;
};

PlateScan generate_plate(const PlateSpec& spec);

/// Truth JSON: {average_edge, triangles, vertices, spec {...}, reliefs: [{shape, center, size,
/// rotation, h, touches, area, vertices}]}.
nlohmann::json plate_truth_json(const PlateScan& plate);

/// make-scan --plate SEED --out PREFIX [--background B] [--radius R] [--noise S] [--triangles N]
/// [--step sharp|blended] [--empty]: writes PREFIX.ply and PREFIX.truth.json (plate_truth_json).
/// --empty: the same plate without its reliefs. Returns the exit code; throws Error on bad arguments.
int run_plate_command(const std::vector<std::string>& args);
extern const char* kPlateUsage;

/// Vertex-count IoU of two sorted index lists (1 when both are empty).
double index_iou(const std::vector<std::int64_t>& a, const std::vector<std::int64_t>& b);

}  // namespace synthetic
}  // namespace relief_snake

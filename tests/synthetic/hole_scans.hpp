#pragma once
// Whole reliefs for issue 13: reliefs with inner holes (Shape::Ring, Shape::HoledLetter on the
// ordinary generator), and a cyclic band (a frieze or an engraved band) right round a cylinder or
// vase, which the rectangular generator cannot make (its domain does not close on itself).
// Truth: the hole boundaries, and both boundaries of the band.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "synthetic.hpp"

namespace relief_snake {
namespace synthetic {

/// The closed boundary polylines of a scan's relief that bound holes (every closed one but the
/// longest, which is the outer boundary). Relief on the left of each, like Scan::boundary.
std::vector<Polyline> hole_boundaries(const Scan& scan);

/// A band right round a surface of revolution about the y axis: radius R (1 + vase_amplitude
/// sin(2 pi y / vase_period)), y in [-length/2, length/2]; the band lies between
/// y = -half_width + wave sin(waves theta + phase) and y = half_width + wave sin(waves theta + phase + 1).
struct TubeSpec {
  double radius = 20, length = 60;
  double vase_amplitude = 0, vase_period = 60;  ///< 0: a cylinder
  double half_width = 8;          ///< the band's half width along the axis
  double wave = 2, phase = 0;     ///< the band's edges wave by this much along the axis ...
  int waves = 3;                  ///< ... this many times round
  double h = 1;                   ///< step height; negative: an engraved band (cut in by |h|)
  Step step = Step::Blended;
  double blend_width = 0.5;       ///< Blended: width of the rising profile, in units of |h|
  double noise = 0;               ///< sigma along the normal, fraction of |h|
  double jitter = 0.3;            ///< fraction of the grid spacing
  std::size_t triangles = 100000;
  std::uint64_t seed = 1;
};

struct TubePicks {
  std::vector<std::int64_t> first, second;  ///< below the band (small y) and above it, each right round
};

/// The band scan: Scan::boundary holds the two band edges (closed; engraved: at the floor, the
/// foot of the groove's walls), Scan::relief the band's vertices (engraved: the cut-in band).
/// Throws Error on bad parameters.
Scan generate_tube(const TubeSpec& spec);
/// Pick rings `distance` |h| beside the band's extreme edges (engraved: on the groove's floor,
/// `distance` |h| inside its innermost edges), `count` picks each, in the same direction round the axis.
TubePicks tube_picks(const Scan& scan, const TubeSpec& spec, int count = 12, double distance = 3);

/// How far a result contour lies from one truth polyline, in average edges (both ways, like score()).
struct ContourMatch {
  double mean_to_truth = 0, max_to_truth = 0, mean_from_truth = 0, max_from_truth = 0;
  double mean() const { return 0.5 * (mean_to_truth + mean_from_truth); }
};
ContourMatch match_contour(const std::vector<Vec3>& contour, const Polyline& truth, double average_edge);

/// The index of the truth polyline nearest a contour (smallest mean distance to it).
std::size_t nearest_polyline(const std::vector<Vec3>& contour, const std::vector<Polyline>& candidates);

/// Truth JSON extras: "holes" (list of polylines, relief on the left), for scans with holes.
void add_hole_truth(const Scan& scan, nlohmann::json* truth);

/// make-scan tube [options] --out PREFIX: writes PREFIX.ply and PREFIX.truth.json (boundary: both
/// band edges; picks, band_picks: the two rings). args: everything after "tube".
int tube_command(const std::vector<std::string>& args);

}  // namespace synthetic
}  // namespace relief_snake

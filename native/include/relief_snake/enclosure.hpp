#pragma once
// Does the picked contour enclose a relief? (issue 11, pick sets that cannot enclose one.)
// check_pick_polygon refuses a figure-eight order and collinear picks. Picks that all lie on one
// side of the relief pass it: a tight cluster or a ring on the background beside the relief
// encloses background only, and a shallow arc along one side encloses a sliver. The snake then
// shrinks onto texture or onto nothing and, without this check, could end "converged" on the
// background with no warning.
//
// The test is close to the step-height estimate's view of the picks (step_height.hpp): a smooth
// background (a quadric, fitted robustly to the corners of the initial contour's faces) continued
// under the contour, and the heights above it of the vertices the contour encloses. A relief of step h inside shows as
// area standing at least half an h above that background; picks on one side show none (or
// only a sliver at the contour, where it runs onto the relief).
#include <algorithm>
#include <string>
#include <vector>

#include "relief_snake/height_statistics.hpp"
#include "relief_snake/initial_contour.hpp"
#include "relief_snake/mesh.hpp"

namespace relief_snake {

struct EnclosureOptions {
  double rise = 0.5;      ///< a vertex counts as relief when it stands rise h above the background
  /// Less relief area than min_area h^2, and less than min_share of the enclosed area: the
  /// picks enclose no relief (a relief one h across is still 0.8 h^2).
  double min_area = 0.5;
  double min_share = 0.01;
};

/// The heights of what a closed initial contour encloses, above the background along it.
struct Enclosure {
  std::vector<WeightedHeight> heights;  ///< the enclosed vertices' heights (weight: vertex area)
  double enclosed_area = 0;             ///< their area
  double background_residual = 0;       ///< RMS residual of a plain least-squares quadric along the contour
};

/// path: the closed initial contour; inside_left: its enclosed side (contour_orientation_left()).
Enclosure measure_enclosure(const Mesh& mesh, const SurfacePath& path, bool inside_left);

/// The step a rise is judged against: the lower of h and the step found along a contour, when one
/// was found (> 0), else h (a rough h given too large, or a background the quadric follows roughly).
inline double judged_step(double h, double step_found) { return step_found > 0 ? std::min(h, step_found) : h; }

/// Area of the enclosed vertices standing at least `rise` above the background.
double risen_area(const Enclosure& enclosure, double rise);

/// For step height h (segment() passes the h used, or the step found along the contour where that is
/// lower): the reason (one sentence, for Result::reasons) when the picks enclose no relief, or "".
std::string enclosure_reason(const Enclosure& enclosure, double h, const EnclosureOptions& options = {});

/// A result's region (#V flags) against the enclosed area standing rise x (the lower of h and
/// step_found, when that is > 0) above the background: its area over that area. -1 when nothing
/// measurable rises (enclosure_reason's case, or an open contour's empty enclosure).
double covered_share(const Mesh& mesh, const Enclosure& enclosure, const std::vector<char>& region, double h,
                     double step_found, const EnclosureOptions& options = {});

}  // namespace relief_snake

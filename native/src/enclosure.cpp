// Does the picked contour enclose a relief: heights inside above the background along it (enclosure.hpp).
#include "relief_snake/enclosure.hpp"

#include <algorithm>
#include <cstdio>
#include <string>

#include "relief_snake/evidence.hpp"

#include "relief_snake/region.hpp"
#include "relief_snake/step_height.hpp"

namespace relief_snake {

Enclosure measure_enclosure(const Mesh& mesh, const SurfacePath& path, bool inside_left) {
  Enclosure out;
  if (path.size() < 3) return out;
  // A quadric through the corners of the contour's own faces, fitted robustly (Tukey): the step-height
  // estimate's band of two more rings reaches the relief on coarse meshes (picks 3 h out are two
  // edges from it at 2,600 triangles), and a contour that runs over a piece of the relief must not
  // lift the background either.
  const std::vector<int> samples = contour_band_vertices(mesh, path, 0);
  const PolynomialBackground background = fit_robust_background(mesh, samples).background;
  out.background_residual = fit_polynomial_background(mesh, samples, 2).residual;  // plain: how well it fits
  const std::vector<char> region = relief_region(mesh, path, true, inside_left);
  for (int v = 0; v < mesh.n_vertices(); ++v)
    if (region[v]) {
      out.heights.push_back({background.height(mesh.position(v)), mesh.vertex_area(v)});
      out.enclosed_area += mesh.vertex_area(v);
    }
  return out;
}

double risen_area(const Enclosure& enclosure, double rise) {
  double area = 0;
  for (const WeightedHeight& v : enclosure.heights)
    if (v.height >= rise) area += v.weight;
  return area;
}

double covered_share(const Mesh& mesh, const Enclosure& enclosure, const std::vector<char>& region, double h,
                     double step_found, const EnclosureOptions& options) {
  const double judged = judged_step(h, step_found);
  if (!(judged > 0) || enclosure.heights.empty()) return -1;
  const double risen = risen_area(enclosure, options.rise * judged);
  if (risen < options.min_area * judged * judged && risen < options.min_share * enclosure.enclosed_area) return -1;
  return region_area(mesh, region) / risen;
}

std::string enclosure_reason(const Enclosure& enclosure, double h, const EnclosureOptions& options) {
  if (!(h > 0) || enclosure.heights.empty()) return "";
  const double risen = risen_area(enclosure, options.rise * h);
  if (risen >= options.min_area * h * h || risen >= options.min_share * enclosure.enclosed_area) return "";
  char text[64];
  std::snprintf(text, sizeof text, "%.3g", h);
  return std::string("nothing the picks enclose rises half a step (") + text +
         ") above the background along them: they may all lie on one side of the relief or on it (a cluster, "
         "an arc, a ring beside it); pick points on the background all around the relief";
}

}  // namespace relief_snake

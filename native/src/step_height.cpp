// Step height from the picks: a quadratic background along the initial contour, Otsu
// on the heights it encloses.
#include "relief_snake/step_height.hpp"

#include <algorithm>
#include <cmath>

#include "relief_snake/background.hpp"
#include "relief_snake/height_statistics.hpp"
#include "relief_snake/region.hpp"

namespace relief_snake {
namespace {

using QuadraticBackground = PolynomialBackground;

QuadraticBackground fit_background(const Mesh& mesh, const std::vector<int>& samples) {
  return fit_polynomial_background(mesh, samples, 2);
}

std::vector<WeightedHeight> heights_of(const Mesh& mesh, const std::vector<char>& region, const QuadraticBackground& bg,
                                       const std::vector<char>* near = nullptr) {
  std::vector<WeightedHeight> out;
  for (int v = 0; v < mesh.n_vertices(); ++v)
    if (region[v] && (!near || (*near)[v])) out.push_back({bg.height(mesh.position(v)), mesh.vertex_area(v)});
  return out;
}

// Vertices within `distance` of the samples (straight distance to the sample a
// breadth-first search from it reached them through), so both sides of an open contour
// are compared over the same strip and the fit is not continued far from its samples.
std::vector<char> near_samples(const Mesh& mesh, const std::vector<int>& samples, double distance) {
  std::vector<char> near(mesh.n_vertices(), 0);
  std::vector<int> source(mesh.n_vertices(), -1), queue;
  for (const int v : samples) source[v] = v, near[v] = 1, queue.push_back(v);
  const double d2 = distance * distance;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int v = queue[head];
    for (const int* w = mesh.neighbors_begin(v); w != mesh.neighbors_end(v); ++w) {
      if (source[*w] >= 0) continue;
      source[*w] = source[v];
      if ((mesh.position(*w) - mesh.position(source[v])).squaredNorm() > d2) continue;
      near[*w] = 1;
      queue.push_back(*w);
    }
  }
  return near;
}

// The heights' upper class at Otsu's threshold (the relief, over the background near zero).
std::vector<WeightedHeight> upper_class(const std::vector<WeightedHeight>& heights, int bins,
                                        OtsuSplit* split_out = nullptr) {
  const OtsuSplit split = otsu_split(heights, bins);
  if (split_out) *split_out = split;
  std::vector<WeightedHeight> relief;
  for (const auto& v : heights)
    if (v.height > split.threshold) relief.push_back(v);
  return relief;
}

// A contour's size, against which a step a sizeable part of it is no relief step (the background's
// own curvature): its length over pi (closed) or 2 (open).
double contour_size(const Mesh& mesh, const SurfacePath& path, bool closed) {
  return path_length(mesh, path, closed) / (closed ? M_PI : 2.0);
}

// The median and the 90% height of the heights' upper Otsu class (none when they are not > 0).
void relief_group_guesses(const std::vector<WeightedHeight>& heights, const StepHeightOptions& options,
                          const std::string& source, std::vector<StepHeightGuess>* out) {
  if (heights.empty()) return;
  const std::vector<WeightedHeight> relief = upper_class(heights, options.histogram_bins);
  const double median = weighted_quantile(relief, 0.5), high = weighted_quantile(relief, 0.9);
  if (median > 0 && std::isfinite(median)) out->push_back({median, "the median height of the relief over " + source});
  if (high > 0 && std::isfinite(high)) out->push_back({high, "the 90% height of the relief over " + source});
}

}  // namespace

std::vector<int> contour_band_vertices(const Mesh& mesh, const SurfacePath& path, int rings) {
  std::vector<char> taken(mesh.n_vertices(), 0);
  std::vector<int> samples;
  for (const SurfacePoint& p : path)
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.face_vertex(p.face, k);
      if (!taken[v]) taken[v] = 1, samples.push_back(v);
    }
  for (int ring = 0, from = 0; ring < rings; ++ring) {
    const int to = static_cast<int>(samples.size());
    for (int i = from; i < to; ++i)
      for (const int* w = mesh.neighbors_begin(samples[i]); w != mesh.neighbors_end(samples[i]); ++w)
        if (!taken[*w]) taken[*w] = 1, samples.push_back(*w);
    from = to;
  }
  return samples;
}

StepHeightEstimate estimate_step_height(const Mesh& mesh, const SurfacePath& path, bool closed, bool inside_left,
                                        const StepHeightOptions& options) {
  StepHeightEstimate estimate;
  estimate.relief_left = inside_left;
  if (path.size() < 2) return estimate;

  // Background samples: the corners of the path's faces and a few rings around them.
  const std::vector<int> samples = contour_band_vertices(mesh, path, options.band_rings);
  const QuadraticBackground background = fit_background(mesh, samples);
  estimate.background_residual = background.residual;

  std::vector<WeightedHeight> heights;
  if (closed) {
    heights = heights_of(mesh, relief_region(mesh, path, true, inside_left), background);
  } else {
    // The relief is on the side that rises above the background, compared over a strip
    // along the contour (a tenth of its length wide) where the fit can be trusted.
    const std::vector<char> near = near_samples(mesh, samples, options.strip_share * path_length(mesh, path, false));
    const auto left = heights_of(mesh, relief_region(mesh, path, false, true), background, &near);
    const auto right = heights_of(mesh, relief_region(mesh, path, false, false), background, &near);
    estimate.left_rise = weighted_quantile(left, 0.9);
    estimate.right_rise = weighted_quantile(right, 0.9);
    // A side the user named is measured as named: the other side's rise (a background that curves
    // away from the fit, the far side's own relief) says nothing about this relief's step.
    estimate.relief_left = options.decide_side ? estimate.left_rise >= estimate.right_rise : inside_left;
    heights = estimate.relief_left ? left : right;
  }
  if (heights.empty()) return estimate;

  OtsuSplit split;
  const double value = weighted_quantile(upper_class(heights, options.histogram_bins, &split), 0.5);
  if (!(value > 0) || !std::isfinite(value)) return estimate;
  estimate.value = value;
  // Sure when the heights split cleanly and the relief stands well above the fit's residual.
  const double clean = std::clamp((split.separation - options.min_separation) / (1 - options.min_separation), 0.0, 1.0);
  const double above_noise = std::clamp(value / (10 * background.residual + 1e-300) , 0.0, 1.0);
  estimate.confidence = clean * above_noise;
  // A step a sizeable part of the contour's own size is no relief step: unsure.
  if (value > largest_plausible_step_height(mesh, path, closed)) estimate.confidence = 0;
  return estimate;
}

double largest_plausible_step_height(const Mesh& mesh, const SurfacePath& path, bool closed) {
  return 0.25 * contour_size(mesh, path, closed);
}

std::vector<StepHeightGuess> alternative_step_heights(const Mesh& mesh, const SurfacePath& path, bool closed,
                                                      bool relief_left, const StepHeightEstimate& first,
                                                      const StepHeightOptions& options) {
  std::vector<StepHeightGuess> out;
  if (path.size() < 2) return out;
  // The thin-plate fill follows a vase or a wave that a quadric over one plane cannot. Closed: the
  // fill of the region the picks enclose from a ring around it. Open: the fill of the whole relief
  // side from a ring on the picks' side, its heights taken over the wide strip along the picks (where
  // the fill is held by its ring; it also reaches a relief picked farther away than the first
  // estimate's narrow strip does).
  const std::vector<char> region = relief_region(mesh, path, closed, relief_left);
  const double scale = options.fill_scale_edges * mesh.average_edge_length();
  const BackgroundResult fill = fill_background(mesh, region, scale);
  const std::vector<int> samples = closed ? std::vector<int>() : contour_band_vertices(mesh, path, options.band_rings);
  const std::vector<char> near =
      closed ? std::vector<char>() : near_samples(mesh, samples, options.wide_strip_share * path_length(mesh, path, false));
  if (fill.ok()) {
    std::vector<WeightedHeight> heights;
    heights.reserve(fill.region_vertices.size());
    for (const int v : fill.region_vertices)
      if (closed || near[v]) heights.push_back({fill.height[v], mesh.vertex_area(v)});
    relief_group_guesses(heights, options, "the background filled in from around the picks", &out);
  }
  if (!closed) {
    const QuadraticBackground background = fit_background(mesh, samples);
    relief_group_guesses(heights_of(mesh, region, background, &near), options, "a wider strip along the picks", &out);
    const double side_rise = relief_left ? first.left_rise : first.right_rise;
    if (side_rise > 0) out.push_back({side_rise, "the 90% height of the relief side along the picks"});
  }
  // A step a sizeable part of the contour's own size is the background's own curvature (as for the
  // first estimate, whose confidence it zeroes).
  const double largest = largest_plausible_step_height(mesh, path, closed);
  out.erase(std::remove_if(out.begin(), out.end(), [&](const StepHeightGuess& g) { return g.value > largest; }),
            out.end());
  return out;
}

}  // namespace relief_snake

// Step height from the picks: a quadratic background along the initial contour, Otsu
// on the heights it encloses.
#include "relief_snake/step_height.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "relief_snake/plane_fit.hpp"
#include "relief_snake/region.hpp"

namespace relief_snake {
namespace {

struct WeightedHeight {
  double height, weight;
};

// A quadratic height field over a plane: z(x, y) = c . (1, x, y, x^2, xy, y^2).
struct QuadraticBackground {
  Vec3 origin = Vec3::Zero(), e1 = Vec3::UnitX(), e2 = Vec3::UnitY(), normal = Vec3::UnitZ();
  Eigen::Matrix<double, 6, 1> c = Eigen::Matrix<double, 6, 1>::Zero();
  double residual = 0;

  static Eigen::Matrix<double, 6, 1> basis(double x, double y) {
    Eigen::Matrix<double, 6, 1> b;
    b << 1, x, y, x * x, x * y, y * y;
    return b;
  }
  double height(const Vec3& p) const {
    const Vec3 d = p - origin;
    return d.dot(normal) - basis(d.dot(e1), d.dot(e2)).dot(c);
  }
};

QuadraticBackground fit_background(const Mesh& mesh, const std::vector<int>& samples) {
  QuadraticBackground fit;
  const VertexPlaneFit plane = fit_vertex_plane(mesh, samples);
  const double weight = plane.weight;
  if (weight <= 0) return fit;
  const Vec3 mean = plane.centroid;
  fit.origin = mean;
  fit.normal = plane.normal;
  fit.e1 = plane.axes.col(2);
  fit.e2 = fit.normal.cross(fit.e1);
  // Scale the plane coordinates to about 1 so the normal equations are well conditioned.
  const double scale = std::sqrt(std::max(plane.eigenvalues[2] / weight, 1e-300));
  fit.e1 /= scale;
  fit.e2 /= scale;
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
  for (const int v : samples) {
    const Vec3 d = mesh.position(v) - mean;
    const auto phi = QuadraticBackground::basis(d.dot(fit.e1), d.dot(fit.e2));
    A += mesh.vertex_area(v) * phi * phi.transpose();
    b += mesh.vertex_area(v) * d.dot(fit.normal) * phi;
  }
  fit.c = A.ldlt().solve(b);
  if (!fit.c.allFinite()) fit.c.setZero();
  double sum2 = 0;
  for (const int v : samples) sum2 += mesh.vertex_area(v) * std::pow(fit.height(mesh.position(v)), 2);
  fit.residual = std::sqrt(sum2 / weight);
  return fit;
}

double weighted_quantile(std::vector<WeightedHeight> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end(), [](const WeightedHeight& a, const WeightedHeight& b) { return a.height < b.height; });
  double total = 0;
  for (const auto& v : values) total += v.weight;
  double acc = 0;
  for (const auto& v : values) {
    acc += v.weight;
    if (acc >= q * total) return v.height;
  }
  return values.back().height;
}

struct Split {
  double threshold = 0, separation = 0;
};

// Otsu's threshold on an area-weighted histogram of the heights.
Split otsu(const std::vector<WeightedHeight>& values, int bins) {
  Split split;
  if (values.size() < 2) return split;
  const double lo = weighted_quantile(values, 0.005), hi = weighted_quantile(values, 0.995);
  if (!(hi > lo)) return split;
  std::vector<double> w(bins, 0), m(bins, 0);
  double total = 0, total_mean = 0;
  for (const auto& v : values) {
    const int k = std::clamp(static_cast<int>((v.height - lo) / (hi - lo) * bins), 0, bins - 1);
    w[k] += v.weight;
    m[k] += v.weight * v.height;
    total += v.weight;
    total_mean += v.weight * v.height;
  }
  double var_total = 0;
  for (const auto& v : values) var_total += v.weight * std::pow(v.height - total_mean / total, 2);
  double w0 = 0, m0 = 0, best = -1;
  for (int k = 0; k + 1 < bins; ++k) {
    w0 += w[k];
    m0 += m[k];
    const double w1 = total - w0;
    if (w0 <= 0 || w1 <= 0) continue;
    const double mu0 = m0 / w0, mu1 = (total_mean - m0) / w1;
    const double between = w0 * w1 * (mu1 - mu0) * (mu1 - mu0) / total;
    if (between > best) {
      best = between;
      split.threshold = lo + (k + 1) * (hi - lo) / bins;
    }
  }
  split.separation = var_total > 0 ? std::clamp(best / var_total, 0.0, 1.0) : 0;
  return split;
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

}  // namespace

StepHeightEstimate estimate_step_height(const Mesh& mesh, const SurfacePath& path, bool closed, bool inside_left,
                                        const StepHeightOptions& options) {
  StepHeightEstimate estimate;
  estimate.relief_left = inside_left;
  if (path.size() < 2) return estimate;

  // Background samples: the corners of the path's faces and a few rings around them.
  std::vector<char> taken(mesh.n_vertices(), 0);
  std::vector<int> samples;
  for (const SurfacePoint& p : path)
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.face_vertex(p.face, k);
      if (!taken[v]) taken[v] = 1, samples.push_back(v);
    }
  for (int ring = 0, from = 0; ring < options.band_rings; ++ring) {
    const int to = static_cast<int>(samples.size());
    for (int i = from; i < to; ++i)
      for (const int* w = mesh.neighbors_begin(samples[i]); w != mesh.neighbors_end(samples[i]); ++w)
        if (!taken[*w]) taken[*w] = 1, samples.push_back(*w);
    from = to;
  }
  const QuadraticBackground background = fit_background(mesh, samples);
  estimate.background_residual = background.residual;

  std::vector<WeightedHeight> heights;
  if (closed) {
    heights = heights_of(mesh, relief_region(mesh, path, true, inside_left), background);
  } else {
    // The relief is on the side that rises above the background, compared over a strip
    // along the contour (a tenth of its length wide) where the fit can be trusted.
    const std::vector<char> near = near_samples(mesh, samples, 0.1 * path_length(mesh, path, false));
    const auto left = heights_of(mesh, relief_region(mesh, path, false, true), background, &near);
    const auto right = heights_of(mesh, relief_region(mesh, path, false, false), background, &near);
    estimate.left_rise = weighted_quantile(left, 0.9);
    estimate.right_rise = weighted_quantile(right, 0.9);
    estimate.relief_left = estimate.left_rise >= estimate.right_rise;
    heights = estimate.relief_left ? left : right;
  }
  if (heights.empty()) return estimate;

  const Split split = otsu(heights, options.histogram_bins);
  std::vector<WeightedHeight> relief;
  for (const auto& v : heights)
    if (v.height > split.threshold) relief.push_back(v);
  const double value = weighted_quantile(relief, 0.5);
  if (!(value > 0) || !std::isfinite(value)) return estimate;
  estimate.value = value;
  // Sure when the heights split cleanly and the relief stands well above the fit's residual.
  const double clean = std::clamp((split.separation - options.min_separation) / (1 - options.min_separation), 0.0, 1.0);
  const double above_noise = std::clamp(value / (10 * background.residual + 1e-300) , 0.0, 1.0);
  estimate.confidence = clean * above_noise;
  // A step a sizeable part of the contour's own size is no relief step: unsure.
  const double size = path_length(mesh, path, closed) / (closed ? M_PI : 2.0);
  if (value > 0.25 * size) estimate.confidence = 0;
  return estimate;
}

}  // namespace relief_snake

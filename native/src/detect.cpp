// Automatic detection of reliefs: robust background, Otsu threshold, components, plateaus,
// and the snake from each candidate's own outline (detect.hpp).
#include "report_text.hpp"
#include "relief_snake/detect.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <sstream>

#include "relief_snake/mesh_graph.hpp"
#include "relief_snake/error.hpp"
#include "relief_snake/evidence.hpp"
#include "relief_snake/height_statistics.hpp"
#include "relief_snake/region.hpp"

namespace relief_snake {
namespace {

using Clock = std::chrono::steady_clock;

/// Rings of the opening that removes a taller relief's wall from the lower plateau around it.
constexpr int kOpeningRings = 3;

void validate(const DetectOptions& o) {
  if (!(o.min_area >= 0) || !std::isfinite(o.min_area))
    throw Error("min_area must be a number >= 0 in mesh units squared (0: the default, (12 average edges)^2)");
  if (o.background_degree != kAutoDegree && (o.background_degree < 0 || o.background_degree > 6))
    throw Error("background_degree must be between 0 and 6 (2: a quadric), or auto");
  if (o.robust_iterations < 0 || o.robust_iterations > 100) throw Error("robust_iterations must be between 0 and 100");
  if (o.histogram_bins < 8 || o.histogram_bins > 65536) throw Error("histogram_bins must be between 8 and 65536");
  if (!(o.min_height_sigmas >= 0) || !std::isfinite(o.min_height_sigmas)) throw Error("min_height_sigmas must be >= 0");
  if (!(o.plateau_separation > 0 && o.plateau_separation <= 1)) throw Error("plateau_separation must be in (0, 1]");
  if (!(o.plateau_ratio >= 1) || !std::isfinite(o.plateau_ratio)) throw Error("plateau_ratio must be >= 1");
  if (!(o.outline_offset > 0) || !std::isfinite(o.outline_offset)) throw Error("outline_offset must be > 0 (in h)");
  if (!(o.pick_spacing > 0) || !std::isfinite(o.pick_spacing)) throw Error("pick_spacing must be > 0 (in h)");
  if (o.retry_factors.empty()) throw Error("retry_factors must hold at least one factor (1: the candidate's height)");
  for (const double f : o.retry_factors)
    if (!(f > 0) || !std::isfinite(f)) throw Error("retry_factors must be numbers > 0");
  if (!(o.duplicate_iou > 0 && o.duplicate_iou <= 1)) throw Error("duplicate_iou must be in (0, 1]");
}

/// Connected components (over mesh edges) of the flagged vertices.
std::vector<std::vector<int>> components_of(const Mesh& mesh, const std::vector<char>& flag) {
  std::vector<std::vector<int>> out = vertex_components(mesh, flag);
  for (std::vector<int>& comp : out) std::sort(comp.begin(), comp.end());
  return out;
}

double area_of(const Mesh& mesh, const std::vector<int>& vertices) {
  double a = 0;
  for (const int v : vertices) a += mesh.vertex_area(v);
  return a;
}

double median_height(const Mesh& mesh, const std::vector<int>& vertices, const std::vector<double>& height) {
  std::vector<WeightedHeight> values;
  values.reserve(vertices.size());
  for (const int v : vertices) values.push_back({height[v], mesh.vertex_area(v)});
  return weighted_quantile(values, 0.5);
}

/// Morphological opening of a vertex set by `rings` rings (erode, then grow back inside the set).
std::vector<char> opening(const Mesh& mesh, const std::vector<int>& vertices, int rings) {
  std::vector<char> in(mesh.n_vertices(), 0), cur;
  for (const int v : vertices) in[v] = 1;
  cur = in;
  for (int r = 0; r < rings; ++r) {
    std::vector<char> next = cur;
    for (const int v : vertices)
      if (cur[v])
        for (const int* w = mesh.neighbors_begin(v); w != mesh.neighbors_end(v); ++w)
          if (!cur[*w]) {
            next[v] = 0;
            break;
          }
    cur.swap(next);
  }
  for (int r = 0; r < rings; ++r) {
    std::vector<char> next = cur;
    for (const int v : vertices)
      if (!cur[v])
        for (const int* w = mesh.neighbors_begin(v); w != mesh.neighbors_end(v); ++w)
          if (cur[*w]) {
            next[v] = 1;
            break;
          }
    cur.swap(next);
  }
  return cur;
}

/// Picks along a loop at about `spacing` apart (at least 6 when the loop allows).
std::vector<int> picks_along(const Mesh& mesh, const std::vector<int>& loop, double spacing) {
  if (loop.size() < 3) return {};
  std::vector<double> at(loop.size() + 1, 0);
  for (std::size_t k = 0; k < loop.size(); ++k)
    at[k + 1] = at[k] + (mesh.position(loop[(k + 1) % loop.size()]) - mesh.position(loop[k])).norm();
  const double length = at.back();
  const int count = std::clamp(static_cast<int>(std::lround(length / spacing)), std::min<int>(6, loop.size()),
                               std::min<int>(400, loop.size()));
  std::vector<int> out;
  std::size_t k = 0;
  for (int i = 0; i < count; ++i) {
    const double target = length * i / count;
    while (k + 1 < loop.size() && at[k + 1] <= target) ++k;
    if (out.empty() || out.back() != loop[k]) out.push_back(loop[k]);
  }
  if (out.size() > 1 && out.back() == out.front()) out.pop_back();
  return out;
}

}  // namespace

DetectResult detect(Segmenter& segmenter, const Mesh& mesh, const std::vector<std::int64_t>& region_vertices,
                    const DetectOptions& options, const GroupProgressCallback& progress) {
  const auto start = Clock::now();
  validate(options);
  DetectResult out;
  const int nv = mesh.n_vertices();
  const double edge = mesh.average_edge_length();
  const double min_area = options.min_area > 0 ? options.min_area : std::pow(12 * edge, 2);

  // --- the region -------------------------------------------------------------------
  std::vector<char> in_region(nv, region_vertices.empty() ? 1 : 0);
  for (const std::int64_t i : region_vertices) {
    if (i < 0 || static_cast<std::size_t>(i) >= mesh.input_vertex_count())
      throw Error("region vertex " + std::to_string(i) + " is not a vertex index (the mesh has " +
                  std::to_string(mesh.input_vertex_count()) + " vertices)");
    const int v = mesh.input_to_mesh(static_cast<std::size_t>(i));
    if (v >= 0) in_region[v] = 1;
  }
  std::vector<int> samples;
  for (int v = 0; v < nv; ++v)
    if (in_region[v]) samples.push_back(v);
  const int max_degree = options.background_degree == kAutoDegree ? 6 : options.background_degree;
  const int terms = (max_degree + 1) * (max_degree + 2) / 2;
  if (static_cast<int>(samples.size()) < 4 * terms + 10)
    throw Error("the region has " + std::to_string(samples.size()) +
                " vertices on the surface, too few to fit a background; give a larger region");
  out.background.region_vertices = samples.size();

  // Progress before the refinement, so front ends can show it and cancel there (on a large scan the
  // fits and the components take about as long as refining a candidate): phase "background" before
  // each fit (iteration: the fits done), then "candidates" once the components are known
  // (iteration: how many). Index 0: no candidate is refined yet.
  auto stage = [&](const char* phase, int iteration) {
    if (!progress) return true;
    Progress p;
    p.phase = phase;
    p.iteration = iteration;
    p.contour = [] { return std::vector<Vec3>{}; };
    return progress(0, p);
  };
  auto cancelled = [&] {
    out.cancelled = true;
    out.seconds = seconds_since(start);
    return out;
  };
  if (!stage("background", 0)) return cancelled();

  // --- 1. robust background over the whole region --------------------------------------
  // auto: the lowest degree of 2, 4, 6 whose noise sigma is within 10% of the best (a plane or a
  // gentle curve keeps its quadric; a vase's changing radius needs the sixth degree).
  // A low-degree polynomial over the whole region is fitted as well from an even sample of at most
  // 20k vertices (the reweighting rounds cost a fit each), and evaluated at every vertex.
  std::vector<int> fit_samples;
  const std::size_t stride = (samples.size() + 19999) / 20000;
  for (std::size_t k = 0; k < samples.size(); k += stride) fit_samples.push_back(samples[k]);
  RobustFitOptions fit_options;
  fit_options.iterations = options.robust_iterations;
  RobustFit fit;
  if (options.background_degree != kAutoDegree) {
    fit_options.degree = options.background_degree;
    fit = fit_robust_background(mesh, fit_samples, fit_options);
  } else {
    std::vector<RobustFit> fits;
    for (const int degree : {2, 4, 6}) {
      if (!fits.empty() && !stage("background", static_cast<int>(fits.size()))) return cancelled();
      fit_options.degree = degree;
      fits.push_back(fit_robust_background(mesh, fit_samples, fit_options));
    }
    double best = fits[0].sigma;
    for (const RobustFit& f : fits) best = std::min(best, f.sigma);
    for (const RobustFit& f : fits)
      if (f.sigma <= 1.1 * best + 1e-12 * mesh.bbox_diagonal()) {
        fit = f;
        break;
      }
  }
  out.background.degree = fit.background.degree;
  std::vector<double> height(nv, 0);
  std::vector<WeightedHeight> values;
  values.reserve(samples.size());
  for (const int v : samples) {
    height[v] = fit.background.height(mesh.position(v));
    values.push_back({height[v], mesh.vertex_area(v)});
  }
  out.background.sigma = fit.sigma;
  out.background.inlier_share = fit.inlier_share;
  out.background.iterations = fit.iterations;
  if (fit.inlier_share < 0.5)
    out.notes.push_back("only " + fmt(100 * fit.inlier_share) +
                        "% of the region fits the smooth background: reliefs may cover most of it, or the background "
                        "is more curved than the fit follows; give a smaller region around the reliefs");

  // --- 2. threshold: Otsu, moved down to a lower relief level where one stands clear -----
  const double floor = std::max(options.min_height_sigmas * fit.sigma, 0.05 * edge);
  const OtsuSplit first = otsu_split(values, options.histogram_bins);
  out.background.otsu_threshold = first.threshold;
  out.background.separation = first.separation;
  double threshold = first.threshold;
  for (int round = 0; round < 4; ++round) {
    std::vector<WeightedHeight> lower;
    for (const auto& w : values)
      if (w.height <= threshold) lower.push_back(w);
    const OtsuSplit split = otsu_split(lower, options.histogram_bins);
    if (!(split.threshold > floor) || split.threshold >= threshold) break;
    double above = 0;
    std::vector<WeightedHeight> upper;
    for (const auto& w : lower)
      if (w.height > split.threshold) above += w.weight, upper.push_back(w);
    // A level of its own: enough area, and its heights stand clear of the split (not the tail of the noise).
    if (above < min_area || weighted_quantile(upper, 0.5) < 1.6 * split.threshold) break;
    threshold = split.threshold;
  }
  // Otsu's level separates background and relief, but it may cut through the lowest relief's top
  // (noise spreads it across the level): candidates are taken halfway down, so that top stays
  // whole; the snake finds the outline anyway.
  threshold = std::max(0.5 * threshold, floor);
  out.background.threshold = threshold;

  // --- 3. components, split into plateaus ------------------------------------------------
  std::vector<char> above(nv, 0);
  for (const int v : samples) above[v] = height[v] > threshold;
  struct Raw {
    std::vector<int> vertices;
    int plateau = 0;
  };
  std::vector<Raw> raw;
  for (std::vector<int>& comp : components_of(mesh, above)) {
    if (area_of(mesh, comp) < min_area) continue;
    std::vector<WeightedHeight> hs;
    for (const int v : comp) hs.push_back({height[v], mesh.vertex_area(v)});
    const OtsuSplit split = otsu_split(hs, options.histogram_bins);
    std::vector<int> lower, upper;
    for (const int v : comp) (height[v] > split.threshold ? upper : lower).push_back(v);
    std::vector<Raw> parts;
    const double ratio = lower.empty() || upper.empty()
                             ? 0.0
                             : median_height(mesh, upper, height) / std::max(median_height(mesh, lower, height), 1e-300);
    if (split.separation >= options.plateau_separation && ratio >= options.plateau_ratio) {
      std::vector<char> flag(nv, 0);
      for (const int v : upper) flag[v] = 1;
      for (std::vector<int>& part : components_of(mesh, flag))
        if (area_of(mesh, part) >= min_area) parts.push_back({std::move(part), 2});
      const std::vector<char> opened = opening(mesh, lower, kOpeningRings);
      bool any_lower = false;
      for (std::vector<int>& part : components_of(mesh, opened))
        if (area_of(mesh, part) >= min_area) parts.push_back({std::move(part), 1}), any_lower = true;
      // Only two plateaus side by side are two reliefs: a lower level that is nothing but the
      // taller one's wall (or rim) is one relief.
      if (!any_lower || parts.size() < 2) parts.clear();
    }
    if (parts.size() > 1)
      out.notes.push_back("a component of area " + fmt(area_of(mesh, comp)) + " was split into " +
                          std::to_string(parts.size()) + " plateaus (heights' separation " + fmt(split.separation) +
                          ", medians x" + fmt(ratio) + ")");
    else if (ratio >= options.plateau_ratio)
      out.notes.push_back("a component of area " + fmt(area_of(mesh, comp)) + " kept whole (heights' separation " +
                          fmt(split.separation) + ", medians x" + fmt(ratio) + ")");
    if (parts.empty()) parts.push_back({std::move(comp), 0});
    for (Raw& p : parts) raw.push_back(std::move(p));
  }
  std::vector<int> label(nv, -1);
  for (std::size_t c = 0; c < raw.size(); ++c)
    for (const int v : raw[c].vertices) label[v] = static_cast<int>(c);
  if (!stage("candidates", static_cast<int>(raw.size()))) return cancelled();

  // --- 4. refine each candidate from its own outline --------------------------------------
  std::vector<DetectCandidate> candidates;
  for (std::size_t c = 0; c < raw.size(); ++c) {
    DetectCandidate cand;
    cand.plateau = raw[c].plateau;
    cand.area = area_of(mesh, raw[c].vertices);
    cand.height = median_height(mesh, raw[c].vertices, height);
    for (const int v : raw[c].vertices) cand.component.push_back(static_cast<std::int64_t>(mesh.mesh_to_input(v)));
    std::sort(cand.component.begin(), cand.component.end());
    const double h = options.segment.step_height > 0 ? options.segment.step_height
                                                      : std::clamp(cand.height, 0.5 * edge, mesh.bbox_diagonal() / 4);
    const int self = static_cast<int>(c);
    const std::vector<char> grown =
        grown_vertices(mesh, raw[c].vertices, std::max(options.outline_offset * h, 3 * edge),
             [&](int w) { return label[w] >= 0 && label[w] != self; });
    const std::vector<int> loop = region_outer_loop(mesh, grown);
    for (const int v : loop) cand.outline.push_back(mesh.to_file(mesh.position(v)));
    for (const int v : picks_along(mesh, loop, std::max(options.pick_spacing * h, 4 * edge)))
      cand.picks.push_back(static_cast<std::int64_t>(mesh.mesh_to_input(v)));
    if (options.refine) {
      const auto t0 = Clock::now();
      std::vector<char> comp(nv, 0);
      for (const int v : raw[c].vertices) comp[v] = 1;
      if (cand.picks.size() < 3) {
        cand.refined.error = "the candidate's outline is too short to start a snake from";
      } else {
        // The candidate's median height first; when the self-check does not hold, larger h (a
        // step only one or two edges high, or a blended one, is easier to hold with a larger h),
        // keeping the best score.
        const std::vector<double> factors = options.segment.step_height > 0 ? std::vector<double>{1.0}
                                                                            : options.retry_factors;
        for (std::size_t k = 0; k < factors.size() && !out.cancelled; ++k) {
          Options o = options.segment;
          o.step_height = std::min(h * factors[k], mesh.bbox_diagonal() / 4);
          o.closed = true;
          ProgressCallback forward;
          if (progress) forward = [&progress, c](const Progress& p) { return progress(c, p); };
          GroupOutcome attempt;
          try {
            attempt.result = segmenter.segment(cand.picks, o, forward);
            if (attempt.result.status == Status::Cancelled) {
              out.cancelled = true;
              break;
            }
            attempt.ok = true;
          } catch (const Error& e) {
            attempt.error = e.what();
          }
          double score = 0;
          if (attempt.ok) {
            std::vector<char> region(nv, 0);
            for (const std::int64_t i : attempt.result.relief_vertices) {
              const int v = mesh.input_to_mesh(static_cast<std::size_t>(i));
              if (v >= 0) region[v] = 1;
            }
            double step_share = 0;
            for (const auto& [name, value] : attempt.result.checks)
              if (name == "step_share") step_share = value;
            score = step_share * region_iou(mesh, comp, region);
          }
          const bool first_try = k == 0;
          if (first_try || (attempt.ok && (!cand.refined.ok || score > cand.score))) {
            if (!first_try && attempt.ok)
              attempt.result.notes.push_back("detect: refined with h = " + fmt(o.step_height) + " (x" +
                                             fmt(factors[k]) + " the candidate's height): a better score than with " +
                                             fmt(h));
            cand.refined = std::move(attempt);
            cand.score = score;
          }
          // A doubtful result that still agrees with the component (the low one of two touching
          // reliefs: the step along their shared side goes up, not down) is not improved by a larger h.
          if (cand.refined.ok && (cand.refined.result.status == Status::Converged || cand.score >= options.retry_below))
            break;
        }
      }
      if (out.cancelled) break;
      cand.refined.seconds = seconds_since(t0);
    }
    candidates.push_back(std::move(cand));
  }

  // --- duplicates, order, overlaps ---------------------------------------------------------
  auto region_flags = [&](const DetectCandidate& cand) {
    std::vector<char> flag(nv, 0);
    for (const std::int64_t i : cand.refined.result.relief_vertices) {
      const int v = mesh.input_to_mesh(static_cast<std::size_t>(i));
      if (v >= 0) flag[v] = 1;
    }
    return flag;
  };
  std::vector<char> dropped(candidates.size(), 0);
  for (std::size_t a = 0; a < candidates.size(); ++a)
    for (std::size_t b = a + 1; b < candidates.size(); ++b) {
      if (dropped[a] || dropped[b] || !candidates[a].refined.ok || !candidates[b].refined.ok) continue;
      const double iou = region_iou(mesh, region_flags(candidates[a]), region_flags(candidates[b]));
      if (iou <= options.duplicate_iou) continue;
      const std::size_t lose = candidates[a].score >= candidates[b].score ? b : a;
      dropped[lose] = 1;
      out.notes.push_back("two candidates (areas " + fmt(candidates[a].area) + " and " + fmt(candidates[b].area) +
                          ") refined to the same relief (IoU " + fmt(iou) + "); kept the one with the better score");
    }
  for (std::size_t c = 0; c < candidates.size(); ++c)
    if (!dropped[c]) out.candidates.push_back(std::move(candidates[c]));
  std::stable_sort(out.candidates.begin(), out.candidates.end(),
                   [](const DetectCandidate& a, const DetectCandidate& b) { return a.area > b.area; });
  std::vector<const std::vector<std::int64_t>*> regions;
  std::vector<std::size_t> index;
  std::vector<GroupOutcome> outcomes;
  for (std::size_t c = 0; c < out.candidates.size(); ++c) {
    outcomes.push_back(std::move(out.candidates[c].refined));
    if (outcomes.back().ok) regions.push_back(&outcomes.back().result.relief_vertices), index.push_back(c);
  }
  // regions point into outcomes: it is not resized from here on.
  out.overlaps = region_overlaps(mesh, regions);
  for (ReliefOverlap& o : out.overlaps) o.a = index[o.a], o.b = index[o.b];
  report_overlaps(&outcomes, out.overlaps, options.overlap, "candidate");
  for (std::size_t c = 0; c < out.candidates.size(); ++c) out.candidates[c].refined = std::move(outcomes[c]);
  if (out.candidates.empty()) out.notes.push_back("no relief found: nothing stands clear of the background by more than " +
                                                  fmt(threshold) + " over an area of at least " + fmt(min_area));
  out.seconds = seconds_since(start);
  return out;
}

}  // namespace relief_snake

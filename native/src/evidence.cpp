// Step evidence along a contour: local background planes outside, heights inside.
#include "relief_snake/evidence.hpp"

#include "relief_snake/background_inside.hpp"
#include "relief_snake/mesh_graph.hpp"
#include "relief_snake/plane_fit.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <string>

namespace relief_snake {
namespace {

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  const std::size_t k = std::min(values.size() - 1, static_cast<std::size_t>(q * (values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

// Vertices of v0's component within `radius` of `centre`, reached through vertices
// that are themselves within it (so the far side of a thin shell stays out).
void gather_ball(const Mesh& mesh, int v0, const Vec3& centre, double radius, std::vector<int>* mark, int stamp,
                 std::vector<int>* out) {
  out->clear();
  const double r2 = radius * radius;
  (*mark)[v0] = stamp;
  out->push_back(v0);
  for (std::size_t head = 0; head < out->size(); ++head) {
    const int v = (*out)[head];
    for (const int* w = mesh.neighbors_begin(v); w != mesh.neighbors_end(v); ++w) {
      if ((*mark)[*w] == stamp) continue;
      (*mark)[*w] = stamp;
      if ((mesh.position(*w) - centre).squaredNorm() <= r2) out->push_back(*w);
    }
  }
}

}  // namespace

FlagRun longest_run(const std::vector<char>& flags, bool closed) {
  const int m = static_cast<int>(flags.size());
  FlagRun best;
  int run = 0;
  // Going round twice lets a run wrap; runs are capped at m.
  for (int k = 0; k < (closed ? 2 * m : m); ++k) {
    run = flags[k % m] ? std::min(run + 1, m) : 0;
    if (run > best.length) best.length = run, best.middle = (k - run / 2) % m;
  }
  return best;
}

double region_area(const Mesh& mesh, const std::vector<char>& region) {
  double area = 0;
  for (int v = 0; v < mesh.n_vertices(); ++v)
    if (region[v]) area += mesh.vertex_area(v);
  return area;
}

double kept_relief_share(const Mesh& mesh, const BackgroundResult& fill, const std::vector<char>& region,
                         double rise) {
  if (!fill.ok() || region.size() != static_cast<std::size_t>(mesh.n_vertices())) return -1;
  double relief = 0, kept = 0, volume = 0, kept_volume = 0;
  for (const int v : fill.region_vertices) {
    const double area = mesh.vertex_area(v), height = fill.height[v];
    if (height > 0) {
      volume += area * height;
      if (region[v]) kept_volume += area * height;
    }
    if (height >= rise) {
      relief += area;
      if (region[v]) kept += area;
    }
  }
  if (!(relief > 0)) return -1.0;
  return std::min(kept / relief, kept_volume / volume);
}

double region_iou(const Mesh& mesh, const std::vector<char>& a, const std::vector<char>& b) {
  double both = 0, either = 0;
  for (int v = 0; v < mesh.n_vertices(); ++v) {
    if (a[v] && b[v]) both += mesh.vertex_area(v);
    if (a[v] || b[v]) either += mesh.vertex_area(v);
  }
  return either > 0 ? both / either : 1.0;
}

namespace {

// One sample of the surface in a strip across the contour at a measured point.
struct StripSample {
  double across, height;  // distance inwards, height above the outside plane
  bool inside;            // a vertex of the region
};

// RMS residual of the least-squares quadric height field z = c0 + c1 x + c2 y + c3 x^2 + c4 x y + c5 y^2
// over `vertices`, in the frame of their plane fit (z along its normal; x, y in units of `scale`
// to keep the normal equations conditioned); the plane's own residual with fewer than 12 vertices.
double quadric_residual(const Mesh& mesh, const std::vector<int>& vertices, const VertexPlaneFit& plane,
                        double scale) {
  if (vertices.size() < 12) return plane.residual();
  const Vec3 ax = plane.axes.col(2), ay = plane.axes.col(1);
  Eigen::Matrix<double, 6, 6> normal_matrix = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
  double zz = 0;
  for (const int v : vertices) {
    const Vec3 d = mesh.position(v) - plane.centroid;
    const double x = d.dot(ax) / scale, y = d.dot(ay) / scale, z = d.dot(plane.normal);
    Eigen::Matrix<double, 6, 1> row;
    row << 1, x, y, x * x, x * y, y * y;
    normal_matrix += row * row.transpose();
    rhs += row * z;
    zz += z * z;
  }
  const Eigen::Matrix<double, 6, 1> c = normal_matrix.ldlt().solve(rhs);
  const double sse = zz - 2 * c.dot(rhs) + c.dot(normal_matrix * c);
  return std::sqrt(std::max(0.0, sse) / static_cast<double>(vertices.size()));
}

// Medians of a strip's heights in bins of `bin` across the contour: bin b holds the samples whose
// distance inwards lies in [(b - offset) bin, (b - offset + 1) bin), offset = floor(radius / bin) + 1,
// so one empty bin lies beyond the ball on each side. NaN: an empty bin.
struct StripBins {
  long offset = 0;
  std::vector<double> median;
};

StripBins bin_strip(const std::vector<StripSample>& strip, double bin, double radius) {
  StripBins out;
  out.offset = static_cast<long>(radius / bin) + 1;
  const long n = 2 * out.offset + 1;
  std::vector<std::vector<double>> heights(static_cast<std::size_t>(n));
  for (const StripSample& x : strip) {
    const long b = static_cast<long>(std::floor(x.across / bin)) + out.offset;
    if (b >= 0 && b < n) heights[b].push_back(x.height);
  }
  out.median.assign(static_cast<std::size_t>(n), std::numeric_limits<double>::quiet_NaN());
  for (long b = 0; b < n; ++b)
    if (!heights[b].empty()) out.median[b] = quantile(heights[b], 0.5);
  return out;
}

// The height where one profile's rise levels off (its knee; 0: none found). The strip's samples in
// bins of `bin` across the contour (medians), walked inwards from the first bin at a quarter of
// `step`: the walk stops at the first bin at or past half of it where the slope to the bin two
// further in falls under max(knee_min_slope, knee_relative_slope x the steepest slope so far), and
// reads the higher of that bin and the next. Past the knee the surface is the relief's top: a dome
// keeps rising there, a rim's inner side falls away, so the rise over the whole ball (the profile's
// rise_quantile) reads the step too high or too low.
double knee_height(const StripBins& strip, double bin, double step, const EvidenceOptions& o) {
  const std::vector<double>& median = strip.median;
  const long n = static_cast<long>(median.size());
  auto empty = [&](long b) { return std::isnan(median[b]); };
  long quarter = -1, mid = -1;
  for (long b = strip.offset - 1; b < n && mid < 0; ++b) {  // from one bin outside the contour inwards
    if (empty(b)) continue;
    if (quarter < 0 && median[b] >= 0.25 * step) quarter = b;
    if (median[b] >= 0.5 * step) mid = b;
  }
  if (quarter < 0 || mid < 0) return 0;
  double steepest = 0;
  for (long b = quarter; b < n; ++b) {
    if (empty(b)) continue;
    long next = -1;  // two bins further in (three where one is empty)
    for (long c = b + 2; c < n && c <= b + 3 && next < 0; ++c)
      if (!empty(c)) next = c;
    if (next < 0) return median[b];  // the strip ends: the highest reached
    const double slope = (median[next] - median[b]) / (static_cast<double>(next - b) * bin);
    steepest = std::max(steepest, slope);
    if (b >= mid && slope < std::max(o.knee_min_slope, o.knee_relative_slope * steepest)) {
      for (long c = b + 1; c < next; ++c)
        if (!empty(c)) return std::max(median[b], median[c]);
      return median[b];
    }
  }
  return 0;
}

}  // namespace

StepEvidence measure_step(const Mesh& mesh, const std::vector<SurfacePoint>& contour,
                          const std::vector<char>& region, double h, const EvidenceOptions& options) {
  StepEvidence evidence;
  if (contour.empty() || h <= 0) return evidence;
  const int n = static_cast<int>(contour.size());
  const int count = std::min(n, std::max(1, options.max_profiles));
  const double edge = mesh.average_edge_length();
  evidence.average_edge = edge;
  const double radius = std::max(options.radius * h, options.min_radius_edges * edge);
  const double exclude = std::max(options.outside_from * h, edge);
  const double exclude2 = exclude * exclude;

  const double front_from = std::max(options.front_from * h, options.front_from_edges * edge);
  const double front_to = std::max(options.front_to * h, options.front_to_edges * edge);
  const double front_half_width = std::max(options.front_half_width * h, options.front_half_width_edges * edge);
  const auto point_at = [&](int j) {
    j = options.closed ? (j % n + n) % n : std::clamp(j, 0, n - 1);
    return position(mesh, contour[j]);
  };

  const double strip_half_width = std::max(0.5 * h, 1.5 * edge);
  // Per measured profile: the vertices in a strip across the contour, for the offset to the step
  // (inside ones), the width of the rise and its knee (all) once the step height is known.
  std::vector<std::vector<StripSample>> strips;

  std::vector<int> mark(mesh.n_vertices(), -1), ball;
  std::vector<double> heights;
  std::vector<int> outside, near_outside, far_outside;
  std::vector<double> quadric_residuals;
  std::vector<int> clear_outside;  // the outside vertices beyond quadric_clearance of the region
  const std::vector<char> near_region =
      options.quadric_clearance > 0 ? grown_region(mesh, region, options.quadric_clearance * h) : std::vector<char>{};
  const double gap_bin = std::max(edge, radius / 1024);  // one edge (at most 1024 bins across the ball)
  std::vector<std::vector<double>> gap_bins(static_cast<std::size_t>(radius / gap_bin) + 1);
  const double gap_from = std::max(options.foot_gap_from * h, options.foot_gap_from_edges * edge);
  // The foot gap of one profile (StepProfile::foot_gap); inward and tangent as for the front.
  const auto foot_gap = [&](const Vec3& centre, const Vec3& inward, const Vec3& tangent, double rise) {
    far_outside.clear();
    for (const int v : ball)
      if (!region[v] && -(mesh.position(v) - centre).dot(inward) >= gap_from) far_outside.push_back(v);
    const VertexPlaneFit far_plane = fit_vertex_plane(mesh, far_outside);
    if (static_cast<int>(far_outside.size()) < options.min_side_vertices || far_plane.weight <= 0 || !(rise > 0))
      return 0.0;
    const double level = std::max(options.foot_gap_level * rise, 3 * far_plane.residual());
    for (auto& bin : gap_bins) bin.clear();
    for (const int v : ball) {
      if (region[v]) continue;
      const Vec3 d = mesh.position(v) - centre;
      const double across = -d.dot(inward);  // outwards
      if (across < 0 || std::fabs(d.dot(tangent)) > strip_half_width) continue;
      const std::size_t b = std::min(gap_bins.size() - 1, static_cast<std::size_t>(across / gap_bin));
      gap_bins[b].push_back((mesh.position(v) - far_plane.centroid).dot(far_plane.normal));
    }
    for (std::size_t b = 0; b < gap_bins.size(); ++b)
      if (!gap_bins[b].empty() && quantile(gap_bins[b], 0.5) < level) return b * gap_bin;
    return radius;
  };
  for (int k = 0; k < count; ++k) {
    const int i = static_cast<int>((static_cast<long long>(k) * n) / count);
    ++evidence.attempted;
    const SurfacePoint& p = contour[i];
    const Vec3 centre = position(mesh, p);
    gather_ball(mesh, nearest_corner(mesh, p), centre, radius, &mark, k, &ball);

    // The background plane: area-weighted least squares over the outside vertices.
    outside.clear();
    near_outside.clear();
    int inside_count = 0;
    for (const int v : ball) {
      if (region[v]) {
        ++inside_count;
        continue;
      }
      if ((mesh.position(v) - centre).squaredNorm() < exclude2) {
        near_outside.push_back(v);
        continue;
      }
      outside.push_back(v);
    }
    const VertexPlaneFit plane = fit_vertex_plane(mesh, outside);
    if (inside_count < options.min_side_vertices || static_cast<int>(outside.size()) < options.min_side_vertices ||
        plane.weight <= 0)
      continue;
    const Vec3 mean = plane.centroid, normal = plane.normal;
    const double residual = plane.residual();
    // The roughness: over the outside vertices clear of the region (quadric_clearance), refitted.
    const std::vector<int>* rough = &outside;
    VertexPlaneFit rough_plane = plane;
    if (!near_region.empty()) {
      clear_outside.clear();
      for (const int v : outside)
        if (!near_region[v]) clear_outside.push_back(v);
      rough = &clear_outside;
      rough_plane = fit_vertex_plane(mesh, clear_outside);
    }
    if (static_cast<int>(rough->size()) >= options.min_side_vertices && rough_plane.weight > 0)
      quadric_residuals.push_back(std::min(rough_plane.residual(), quadric_residual(mesh, *rough, rough_plane, h)));

    heights.clear();
    for (const int v : ball)
      if (region[v]) heights.push_back((mesh.position(v) - mean).dot(normal));
    StepProfile profile;
    profile.contour_index = i;
    profile.rise = quantile(heights, options.rise_quantile);
    profile.residual = residual;
    profile.on_step = profile.rise > std::max(options.min_rise * h, options.residual_factor * residual);
    heights.clear();
    for (const int v : near_outside) heights.push_back((mesh.position(v) - mean).dot(normal));
    profile.foot = quantile(heights, 0.5);
    profile.at_foot = heights.empty() || profile.foot < options.max_foot * profile.rise;

    // The front: inside vertices in a box right behind the point, across the contour's
    // tangent in the background plane, on the side where the inside lies.
    Vec3 tangent = point_at(i + 1) - point_at(i - 1);
    tangent -= tangent.dot(normal) * normal;
    Vec3 inside_mean = Vec3::Zero();
    for (const int v : ball)
      if (region[v]) inside_mean += mesh.position(v) - centre;
    if (tangent.squaredNorm() > 0) {
      tangent.normalize();
      Vec3 inward = normal.cross(tangent);
      if (inward.dot(inside_mean) < 0) inward = -inward;
      heights.clear();
      strips.emplace_back();
      for (const int v : ball) {
        const Vec3 d = mesh.position(v) - centre;
        const double across = d.dot(inward), along = d.dot(tangent);
        const double height = (mesh.position(v) - mean).dot(normal);
        if (std::fabs(along) <= strip_half_width) strips.back().push_back({across, height, region[v] != 0});
        if (region[v] && across >= front_from && across <= front_to && std::fabs(along) <= front_half_width)
          heights.push_back(height);
      }
      if (heights.size() >= 2) {
        profile.front_measured = true;
        profile.front = quantile(heights, 0.5);
      }
      profile.foot_gap = foot_gap(centre, inward, tangent, profile.rise);
    } else {
      strips.emplace_back();
    }
    evidence.profiles.push_back(profile);
  }

  if (evidence.profiles.empty()) return evidence;
  std::vector<double> rises, step_rises, residuals;
  int at_foot = 0;
  for (const StepProfile& p : evidence.profiles) {
    rises.push_back(p.rise);
    residuals.push_back(p.residual);
    if (p.on_step) step_rises.push_back(p.rise), at_foot += p.at_foot ? 1 : 0;
  }
  evidence.foot_share = step_rises.empty() ? 1.0 : double(at_foot) / step_rises.size();
  evidence.step_share = double(step_rises.size()) / evidence.profiles.size();
  evidence.rise_median = quantile(rises, 0.5);
  evidence.background_residual = quantile(residuals, 0.5);
  evidence.background_quadric_residual = quantile(quadric_residuals, 0.5);
  if (!step_rises.empty()) {
    evidence.step_height = quantile(step_rises, 0.5);
    if (evidence.step_height > 0)
      evidence.step_spread = (quantile(step_rises, 0.75) - quantile(step_rises, 0.25)) / evidence.step_height;
  }
  // Runs of consecutive profiles (in contour order) whose front is low against the step
  // found along the whole contour, as contour length.
  {
    int low = 0;
    const double front_floor = std::max(options.min_rise * h, options.front_low * evidence.step_height);
    for (StepProfile& p : evidence.profiles) {
      p.front_low = p.front_measured && p.front < front_floor;
      low += p.front_low ? 1 : 0;
    }
    evidence.front_low_share = double(low) / evidence.profiles.size();
    double length = 0;
    for (int j = 0; j + 1 < n || (options.closed && j < n); ++j) length += (point_at(j + 1) - point_at(j)).norm();
    const double spacing = length / count;  // contour length per attempted profile
    const int m = static_cast<int>(evidence.profiles.size());
    std::vector<char> low_flags(m);
    for (int k = 0; k < m; ++k) low_flags[k] = evidence.profiles[k].front_low;
    evidence.longest_front_low = longest_run(low_flags, options.closed).length * spacing;

    // Offset from each point inwards to where the surface first reaches half the step.
    std::vector<double> offsets;
    for (std::size_t k = 0; k < evidence.profiles.size(); ++k) {
      double offset = radius;
      for (const StripSample& x : strips[k])
        if (x.inside && x.height >= 0.5 * evidence.step_height) offset = std::min(offset, std::max(0.0, x.across));
      evidence.profiles[k].offset = offset;
      offsets.push_back(offset);
    }
    evidence.offset_median = quantile(offsets, 0.5);
    const double far = evidence.offset_median + std::max(options.offset_tolerance * h, 2 * edge);
    std::vector<char> far_flags(m);
    for (int k = 0; k < m; ++k) far_flags[k] = evidence.profiles[k].offset > far;
    const FlagRun far_run = longest_run(far_flags, options.closed);
    if (far_run.length > 0) evidence.far_point = evidence.profiles[far_run.middle].contour_index;
    evidence.offset_q90 = quantile(offsets, 0.9);
    evidence.offset_q75 = quantile(offsets, 0.75);
    evidence.offset_q95 = quantile(offsets, 0.95);
    evidence.far_share = double(std::count(far_flags.begin(), far_flags.end(), 1)) / m;
    std::vector<double> gaps;
    for (const StepProfile& p : evidence.profiles)
      if (p.on_step) gaps.push_back(p.foot_gap);
    evidence.foot_gap_median = quantile(gaps, 0.5);
    evidence.foot_gap_q75 = quantile(gaps, 0.75);
    evidence.longest_far = far_run.length * spacing;
    // Per on-step profile, from the strip's heights in bins across the contour: the width of the rise,
    // from the outermost one-edge bin whose median stands a quarter of the step high to the outermost
    // at three quarters; and the height where the rise levels off (the step at the edge).
    std::vector<double> widths, knees;
    const double knee_bin = std::max(options.knee_bin * h, edge);
    for (std::size_t k = 0; k < evidence.profiles.size(); ++k) {
      if (!evidence.profiles[k].on_step) continue;
      const StripBins one_edge = bin_strip(strips[k], edge, radius);
      long quarter = -1, three_quarters = -1;
      for (long b = 0; b < static_cast<long>(one_edge.median.size()); ++b) {
        const double median = one_edge.median[b];
        if (std::isnan(median)) continue;
        if (quarter < 0 && median >= 0.25 * evidence.step_height) quarter = b;
        if (three_quarters < 0 && median >= 0.75 * evidence.step_height) three_quarters = b;
      }
      if (quarter >= 0 && three_quarters >= quarter) widths.push_back(double(three_quarters - quarter) * edge);
      const double knee = knee_height(bin_strip(strips[k], knee_bin, radius), knee_bin, evidence.step_height, options);
      if (knee > 0) knees.push_back(knee);
    }
    evidence.rise_width_median = quantile(widths, 0.5);
    evidence.edge_step_height = quantile(knees, 0.5);
  }
  return evidence;
}

}  // namespace relief_snake

namespace relief_snake {
namespace {
std::string percent(double share) { return std::to_string(static_cast<int>(std::lround(100 * share))) + "%"; }
std::string number(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", x);
  return buffer;
}
}  // namespace

Vec3 vector_area(const std::vector<Vec3>& polyline) {
  Vec3 area = Vec3::Zero();
  const std::size_t n = polyline.size();
  for (std::size_t i = 0; i < n; ++i)
    area += (polyline[i] - polyline[0]).cross(polyline[(i + 1) % n] - polyline[0]);
  return 0.5 * area;
}

Vec3 region_vector_area(const Mesh& mesh, const std::vector<char>& region) {
  Vec3 area = Vec3::Zero();
  for (int f = 0; f < mesh.n_faces(); ++f)
    if (region[mesh.face_vertex(f, 0)] && region[mesh.face_vertex(f, 1)] && region[mesh.face_vertex(f, 2)])
      area += mesh.face_area(f) * mesh.face_normal(f);
  return area;
}

double background_depth_limit(const ContourEvidence& e, const SelfCheckOptions& options) {
  return std::max(options.max_background_depth, e.background_depth_floor);
}

bool background_taken_in(const ContourEvidence& e, const SelfCheckOptions& options) {
  return e.background_measured &&
         deep_background_piece(e.background_depth, e.background_area, background_depth_limit(e, options));
}

bool strayed_from_coarse(double coarse_step_share, double coarse_iou, const SelfCheckOptions& options) {
  return (coarse_step_share >= options.min_step_share && coarse_iou < options.min_coarse_iou) ||
         (coarse_step_share >= options.strayed_min_step_share && coarse_iou < options.strayed_coarse_iou);
}

SelfCheck judge(const ContourEvidence& all, double h, const SelfCheckOptions& options, const Vec3* far_position) {
  SelfCheck check;
  const StepEvidence& evidence = all.step;
  const double measured = evidence.measured_share();
  if (measured < options.min_measured_share)
    check.reasons.push_back("the step could be measured along only " + percent(measured) +
                            " of the contour (too little surface on one side)");
  else if (evidence.step_share < options.min_step_share)
    check.reasons.push_back("only " + percent(evidence.step_share) +
                            " of the contour runs along a step: it may have crossed into the relief or stopped "
                            "on detail or texture");
  // Where the region-wide check ran, only a long, substantial run on a mesh that resolves the step.
  const bool resolved = evidence.average_edge > 0 && h >= 3 * evidence.average_edge;
  const bool far = all.region_checked ? resolved && evidence.longest_far > options.max_far_run_checked * h &&
                                            evidence.far_share > options.min_far_share_checked
                                      : evidence.longest_far > options.max_far_run * h;
  if (far) {
    std::string where;
    if (far_position)
      where = " around (" + number((*far_position)[0]) + ", " + number((*far_position)[1]) + ", " +
              number((*far_position)[2]) + ")";
    check.reasons.push_back("a stretch of the contour " + number(evidence.longest_far / h) + " h long" + where +
                            " runs away from the step: the region takes in background there (a lobe out into "
                            "the background, or a bridge across a concavity)");
  }
  const bool background_inside = background_taken_in(all, options);
  if (background_inside)
    check.reasons.push_back("a piece of about " + number(all.background_area) + " h^2 inside the region around (" +
                            number(all.background_where[0]) + ", " + number(all.background_where[1]) + ", " +
                            number(all.background_where[2]) +
                            ") lies at the background's height: the contour bridges a concavity there, or "
                            "wraps a lobe of background");
  if (all.covered_share >= 0 && all.covered_share < options.min_covered_share)
    check.reasons.push_back("the region covers only " +
                            (all.covered_share < 0.005 ? std::string("under 1%") : percent(all.covered_share)) +
                            " of the surface the picks enclose that stands half a step above the background: the "
                            "snake may have settled on detail or texture inside the relief");
  if (all.beyond_mask_share > options.max_beyond_mask_share)
    check.reasons.push_back(percent(all.beyond_mask_share) +
                            " of the region lies away from anything standing half a step above the background: it "
                            "leaked past the contour or takes in background");
  if (evidence.step_share >= options.min_step_share && evidence.foot_share < options.min_foot_share)
    check.reasons.push_back("only " + percent(evidence.foot_share) +
                            " of the contour sits at the foot of the step; the rest runs partway up it");
  // A coarse contour that sat on a step and a refinement that left it far behind: the
  // deflation carried the snake across the step. (A coarse contour still on the
  // background, from picks far out, may rightly be left behind.)
  // A refinement that let go of background only (a bridged concavity) is not one that crossed.
  const bool coarse_left = strayed_from_coarse(all.coarse_step_share, all.coarse_iou, options) &&
                           !(all.coarse_relief_kept >= options.min_coarse_relief_kept);
  if (coarse_left)
    check.reasons.push_back("the refined region overlaps the coarse contour's by only " + percent(all.coarse_iou) +
                            (all.coarse_relief_kept >= 0
                                 ? " and keeps " + percent(all.coarse_relief_kept) + " of the relief it enclosed"
                                 : std::string()) +
                            ": refinement moved far from where the step was first found");
  if (all.abandoned_area_share >= 0)
    check.reasons.push_back("the refinement was stopped when the contour enclosed only " +
                            percent(all.abandoned_area_share) +
                            " of the area the coarse contour found: it was crossing the relief");
  if (all.abandoned_left_share >= 0)
    check.reasons.push_back("the refinement was stopped when the contour had moved more than 2 h away from " +
                            percent(all.abandoned_left_share) +
                            " of the step the coarse contour found: it was crossing the relief");
  if (all.area_ratio > options.max_area_ratio || all.area_ratio * options.max_area_ratio < 1)
    check.reasons.push_back("the relief region covers " + number(all.area_ratio) +
                            " times the area the contour encloses: the region leaked past the contour or lost a "
                            "piece (the contour may cross itself)");
  if (all.other_side_share > evidence.step_share)
    check.reasons.push_back("the step looks clearer from the other side of the contour: the relief side may be "
                            "wrong (give it)");
  if (evidence.step_height > 0 &&
      (evidence.step_height > options.max_step_ratio * h || evidence.step_height * options.max_step_ratio < h))
    check.reasons.push_back("the step along the contour is " + number(evidence.step_height) +
                            " high, far from the step height used (" + number(h) + ")");
  if (evidence.edge_step_height > 0 && (evidence.edge_step_height > options.max_edge_step_ratio * h ||
                                        evidence.edge_step_height * options.max_edge_step_ratio < h))
    check.reasons.push_back("the step at the contour's edge is " + number(evidence.edge_step_height) +
                            " high, far from the step height used (" + number(h) + ")");
  if (evidence.average_edge > 0 && evidence.foot_gap_median > options.max_foot_gap_edges * evidence.average_edge)
    check.reasons.push_back("the surface keeps rising for about " +
                            number(evidence.foot_gap_median / evidence.average_edge) +
                            " average edges outside the contour: it runs partway up the step (h may be too small)");
  const bool coarse_on_step = all.coarse_step_share >= options.min_step_share ||
                              strayed_from_coarse(all.coarse_step_share, all.coarse_iou, options);
  const double coarse_iou = !coarse_on_step ? 1.0
                            : all.coarse_relief_kept >= 0 ? std::max(all.coarse_iou, all.coarse_relief_kept)
                                                          : all.coarse_iou;
  check.holds = check.reasons.empty();
  // Prefer evidence that holds; then more of the contour on a step, a region that agrees
  // with the coarse phase, and a step that agrees with h.
  const double ratio = evidence.step_height > 0 ? std::fabs(std::log(evidence.step_height / h)) : 2.0;
  check.score = (check.holds ? 10.0 : 0.0) - 2.0 * evidence.far_share - (background_inside ? 1.0 : 0.0) + 2.0 * evidence.step_share * std::min(1.0, measured / 0.6) +
                std::min(coarse_iou, 0.8) - 0.5 * std::min(ratio, 2.0);
  return check;
}

}  // namespace relief_snake

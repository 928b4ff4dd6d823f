#include "relief_snake/foot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Dense>

#include "grid.hpp"

namespace relief_snake {

namespace {

// Snaxel i's inward direction from its neighbours `span` snaxels away: a jagged snake's
// own bisectors point every which way, and moves along them would twist it.
Vec3 smooth_inward(const Snake& snake, int i, int span) {
  const int n = snake.size();
  auto at = [&](int j) {
    if (snake.closed()) return snake[((j % n) + n) % n].position;
    return snake[std::clamp(j, 0, n - 1)].position;
  };
  const Vec3 nrm = normal(snake.mesh(), snake[i].point);
  Vec3 t = at(i + span) - at(i - span);
  t -= t.dot(nrm) * nrm;
  const Vec3 own = snake.inward(i);
  if (!(t.norm() > 0)) return own;
  Vec3 m = nrm.cross(t.normalized());
  if (m.dot(own) < 0) m = -m;  // the side the snake's own inward direction says
  return m;
}

// The surface's profile outwards from snaxel i along `inward`: heights at `distances` (every h / 20,
// at least every half edge, out to the band's end), along the band's mean normal, from the band's
// end, after `inner` heights read inwards of the snaxel at the same spacing (the innermost first).
// *across: with inner > 0, the samples' distances across the background (empty otherwise). Empty
// where the walk or the band fails (the mesh ends first, no normal).
std::vector<double> foot_profile(const Snake& snake, int i, const Vec3& inward, const FootOptions& o,
                                 const std::vector<double>& distances, int inner,
                                 std::vector<SurfacePoint>* samples, std::vector<double>* across) {
  const Mesh& mesh = snake.mesh();
  if (inward.isZero()) return {};
  const int count = static_cast<int>(distances.size()) - 1;
  WalkOptions walk_options;
  walk_options.distance = distances.back();
  walk_options.samples = distances.data();
  walk_options.n_samples = distances.size();
  *samples = walk_points(walk(mesh, snake[i].point, -inward, walk_options));
  if (static_cast<int>(samples->size()) <= count) return {};  // the mesh ends before the band does
  std::vector<SurfacePoint> inside;
  if (inner > 0) {  // distances[1 .. inner] inwards
    WalkOptions in_options;
    in_options.distance = distances[inner];
    in_options.samples = distances.data() + 1;
    in_options.n_samples = inner;
    inside = walk_points(walk(mesh, snake[i].point, inward, in_options));
    if (static_cast<int>(inside.size()) < inner) return {};
  }
  // The background's normal: the surface normal averaged over the band.
  const int band_start = static_cast<int>(std::ceil(o.band_from * o.h / distances[1]));
  Vec3 n = Vec3::Zero();
  for (int k = band_start; k <= count; ++k) n += normal(mesh, (*samples)[k]);
  if (!(n.norm() > 0)) return {};
  n.normalize();
  const Vec3 origin = position(mesh, (*samples)[count]);
  std::vector<double> heights(inner + count + 1);
  for (int j = 0; j < inner; ++j) heights[inner - 1 - j] = (position(mesh, inside[j]) - origin).dot(n);
  for (int k = 0; k <= count; ++k) heights[inner + k] = (position(mesh, (*samples)[k]) - origin).dot(n);
  // With the toe read, each sample's distance from the snaxel across the background (in the band's
  // plane; negative inwards): up a steep blend a walk along the surface covers much less than its
  // length across.
  across->clear();
  if (inner == 0) return heights;
  across->resize(heights.size());
  const Vec3 start = position(mesh, (*samples)[0]);
  auto flat = [&](const Vec3& p) {
    const Vec3 d = p - start;
    return (d - d.dot(n) * n).norm();
  };
  for (int j = 0; j < inner; ++j) (*across)[inner - 1 - j] = -flat(position(mesh, inside[j]));
  for (int k = 0; k <= count; ++k) (*across)[inner + k] = flat(position(mesh, (*samples)[k]));
  return heights;
}

// The foot distance (>= 0) outwards along a profile (foot_profile's heights: `inner` samples inwards of
// the snaxel, then those at `distances`), or a negative value to leave the snaxel; *band_residual: the
// band fit's RMS residual; *toe_fitted: the toe's fit placed the foot (FootOptions::toe).
double foot_of_profile(const std::vector<double>& profile, const std::vector<double>& across_profile, int inner,
                       const std::vector<double>& distances, const FootOptions& o, double* band_residual,
                       bool* toe_fitted) {
  const double h = o.h;
  const int count = static_cast<int>(distances.size()) - 1;
  const int band_start = static_cast<int>(std::ceil(o.band_from * h / distances[1]));
  // A quadratic profile z(d) = a + b d + c d^2 through the band (least squares, d in h).
  const int m = count - band_start + 1;
  if (m < 4 || static_cast<int>(profile.size()) != inner + count + 1) return -1;
  const double* heights = profile.data() + inner;  // heights[k] at distances[k]; k < 0 inwards
  Eigen::MatrixXd A(m, 3);
  Eigen::VectorXd z(m);
  for (int k = band_start; k <= count; ++k) {
    const double d = distances[k] / h;
    A.row(k - band_start) << 1.0, d, d * d;
    z(k - band_start) = heights[k];
  }
  Eigen::Vector3d coef = A.colPivHouseholderQr().solve(z);
  const double residual = std::sqrt((A * coef - z).squaredNorm() / m);
  *band_residual = residual;
  if (!(residual <= o.max_residual * h)) return -1;  // no clean background outside this snaxel
  // The profile is read inwards of the band, down to the snaxel, where its error grows: the
  // prediction's variance is the residual's times the leverage x^T (A^T A)^-1 x. Read at 0.2 h, a
  // quadratic fitted over [0.8, 1.6] h errs by about 4 residuals, a line by 1. So the curvature is
  // kept only where the band shows it (its coefficient at least 3 standard errors), and a sample
  // counts as risen above the background only by 4 times the prediction's standard deviation (the
  // plain 4 residuals fired on the fit's own error: runs of snaxels moved two edges past the foot
  // on a noisy plane, seed 3126 of the randomized suite).
  Eigen::Matrix3d spread = (A.transpose() * A).inverse();  // (A^T A)^-1 of the profile kept
  const double variance = (A * coef - z).squaredNorm() / std::max(1, m - 3);
  if (!(std::fabs(coef(2)) >= 3 * std::sqrt(variance * spread(2, 2)))) {
    const Eigen::MatrixXd line = A.leftCols(2);
    const Eigen::Vector2d fit = line.colPivHouseholderQr().solve(z);
    coef = Eigen::Vector3d(fit(0), fit(1), 0.0);
    spread.setZero();
    spread.topLeftCorner<2, 2>() = (line.transpose() * line).inverse();
  }
  const double spacing = distances[1];
  // Sample k's rise above the background, and the rise the fit's error explains there.
  auto rise = [&](int k) {
    const double d = k * spacing / h;
    return heights[k] - coef.dot(Eigen::Vector3d(1.0, d, d * d));
  };
  auto threshold = [&](int k) {
    const double d = k * spacing / h;
    const Eigen::Vector3d x(1.0, d, d * d);
    return std::max(4 * residual * std::sqrt(1 + x.dot(spread * x)), 0.02 * h);
  };
  auto above = [&](int k) { return rise(k) - threshold(k); };
  // The crossing: from the band inwards, the first sample that rises above the background ends it.
  // A snaxel on the background already (as far as the fit can tell) stays, unless the toe is read:
  // then the crossing is looked for inwards of it.
  const bool risen = above(0) > 0;
  int crossing = 0;
  bool found = false;
  for (int k = risen ? band_start - 1 : -1; k >= -inner && !found; --k)
    if (above(k) > 0) crossing = k, found = true;
  if (!found) return 0;
  if (crossing + 1 >= band_start) return -1;
  double foot = crossing >= 0 ? distances[crossing + 1] : 0.0;
  if (inner == 0) return foot;
  // The toe: sqrt(rise) along the samples from the crossing inwards, while they stay above the
  // threshold and under the cap, fitted by a line in the distance across the background (not the
  // distance walked, which up the blend's slope grows faster and bends the square root the wrong
  // way: the line then met zero up to half an h past the foot); where it meets zero is the foot.
  const double* across = across_profile.data() + inner;
  double sd = 0, sr = 0, sdd = 0, sdr = 0;
  int used = 0;
  for (int k = crossing; k >= -inner; --k) {
    const double r = rise(k);
    if (!(r > threshold(k)) || r >= o.toe_cap * h) break;
    const double d = across[k], q = std::sqrt(r);
    sd += d, sr += q, sdd += d * d, sdr += d * q, ++used;
  }
  if (used < o.toe_min_samples) return foot;
  const double var = sdd - sd * sd / used, cov = sdr - sd * sr / used;
  if (!(var > 0) || !(cov < 0)) return foot;  // sqrt(rise) must grow inwards
  const double slope = cov / var, intercept = (sr - slope * sd) / used;
  const double toe_across = -intercept / slope;
  // Back to distance walked outwards, where the samples' distances across bracket it (the band's
  // inner end at most).
  double toe = distances[band_start - 1];
  for (int k = std::max(crossing, 0); k + 1 < band_start; ++k)
    if (toe_across <= across[k + 1]) {
      const double span = across[k + 1] - across[k];
      const double t = span > 0 ? std::clamp((toe_across - across[k]) / span, 0.0, 1.0) : 0.0;
      toe = distances[k] + t * (distances[k + 1] - distances[k]);
      break;
    }
  if (toe > foot) {
    foot = toe;
    *toe_fitted = true;
  }
  return foot;
}

// The pooled profile of snaxel i: per sample, the median of the profiles of the snaxels within
// `pool` of it along the snake (those that have one); empty with fewer than pool + 1 of them.
std::vector<double> pooled_profile(const std::vector<std::vector<double>>& profiles, int i, int pool, bool closed) {
  const int n = static_cast<int>(profiles.size());
  std::vector<const std::vector<double>*> near;
  for (int k = -pool; k <= pool; ++k) {
    int j = i + k;
    if (closed) j = ((j % n) + n) % n;
    else if (j < 0 || j >= n) continue;
    if (!profiles[j].empty()) near.push_back(&profiles[j]);
  }
  if (static_cast<int>(near.size()) < pool + 1) return {};
  const std::size_t length = near.front()->size();
  std::vector<double> pooled(length), column;
  for (std::size_t s = 0; s < length; ++s) {
    column.clear();
    for (const auto* p : near) column.push_back((*p)[s]);
    std::nth_element(column.begin(), column.begin() + column.size() / 2, column.end());
    pooled[s] = column[column.size() / 2];
  }
  return pooled;
}

}  // namespace

FootResult settle_at_foot(Snake* snake, const FootOptions& o) {
  FootResult result;
  const int n = snake->size();
  std::vector<double> foot(n, -1);
  std::vector<SurfacePoint> samples;
  std::vector<Vec3> inward(n, Vec3::Zero());
  std::vector<double> residuals;
  // Samples every h / 20 (and at least every half edge) out to the band's end.
  const double spacing = std::min(0.05 * o.h, 0.5 * snake->mesh().average_edge_length());
  const int count = static_cast<int>(std::ceil(o.band_to * o.h / spacing));
  std::vector<double> distances(count + 1);
  for (int k = 0; k <= count; ++k) distances[k] = k * spacing;
  const int inner = o.toe ? std::min(count, static_cast<int>(std::ceil(o.toe_inner * o.h / spacing))) : 0;
  std::vector<std::vector<double>> profiles(n), acrosses(n);
  for (int i = 0; i < n; ++i) {
    if (snake->is_end(i)) continue;
    inward[i] = smooth_inward(*snake, i, o.smoothing + 1);
    profiles[i] = foot_profile(*snake, i, inward[i], o, distances, inner, &samples, &acrosses[i]);
  }
  for (int i = 0; i < n; ++i) {
    if (profiles[i].empty()) continue;
    double residual = -1;
    bool toe = false;
    if (o.pool > 0) {
      // Noise and texture independent from one profile to the next cancel in the median: the band's
      // residual, and so the threshold, fall with it (a texture that runs along the contour does not).
      const std::vector<double> pooled = pooled_profile(profiles, i, o.pool, snake->closed());
      const std::vector<double> pooled_across = inner > 0 ? pooled_profile(acrosses, i, o.pool, snake->closed())
                                                          : std::vector<double>{};
      if (!pooled.empty()) foot[i] = foot_of_profile(pooled, pooled_across, inner, distances, o, &residual, &toe);
    } else {
      foot[i] = foot_of_profile(profiles[i], acrosses[i], inner, distances, o, &residual, &toe);
    }
    if (toe) ++result.toe_fitted;
    if (residual >= 0) residuals.push_back(residual);
  }
  // A noisy background hides where the surface leaves it: measured, the snap then puts
  // snaxels on noise bumps outside the foot. Leave such a contour as it is.
  if (!residuals.empty()) {
    std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
    result.background_residual = residuals[residuals.size() / 2];
  }
  if (result.background_residual > o.max_noise * o.h) {
    result.skipped = n;
    result.noisy = true;
    return result;
  }
  if (std::count_if(foot.begin(), foot.end(), [](double f) { return f < 0; }) > o.max_unclean_share * n) {
    result.skipped = n;
    result.unclean = true;
    return result;
  }
  // Median filter along the snake over the snaxels that have a foot.
  std::vector<double> window, smoothed(n, -1);
  for (int i = 0; i < n; ++i) {
    if (foot[i] < 0) continue;
    window.clear();
    for (int k = -o.smoothing; k <= o.smoothing; ++k) {
      int j = i + k;
      if (snake->closed()) j = ((j % n) + n) % n;
      else if (j < 0 || j >= n) continue;
      if (foot[j] >= 0) window.push_back(foot[j]);
    }
    std::nth_element(window.begin(), window.begin() + window.size() / 2, window.end());
    smoothed[i] = window[window.size() / 2];
  }
  // Never move more than 40% of the way to another part of the snake (the far wall
  // of a narrow slot the snake went into, whose snaxels move towards these): the two
  // sides must not meet.
  {
    const double cell = 0.5 * o.h;
    HashGrid grid(n > 0 ? (*snake)[0].position : Vec3::Zero(), cell);
    for (int i = 0; i < n; ++i) grid.add(grid.cell_of((*snake)[i].position), i);
    grid.build();
    const int apart = 4 * o.smoothing + 4;  // snaxels closer along the snake are its own side
    for (int i = 0; i < n; ++i) {
      if (!(smoothed[i] > 0)) continue;
      const Vec3& p = (*snake)[i].position;
      const HashGrid::Cell c = grid.cell_of(p);
      double nearest = std::numeric_limits<double>::infinity();
      const int reach = static_cast<int>(std::ceil(smoothed[i] / (0.4 * cell))) + 1;
      for (int x = -reach; x <= reach; ++x)
        for (int y = -reach; y <= reach; ++y)
          for (int z = -reach; z <= reach; ++z)
            grid.for_each(c + HashGrid::Cell(x, y, z), [&](int j) {
              int gap = std::abs(i - j);
              if (snake->closed()) gap = std::min(gap, n - gap);
              if (gap > apart) nearest = std::min(nearest, ((*snake)[j].position - p).norm());
            });
      smoothed[i] = std::min(smoothed[i], 0.4 * nearest);
    }
  }
  // Move (all outward steps are computed from the snake as it was).
  std::vector<SurfacePoint> target(n);
  for (int i = 0; i < n; ++i) {
    target[i] = (*snake)[i].point;
    if (smoothed[i] > 0) target[i] = walk(snake->mesh(), (*snake)[i].point, -inward[i], WalkOptions{smoothed[i]}).end;
  }
  double total = 0;
  for (int i = 0; i < n; ++i) {
    if (smoothed[i] < 0) {
      ++result.skipped;
    } else if (smoothed[i] > 0) {
      snake->move(i, target[i]);
      ++result.moved;
      total += smoothed[i];
    }
  }
  result.mean_move = result.moved ? total / result.moved : 0;
  return result;
}

WallResult settle_down_walls(const Mesh& mesh, std::vector<SurfacePoint>* contour, const std::vector<char>& region,
                             const WallOptions& options) {
  WallResult result;
  const double edge = mesh.average_edge_length();
  for (SurfacePoint& p : *contour) {
    if (!p.valid()) continue;
    int in = 0;
    for (int k = 0; k < 3; ++k) in += region[mesh.face_vertex(p.face, k)] ? 1 : 0;
    if (in == 0 || in == 3) continue;
    // The background normal: the faces round the outside corners whose corners are all outside.
    Vec3 background = Vec3::Zero(), low = Vec3::Zero();
    int n_low = 0;
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.face_vertex(p.face, k);
      if (region[v]) continue;
      low += mesh.position(v), ++n_low;
      for (const int* f = mesh.faces_begin(v); f != mesh.faces_end(v); ++f) {
        bool outside = true;
        for (int j = 0; j < 3; ++j) outside = outside && !region[mesh.face_vertex(*f, j)];
        if (outside) background += mesh.face_area(*f) * mesh.face_normal(*f);
      }
    }
    if (!(background.norm() > 0)) continue;
    background.normalize();
    if (std::fabs(mesh.face_normal(p.face).dot(background)) > options.max_cosine) continue;
    low /= n_low;
    double height = 0;
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.face_vertex(p.face, k);
      if (region[v]) height += (mesh.position(v) - low).dot(background) / in;
    }
    if (height < options.min_height_edges * edge) continue;
    double up = 0;
    for (int k = 0; k < 3; ++k)
      if (region[mesh.face_vertex(p.face, k)]) up += p.bary[k];
    if (!(up > 0)) continue;  // already on the wall's lower edge
    if (up * height < options.min_snaxel_height_edges * edge) continue;
    Vec3 bary = p.bary;
    for (int k = 0; k < 3; ++k)
      if (region[mesh.face_vertex(p.face, k)]) bary[k] *= options.keep;
    p.bary = bary / bary.sum();
    ++result.moved;
  }
  return result;
}

}  // namespace relief_snake

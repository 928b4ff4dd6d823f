#include "relief_snake/energy.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "relief_snake/error.hpp"

namespace relief_snake {

double tension_energy(double alpha, const Vec3& prev, const Vec3& x, const Vec3& next) {
  return 0.25 * alpha * ((x - prev).norm() + (next - x).norm());
}

double bending_energy(double beta, const Vec3& prev, const Vec3& x, const Vec3& next) {
  const Vec3 a = x - prev, b = next - x;
  const double na = a.norm(), nb = b.norm();
  const double sum = na + nb;
  if (!(na > 0) || !(nb > 0)) return 0;
  const double cos_theta = a.dot(b) / (na * nb);
  return beta * (1 - cos_theta) / (sum * sum);
}

double deflation_energy(double alpha, double beta, double tau, double l, double gamma_sigma2) {
  const double t2 = tau * tau;
  return -0.5 * alpha * (std::sqrt(1 + t2) - 1) * l - 2 * beta * t2 / ((1 + t2) * (1 + t2) * l * l) - gamma_sigma2;
}

double normalise_alpha(double l) {
  // E_t in [0.5 alpha l_min, 0.5 alpha l_max] with l_max = 1.5 l.
  return 1.0 / (0.5 * 1.5 * l);
}

double normalise_beta(double l, double max_turn_degrees) {
  // Largest E_b: sharpest allowed turn with both segments at l_min = 0.5 l.
  const double worst = 1 - std::cos(max_turn_degrees * M_PI / 180.0);
  const double shortest = 2 * 0.5 * l;
  return shortest * shortest / worst;
}

FeatureEnergy::FeatureEnergy(PlanarityField& planarity, double h, double epsilon, int q_samples, bool exact_q)
    : planarity_(planarity), exact_q_(exact_q), q_from_((1 - epsilon) * h), q_to_((1 + epsilon) * h) {
  const int n = std::max(1, q_samples);
  for (int k = 0; k < n; ++k) {
    const double t = n == 1 ? 0.0 : -1.0 + 2.0 * k / (n - 1);
    distances_.push_back((1 + t * epsilon) * h);
  }
}

void FeatureEnergy::trace(const SurfacePoint& x, const Vec3& inward, const double* offsets, int count,
                          QTrace* out) const {
  out->candidates = count;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int k = 0; k < count; ++k) {
    out->offset[k] = offsets[k];
    lo = std::min(lo, offsets[k]);
    hi = std::max(hi, offsets[k]);
  }
  // Sample distances in increasing order; the walk tags each point with its index
  // in this order, which is mapped back to (candidate, sample) below.
  std::array<std::pair<double, int>, 3 * 64 + 6> wanted;
  int n = 0;
  if (exact_q_) {
    for (int k = 0; k < count; ++k) {
      wanted[n++] = {std::max(0.0, q_from_ + offsets[k]), -1};
      wanted[n++] = {std::max(0.0, q_to_ + offsets[k]), -1};
    }
  } else {
    const int q = static_cast<int>(distances_.size());
    if (count * q > 3 * 64) throw Error("q_samples must be at most 64");
    for (int k = 0; k < count; ++k)
      for (int j = 0; j < q; ++j) wanted[n++] = {std::max(0.0, distances_[j] + offsets[k]), k * q + j};
  }
  std::sort(wanted.begin(), wanted.begin() + n);
  std::array<double, 3 * 64 + 6> distances;
  for (int i = 0; i < n; ++i) distances[i] = wanted[i].first;
  WalkOptions walk_options;
  walk_options.distance = n > 0 ? distances[n - 1] : 0;
  walk_options.samples = distances.data();
  walk_options.n_samples = n;
  walk_options.record_crossings = exact_q_;
  walk_options.crossings_from = q_from_ + lo;
  walk_options.crossings_to = q_to_ + hi;
  out->points = walk(planarity_.mesh(), x, inward, walk_options).points;
  for (WalkPoint& p : out->points)
    if (p.tag >= 0) p.tag = wanted[p.tag].second;
}

void FeatureEnergy::corners(const SurfacePoint* candidates, int count, const QTrace& trace,
                            std::vector<int>* out) const {
  const Mesh& mesh = planarity_.mesh();
  auto add = [&](const SurfacePoint& p) {
    if (!p.valid() || p.face >= mesh.n_faces()) return;  // evaluate() reports it
    for (int k = 0; k < 3; ++k) out->push_back(mesh.face_vertex(p.face, k));
  };
  for (int k = 0; k < count; ++k) add(candidates[k]);
  for (const WalkPoint& p : trace.points) add(p.point);
}

double FeatureEnergy::evaluate(const SurfacePoint& x, const QTrace& trace, int k, SurfacePoint* q) const {
  const int samples = static_cast<int>(distances_.size());
  const double lo = q_from_ + trace.offset[k] - 1e-12, hi = q_to_ + trace.offset[k] + 1e-12;
  double q_value = std::numeric_limits<double>::infinity();
  for (const WalkPoint& p : trace.points) {
    const bool mine = exact_q_ ? (p.distance >= lo && p.distance <= hi) : (p.tag >= 0 && p.tag / samples == k);
    if (!mine) continue;
    const double value = planarity_.cached_filtered(p.point);
    if (std::isnan(value)) return value;  // not computed yet
    if (value < q_value) {
      q_value = value;
      if (q) *q = p.point;
    }
  }
  if (q_value == std::numeric_limits<double>::infinity()) return 0;  // the mesh ends before the window
  const double d = planarity_.cached_filtered(x) - q_value;  // NaN if P^(x) is missing
  if (std::isnan(d)) return d;
  if (d > 0) return d * d;
  // Optional barrier: a snaxel on a convex crease looking inwards (P^(x) < P^(q))
  // is penalised instead of ignored, so it cannot slip past the step's top edge.
  return convex_barrier_ ? -d * d : 0.0;
}

double FeatureEnergy::unscaled(const SurfacePoint& x, const Vec3& inward) {
  QTrace t;
  const double zero = 0;
  trace(x, inward, &zero, 1, &t);
  std::vector<int> vertices;
  corners(&x, 1, t, &vertices);
  planarity_.prefetch_filtered(vertices);
  return evaluate(x, t, 0, &last_q_);
}

}  // namespace relief_snake

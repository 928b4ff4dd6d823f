#include "relief_snake/energy.hpp"

#include <cmath>
#include <limits>

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

void FeatureEnergy::q_candidates(const SurfacePoint& x, const Vec3& inward, std::vector<SurfacePoint>* out) const {
  if (exact_q_)
    walk_stretch(planarity_.mesh(), x, inward, q_from_, q_to_, out);
  else
    walk_sampled(planarity_.mesh(), x, inward, distances_, out);
}

double FeatureEnergy::unscaled(const SurfacePoint& x, const Vec3& inward) {
  double value = 0;
  unscaled(&x, 1, inward, &value);
  return value;
}

bool FeatureEnergy::exploring() const { return planarity_.raw_count() != mark_; }

void FeatureEnergy::mark() { mark_ = planarity_.raw_count(); }

void FeatureEnergy::prefetch(const std::vector<SurfacePoint>& points, const std::vector<Vec3>& inward) {
  const Mesh& mesh = planarity_.mesh();
  if (samples_.empty()) samples_.resize(1);
  vertices_.clear();
  auto corners = [&](const SurfacePoint& p) {
    if (!p.valid() || p.face >= mesh.n_faces()) return;
    for (int k = 0; k < 3; ++k) vertices_.push_back(mesh.face_vertex(p.face, k));
  };
  for (std::size_t i = 0; i < points.size(); ++i) {
    corners(points[i]);
    q_candidates(points[i], inward[i], &samples_[0]);
    for (const SurfacePoint& q : samples_[0]) corners(q);
  }
  planarity_.prefetch_filtered(vertices_);
}

void FeatureEnergy::unscaled(const SurfacePoint* xs, int count, const Vec3& inward, double* out) {
  const Mesh& mesh = planarity_.mesh();
  if (static_cast<int>(samples_.size()) < count) samples_.resize(count);
  // Gather every face corner first, so the missing planarity is one parallel batch.
  vertices_.clear();
  auto corners = [&](const SurfacePoint& p) {
    if (!p.valid() || p.face >= mesh.n_faces()) return;  // filtered() reports it below
    for (int k = 0; k < 3; ++k) vertices_.push_back(mesh.face_vertex(p.face, k));
  };
  for (int i = 0; i < count; ++i) {
    q_candidates(xs[i], inward, &samples_[i]);
    corners(xs[i]);
    for (const SurfacePoint& q : samples_[i]) corners(q);
  }
  planarity_.prefetch_filtered(vertices_);

  for (int i = 0; i < count; ++i) {
    out[i] = 0;
    if (samples_[i].empty()) continue;  // the mesh ends before (1 - eps) h: no step inside
    double q_value = std::numeric_limits<double>::infinity();
    for (const SurfacePoint& q : samples_[i]) {
      const double value = planarity_.filtered(q);
      if (value < q_value) {
        q_value = value;
        last_q_ = q;
      }
    }
    const double d = planarity_.filtered(xs[i]) - q_value;
    if (d > 0) {
      out[i] = d * d;
    } else if (convex_barrier_) {
      // Optional barrier: a snaxel on a convex crease looking inwards (P^(x) < P^(q))
      // is penalised instead of ignored, so it cannot slip past the step's top edge.
      out[i] = -d * d;
    }
  }
}

}  // namespace relief_snake

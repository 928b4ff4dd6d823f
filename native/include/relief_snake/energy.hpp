#pragma once
// The snake's energy terms (Section 5) and their normalisation (7.2.3):
// tension (Eqn. 3), bending (4), relief-step feature energy (8) and deflation (9).
#include <vector>

#include "relief_snake/planarity.hpp"
#include "relief_snake/surface_point.hpp"

namespace relief_snake {

/// E_t(i) = alpha/4 (|v_{i-1} v_i| + |v_i v_{i+1}|)   (Eqn. 3)
double tension_energy(double alpha, const Vec3& prev, const Vec3& x, const Vec3& next);
/// E_b(i) = beta (1 - cos theta_i) / (|v_{i-1} v_i| + |v_i v_{i+1}|)^2   (Eqn. 4)
double bending_energy(double beta, const Vec3& prev, const Vec3& x, const Vec3& next);
/// E_d(i) at the inside candidate   (Eqn. 9); sigma2_term = gamma sigma^2, or 0 after the coarse phase.
double deflation_energy(double alpha, double beta, double tau, double local_length, double gamma_sigma2);

/// alpha so that E_t lies in [0, 1] for segment lengths in [0.5 l, 1.5 l].
double normalise_alpha(double l);
/// beta so that E_b lies in [0, 1] for segments >= 0.5 l and turns <= max_turn_degrees.
double normalise_beta(double l, double max_turn_degrees);

/// The relief-step feature energy E_f^3 (Eqn. 8) with q_i searched over
/// (1 +- epsilon) h along the inward direction (Section 5.3.3): at q_samples
/// evenly spaced points (the paper's "small set of candidate positions"), or,
/// with exact_q, over the whole stretch (the minimum of the piecewise-linear
/// P^ along it, found at its edge crossings and ends).
class FeatureEnergy {
 public:
  FeatureEnergy(PlanarityField& planarity, double h, double epsilon, int q_samples, bool exact_q = false);
  /// E_f at x, with q searched along `inward` from x; gamma applied by the caller.
  /// Returns (P^(x) - P^(q))^2 if P^(x) > P^(q), else 0 (i.e. -E_f / gamma).
  double unscaled(const SurfacePoint& x, const Vec3& inward);
  /// unscaled() at count points with the same inward direction, into out[k];
  /// the planarity they need is computed as one parallel batch.
  void unscaled(const SurfacePoint* xs, int count, const Vec3& inward, double* out);
  /// Computes, as one parallel batch, the planarity unscaled() will need at
  /// and around these points (their corners and their q samples along
  /// inward[k]). Pure speed-up: values do not depend on it.
  void prefetch(const std::vector<SurfacePoint>& points, const std::vector<Vec3>& inward);
  /// True if planarity had to be computed since the last mark(): the snake is
  /// in new territory, and prefetch() pays off.
  bool exploring() const;
  void mark();
  /// The q found by the last unscaled() call (for tests and drawing).
  const SurfacePoint& last_q() const { return last_q_; }
  PlanarityField& planarity() { return planarity_; }
  /// Also penalise P^(x) < P^(q) (returns -(P^(x) - P^(q))^2 there). Not in the paper.
  void set_convex_barrier(bool on) { convex_barrier_ = on; }

 private:
  /// Where q is searched for x: the sample points, or the stretch's crossings and ends.
  void q_candidates(const SurfacePoint& x, const Vec3& inward, std::vector<SurfacePoint>* out) const;

  PlanarityField& planarity_;
  bool exact_q_ = false;
  double q_from_ = 0, q_to_ = 0;  // the searched stretch, (1 -+ epsilon) h
  std::vector<double> distances_;
  std::vector<std::vector<SurfacePoint>> samples_;  // per point of a batch
  std::vector<int> vertices_;                       // the batch's face corners
  SurfacePoint last_q_;
  bool convex_barrier_ = false;
  std::size_t mark_ = 0;  // planarity raw_count() at the last mark()
};

}  // namespace relief_snake

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

/// Where q is searched for up to three candidate positions of one snaxel: the points
/// of a single straight walk from the snaxel along its inward direction. Candidate k
/// sits at `offset[k]` along that line (0 for the snaxel, +-tau l_i for the greedy
/// candidates, which the paper places on the same bisector), so its q window is
/// (1 -+ epsilon) h + offset[k] along the walk.
struct QTrace {
  std::vector<WalkPoint> points;  ///< samples (tag = candidate * q_samples + sample) or crossings (tag -1)
  double offset[3] = {0, 0, 0};
  int candidates = 1;
};

/// The relief-step feature energy E_f^3 (Eqn. 8) with q_i searched over
/// (1 +- epsilon) h along the inward direction (Section 5.3.3): at q_samples
/// evenly spaced points (the paper's "small set of candidate positions"), or,
/// with exact_q, over the whole stretch (the minimum of the piecewise-linear
/// P^ along it, found at its edge crossings and ends).
///
/// The greedy loop uses it in three steps so that the walks and the energies can run
/// on several threads: trace() the q line (thread-safe), gather corners() and
/// prefetch their P^ (one parallel batch), then evaluate() (thread-safe, reads only
/// prefetched values).
class FeatureEnergy {
 public:
  FeatureEnergy(PlanarityField& planarity, double h, double epsilon, int q_samples, bool exact_q = false);

  /// The q line from x along `inward` for `count` (1..3) candidates at `offsets`.
  void trace(const SurfacePoint& x, const Vec3& inward, const double* offsets, int count, QTrace* out) const;
  /// Appends the mesh vertices whose P^ evaluate() reads for these candidate points and trace.
  void corners(const SurfacePoint* candidates, int count, const QTrace& trace, std::vector<int>* out) const;
  /// (P^(x) - P^(q))^2 if P^(x) > P^(q), else 0 (i.e. -E_f / gamma), for candidate k of
  /// the trace at x. 0 when the mesh ends before its window. Reads cached P^ only and
  /// never computes any: NaN when some of what it needs (corners()) is missing.
  double evaluate(const SurfacePoint& x, const QTrace& trace, int k, SurfacePoint* q = nullptr) const;

  /// One point, computing what it needs (tests and tools; not for threads).
  double unscaled(const SurfacePoint& x, const Vec3& inward);
  /// The q found by the last unscaled() call.
  const SurfacePoint& last_q() const { return last_q_; }
  /// Also penalise P^(x) < P^(q) (returns -(P^(x) - P^(q))^2 there). Not in the paper.
  void set_convex_barrier(bool on) { convex_barrier_ = on; }
  PlanarityField& planarity() { return planarity_; }

 private:
  PlanarityField& planarity_;
  bool exact_q_ = false;
  double q_from_ = 0, q_to_ = 0;  // the searched stretch, (1 -+ epsilon) h
  std::vector<double> distances_;  // the q_samples distances in it
  bool convex_barrier_ = false;
  SurfacePoint last_q_;
};

}  // namespace relief_snake

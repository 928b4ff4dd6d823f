#pragma once
// Greedy evolution (Sections 5.1, 6): one iteration moves each snaxel to the
// lowest-energy of {stay, inside candidate, outside candidate}; a phase repeats
// iterations with the housekeeping until nothing moves or the cap is hit.
#include <functional>
#include <vector>

#include "relief_snake/energy.hpp"
#include "relief_snake/segment.hpp"
#include "relief_snake/snake.hpp"

namespace relief_snake {

/// Everything that differs between the coarse, refinement and stabilisation phases.
struct PhaseSettings {
  const char* name = "";
  double l = 0;               ///< nominal segment length
  double alpha = 0, beta = 0, gamma = 0;
  double w_int = 1, w_f = 1, w_d = 1;
  double gamma_sigma2 = 0;    ///< the -gamma sigma^2 denoising term of Eqn. 9 (coarse only)
  double tau = 0.2;
  double max_turn_degrees = 160;
  int lock_interval = 10;
  int max_iterations = 3000;
  bool remove_loops = true;   ///< cut off self-intersection loops (not in the paper)
  int min_snaxels = 4;        ///< fewer means the snake collapsed
  /// A height per mesh vertex (#V; e.g. above the background model, relief_mask.hpp) that no move may
  /// rise above barrier_level to, unless it ends lower than where the snaxel is: deflation cannot
  /// carry a snaxel onto the relief (not in the paper). Null: no barrier.
  const std::vector<double>* barrier = nullptr;
  double barrier_level = 0;
  /// Asked every lock_interval iterations: true abandons the phase (PhaseOutcome::abandoned), e.g.
  /// a refinement that is carrying the snake across the relief. Empty: never.
  std::function<bool(const Snake&)> abandon;
};

struct PhaseOutcome {
  int iterations = 0;
  bool converged = false;
  bool cancelled = false;
  bool collapsed = false;
  bool abandoned = false;  ///< PhaseSettings::abandon said so
};

/// Energy of snaxel i of `snake` if it were at candidate x (without
/// deflation), given FeatureEnergy::unscaled() there.
double snaxel_energy(const Snake& snake, int i, const SurfacePoint& x, double feature_unscaled,
                     const PhaseSettings& phase);

class WorkerPool;
struct GreedyWorkspace;  // reusable buffers of greedy_iteration()

/// One greedy iteration; returns the number of snaxels that moved. pool (optional)
/// spreads the walks and energies over threads; the result does not depend on it.
/// workspace (optional) keeps buffers between calls.
int greedy_iteration(Snake& snake, FeatureEnergy& feature, const PhaseSettings& phase, WorkerPool* pool = nullptr,
                     GreedyWorkspace* workspace = nullptr);

/// Runs a phase to convergence (nothing moved, housekeeping changed nothing, or the
/// shape stopped changing) or the cap.
PhaseOutcome run_phase(Snake& snake, FeatureEnergy& feature, const PhaseSettings& phase,
                       const ProgressCallback& progress, WorkerPool* pool = nullptr);

}  // namespace relief_snake

#include "relief_snake/evolution.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "worker_pool.hpp"

namespace relief_snake {

double snaxel_energy(const Snake& snake, int i, const SurfacePoint& x, double feature_unscaled,
                     const PhaseSettings& phase) {
  const Vec3 p = position(snake.mesh(), x);
  const int ip = snake.prev(i), in = snake.next(i);
  double internal = 0;
  if (ip >= 0 && in >= 0) {
    const Vec3& a = snake[ip].position;
    const Vec3& b = snake[in].position;
    internal = tension_energy(phase.alpha, a, p, b) + bending_energy(phase.beta, a, p, b);
  } else if (ip >= 0 || in >= 0) {
    // Open end: one segment, counted on both sides so E_t keeps its scale; no bending.
    const Vec3& a = snake[ip >= 0 ? ip : in].position;
    internal = tension_energy(phase.alpha, a, p, a);
  }
  return phase.w_int * internal - phase.w_f * phase.gamma * feature_unscaled;
}

// One snaxel's greedy step: its three candidates, the q line(s), the decision.
struct GreedyProbe {
  int i = 0;
  Vec3 inward = Vec3::Zero();
  double li = 0;
  SurfacePoint candidate[3];  // stay, inside, outside
  QTrace trace[3];            // interior snaxels: trace[0] for all three; open ends: one each
  int traces = 0;             // 0: nothing to evaluate (no inward direction)
  int decision = 0;           // 0 stay, 1 inside, 2 outside
  bool missing = false;       // its energies need planarity not computed yet
};

namespace {

// Below this many probes a colour class runs on the calling thread: waking the
// workers costs more than the work.
constexpr int kParallelProbes = 24;

void parallel_for(WorkerPool* pool, int count, const std::function<void(int)>& task) {
  if (!pool || pool->size() == 1 || count < kParallelProbes) {
    for (int k = 0; k < count; ++k) task(k);
    return;
  }
  pool->run(count, [&](int item, int) { task(item); });
}

}  // namespace

struct GreedyWorkspace {
  std::vector<GreedyProbe> probes;
  std::vector<int> vertices;
  std::vector<char> moved_before;
  std::vector<int> indices;
  std::vector<int> retry;
};


int greedy_iteration(Snake& snake, FeatureEnergy& feature, const PhaseSettings& phase, WorkerPool* pool,
                     GreedyWorkspace* workspace) {
  std::unique_ptr<GreedyWorkspace> owned;
  if (!workspace) {
    owned = std::make_unique<GreedyWorkspace>();
    workspace = owned.get();
  }
  GreedyWorkspace& w = *workspace;
  const Mesh& mesh = snake.mesh();
  const int n = snake.size();
  // After a loop was cut, every snaxel is looked at again (the cut shifts the colour classes).
  // One whose flags are clear and none of whose neighbours moved earlier in this iteration has the
  // position and neighbours it had when it last decided to stay: it would stay again, so it is
  // skipped (the moves, and so the result, are those of looking at it; an iteration after a cut
  // used to cost a full pass of walks).
  const bool revisit = snake.take_moved_flags(&w.moved_before);
  auto evaluated = [&](int i) {
    // If it and its neighbours stood still last time, its energies are unchanged.
    const int ip = snake.prev(i), in = snake.next(i);
    if (snake[i].locked) return false;
    if (w.moved_before[i] || (ip >= 0 && w.moved_before[ip]) || (in >= 0 && w.moved_before[in])) return true;
    return revisit && ((ip >= 0 && snake[ip].moved) || (in >= 0 && snake[in].moved));
  };
  const bool use_feature = phase.w_f != 0 && phase.gamma != 0;

  // Snaxels are visited in colour classes, every other snaxel at a time, so that no
  // two snaxels of a class are neighbours: within a class the moves are independent
  // and their evaluation runs in parallel, each seeing its neighbours' latest
  // positions (as a sequential sweep would see one of them). An odd closed snake
  // puts its last snaxel, neighbour of the first, in a class of its own. The result
  // does not depend on the number of threads.
  const int classes = snake.closed() && n % 2 == 1 ? 3 : 2;
  int moved = 0;
  for (int c = 0; c < classes; ++c) {
    w.indices.clear();
    for (int i = c == 2 ? n - 1 : c; i < n; i += 2) {
      if (c == 0 && classes == 3 && i == n - 1) break;
      if (evaluated(i)) w.indices.push_back(i);
      if (c == 2) break;
    }
    const int count = static_cast<int>(w.indices.size());
    if (count == 0) continue;
    if (static_cast<int>(w.probes.size()) < count) w.probes.resize(count);

    // 1. Candidates and q lines (walks only: thread-safe).
    parallel_for(pool, count, [&](int k) {
      GreedyProbe& p = w.probes[k];
      p.i = w.indices[k];
      p.decision = 0;
      p.traces = 0;
      const Snaxel& s = snake[p.i];
      p.inward = snake.inward(p.i);
      if (p.inward.isZero()) return;
      p.li = snake.local_length(p.i);
      const double step = phase.tau * p.li;
      p.candidate[0] = s.point;
      if (snake.is_end(p.i)) {
        // Open ends slide along the mesh boundary; each candidate gets its own q line.
        const SurfacePoint a = slide_along_boundary(mesh, s.point, step);
        const SurfacePoint b = slide_along_boundary(mesh, s.point, -step);
        const bool a_inside = (position(mesh, a) - s.position).dot(p.inward) >= 0;
        p.candidate[1] = a_inside ? a : b;
        p.candidate[2] = a_inside ? b : a;
        p.traces = 3;
        const double zero = 0;
        if (use_feature)
          for (int t = 0; t < 3; ++t) feature.trace(p.candidate[t], p.inward, &zero, 1, &p.trace[t]);
      } else {
        p.candidate[1] = walk(mesh, s.point, p.inward, WalkOptions{step}).end;
        p.candidate[2] = walk(mesh, s.point, -p.inward, WalkOptions{step}).end;
        p.traces = 1;
        // The candidates lie on the bisector through the snaxel: one walk along it
        // holds the q windows of all three.
        const double offsets[3] = {0, step, -step};
        if (use_feature) feature.trace(s.point, p.inward, offsets, 3, &p.trace[0]);
      }
    });

    // 2. Energies and decisions (reads cached planarity only: thread-safe). A probe
    // that needs planarity not computed yet gets NaN energies and is done again below.
    auto decide = [&](int k) {
      GreedyProbe& p = w.probes[k];
      p.missing = false;
      if (p.traces == 0) return;
      double f[3] = {0, 0, 0};
      if (use_feature)
        for (int j = 0; j < 3; ++j) {
          f[j] = p.traces == 3 ? feature.evaluate(p.candidate[j], p.trace[j], 0)
                               : feature.evaluate(p.candidate[j], p.trace[0], j);
          if (std::isnan(f[j])) {
            p.missing = true;
            return;
          }
        }
      const double e_stay = snaxel_energy(snake, p.i, p.candidate[0], f[0], phase);
      double e_in = snaxel_energy(snake, p.i, p.candidate[1], f[1], phase);
      if (phase.w_d != 0)
        e_in += phase.w_d * deflation_energy(phase.alpha, phase.beta, phase.tau, p.li, phase.gamma_sigma2);
      double e_out = snaxel_energy(snake, p.i, p.candidate[2], f[2], phase);
      if (phase.barrier) {
        // A move onto the relief (above the barrier, and higher than the snaxel stands) is not one.
        const auto height = [&](int v) { return (*phase.barrier)[v]; };
        const double here = interpolate(mesh, p.candidate[0], height);
        const double limit = std::max(here, phase.barrier_level);
        constexpr double kForbidden = std::numeric_limits<double>::infinity();
        if (interpolate(mesh, p.candidate[1], height) > limit) e_in = kForbidden;
        if (interpolate(mesh, p.candidate[2], height) > limit) e_out = kForbidden;
      }
      if (e_in < e_stay && e_in <= e_out) p.decision = 1;
      else if (e_out < e_stay && e_out < e_in) p.decision = 2;
    };
    parallel_for(pool, count, decide);

    // 3. The missing planarity, as one parallel batch, then those probes again.
    if (use_feature) {
      w.vertices.clear();
      w.retry.clear();
      for (int k = 0; k < count; ++k) {
        const GreedyProbe& p = w.probes[k];
        if (!p.missing) continue;
        w.retry.push_back(k);
        for (int t = 0; t < p.traces; ++t)
          feature.corners(p.traces == 3 ? &p.candidate[t] : p.candidate, p.traces == 3 ? 1 : 3, p.trace[t],
                          &w.vertices);
      }
      if (!w.retry.empty()) {
        feature.planarity().prefetch_filtered(w.vertices);
        parallel_for(pool, static_cast<int>(w.retry.size()), [&](int r) { decide(w.retry[r]); });
      }
    }

    // 4. The moves.
    for (int k = 0; k < count; ++k) {
      const GreedyProbe& p = w.probes[k];
      if (p.decision == 0) continue;
      snake.step(p.i, p.candidate[p.decision]);
      ++moved;
    }
  }
  return moved;
}

PhaseOutcome run_phase(Snake& snake, FeatureEnergy& feature, const PhaseSettings& phase,
                       const ProgressCallback& progress, WorkerPool* pool) {
  PhaseOutcome outcome;
  GreedyWorkspace workspace;
  const double lock_distance = 2 * phase.tau * phase.l;
  std::vector<Vec3> checkpoint;
  for (int iteration = 1; iteration <= phase.max_iterations; ++iteration) {
    outcome.iterations = iteration;
    int changes = greedy_iteration(snake, feature, phase, pool, &workspace);

    // Oscillation lock (Section 6.1): every lock_interval iterations, a snaxel
    // that got less than 2 tau l from where it was is frozen for the phase.
    snake.update_locks(phase.lock_interval, lock_distance);
    changes += snake.remove_sharp_turns(phase.max_turn_degrees);
    changes += snake.resample(phase.l);
    if (phase.remove_loops) changes += snake.remove_loops();
    changes += snake.trim_boundary_ends();

    if (snake.size() < phase.min_snaxels) {
      outcome.collapsed = true;
      return outcome;
    }
    if (progress) {
      Progress p;
      p.phase = phase.name;
      p.iteration = iteration;
      p.snaxels = snake.size();
      p.contour = [&snake] {  // in file coordinates, like every result
        std::vector<Vec3> line = snake.polyline();
        for (Vec3& q : line) q = snake.mesh().to_file(q);
        return line;
      };
      if (!progress(p)) {
        outcome.cancelled = true;
        return outcome;
      }
    }
    if (changes == 0) {
      outcome.converged = true;
      return outcome;
    }
    // The lock's rule applied to the snake's shape, so that resampling (which makes
    // new, unlocked snaxels) cannot keep a phase alive: every lock_interval
    // iterations, if no snaxel is farther than 2 tau l from the snake as it was
    // lock_interval iterations ago, what still moves is a slow circulation along
    // the contour (a few snaxels trading places with splits and merges), not
    // progress, and the phase has converged.
    if (iteration % phase.lock_interval == 0) {
      if (phase.abandon && phase.abandon(snake)) {
        outcome.abandoned = true;
        return outcome;
      }
      if (!checkpoint.empty() && snake.within(checkpoint, lock_distance)) {
        outcome.converged = true;
        return outcome;
      }
      checkpoint = snake.polyline();
    }
  }
  return outcome;
}

}  // namespace relief_snake

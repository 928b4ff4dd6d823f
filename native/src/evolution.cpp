#include "relief_snake/evolution.hpp"

#include <vector>

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

int greedy_iteration(Snake& snake, FeatureEnergy& feature, const PhaseSettings& phase) {
  const Mesh& mesh = snake.mesh();
  const int n = snake.size();
  std::vector<char> moved_before(n);
  for (int i = 0; i < n; ++i) moved_before[i] = snake[i].moved;
  auto evaluated = [&](int i) {
    // If it and its neighbours stood still last time, its energies are unchanged.
    const int ip = snake.prev(i), in = snake.next(i);
    return !snake[i].locked &&
           (moved_before[i] || (ip >= 0 && moved_before[ip]) || (in >= 0 && moved_before[in]));
  };
  // While the snake is entering new territory (planarity was computed since
  // the last iteration began), compute what this one will need as one parallel batch
  // first. The candidates are within tau l of the snaxels, so their q samples
  // fall mostly on the same faces.
  const bool exploring = feature.exploring();
  feature.mark();
  if (phase.w_f != 0 && phase.gamma != 0 && exploring) {
    std::vector<SurfacePoint> points;
    std::vector<Vec3> inwards;
    for (int i = 0; i < n; ++i) {
      if (!evaluated(i) || snake.is_end(i)) continue;
      const Vec3 inward = snake.inward(i);
      if (inward.isZero()) continue;
      points.push_back(snake[i].point);
      inwards.push_back(inward);
    }
    feature.prefetch(points, inwards);
  }
  int moved = 0;
  for (int i = 0; i < n; ++i) {
    Snaxel& s = snake[i];
    const bool evaluate = evaluated(i);
    s.moved = false;
    if (!evaluate) continue;

    const Vec3 inward = snake.inward(i);
    if (inward.isZero()) continue;
    const double li = snake.local_length(i);
    const double step = phase.tau * li;
    SurfacePoint inside, outside;
    if (snake.is_end(i)) {
      // Open ends slide along the mesh boundary.
      const SurfacePoint a = slide_along_boundary(mesh, s.point, step);
      const SurfacePoint b = slide_along_boundary(mesh, s.point, -step);
      const bool a_inside = (position(mesh, a) - s.position).dot(inward) >= 0;
      inside = a_inside ? a : b;
      outside = a_inside ? b : a;
    } else {
      inside = walk(mesh, s.point, inward, step).end;
      outside = walk(mesh, s.point, -inward, step).end;
    }
    // Stay, inside, outside: one planarity batch for the three.
    const SurfacePoint candidates[3] = {s.point, inside, outside};
    double f[3] = {0, 0, 0};
    if (phase.w_f != 0 && phase.gamma != 0) feature.unscaled(candidates, 3, inward, f);
    const double e_stay = snaxel_energy(snake, i, s.point, f[0], phase);
    double e_in = snaxel_energy(snake, i, inside, f[1], phase);
    if (phase.w_d != 0)
      e_in += phase.w_d * deflation_energy(phase.alpha, phase.beta, phase.tau, li, phase.gamma_sigma2);
    const double e_out = snaxel_energy(snake, i, outside, f[2], phase);
    if (e_in < e_stay && e_in <= e_out) {
      snake.move(i, inside);
    } else if (e_out < e_stay && e_out < e_in) {
      snake.move(i, outside);
    } else {
      continue;
    }
    snake[i].moved = true;
    ++moved;
  }
  return moved;
}

PhaseOutcome run_phase(Snake& snake, FeatureEnergy& feature, const PhaseSettings& phase,
                       const ProgressCallback& progress) {
  PhaseOutcome outcome;
  const double lock_distance = 2 * phase.tau * phase.l;
  std::vector<Vec3> polyline, checkpoint;
  for (int iteration = 1; iteration <= phase.max_iterations; ++iteration) {
    outcome.iterations = iteration;
    int changes = greedy_iteration(snake, feature, phase);

    // Oscillation lock (Section 6.1): every lock_interval iterations, a snaxel
    // that got less than 2 tau l from where it was is frozen for the phase.
    for (int i = 0; i < snake.size(); ++i) {
      Snaxel& s = snake[i];
      if (++s.age < phase.lock_interval || s.locked) continue;
      if ((s.position - s.anchor).norm() < lock_distance) s.locked = true;
      s.anchor = s.position;
      s.age = 0;
    }
    changes += snake.remove_sharp_turns(phase.max_turn_degrees);
    changes += snake.resample(phase.l);
    if (phase.remove_loops) changes += snake.remove_loops();

    if (snake.size() < phase.min_snaxels) {
      outcome.collapsed = true;
      return outcome;
    }
    if (progress) {
      polyline = snake.polyline();
      Progress p;
      p.phase = phase.name;
      p.iteration = iteration;
      p.snaxels = snake.size();
      p.contour = &polyline;
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

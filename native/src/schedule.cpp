// The evolution schedule: coarse, refinement (one or more spacings), stabilisation.
#include "report_text.hpp"
#include "relief_snake/schedule.hpp"

#include <chrono>
#include <cmath>

#include "relief_snake/energy.hpp"
#include "relief_snake/evidence.hpp"
#include "relief_snake/evolution.hpp"

namespace relief_snake {
namespace {

using Clock = std::chrono::steady_clock;
// sigma of Eqn. 9: the spread of P^ along the initial contour, on the background.
double background_sigma(const Mesh& mesh, PlanarityField& planarity, const std::vector<SurfacePoint>& start) {
  std::vector<int> corners;
  for (const SurfacePoint& p : start)
    for (int k = 0; k < 3; ++k) corners.push_back(mesh.face_vertex(p.face, k));
  planarity.prefetch_filtered(corners);  // one parallel batch
  double sum = 0, sum2 = 0;
  for (const SurfacePoint& p : start) {
    const double v = planarity.filtered(p);
    sum += v;
    sum2 += v * v;
  }
  const double n = static_cast<double>(start.size());
  return std::sqrt(std::max(0.0, sum2 / n - (sum / n) * (sum / n)));
}

PhaseSettings base_settings(const Options& options) {
  PhaseSettings base;
  base.tau = options.tau;
  base.max_turn_degrees = options.max_turn_degrees;
  base.lock_interval = options.lock_interval;
  base.max_iterations = options.max_iterations;
  base.min_snaxels = options.closed ? 4 : 2;
  base.remove_loops = options.remove_loops;
  return base;
}

}  // namespace

EvolutionSchedule::EvolutionSchedule(const Mesh& mesh, PlanarityField& planarity, const Options& options, double h,
                                     const std::vector<SurfacePoint>& start, bool inside_left)
    : mesh_(mesh), planarity_(planarity), options_(options), h_(h), inside_left_(inside_left), start_(start) {
  sigma_background_ = background_sigma(mesh, planarity, start);
}

DerivedParameters EvolutionSchedule::parameters(double w_int) const {
  DerivedParameters param;
  param.average_edge = mesh_.average_edge_length();
  param.sigma_s = planarity_.sigma_s();
  param.sigma_background = sigma_background_;
  param.coarse_spacing = h_;
  param.refine_spacing = 0.5 * mesh_.average_edge_length();
  param.alpha_coarse = normalise_alpha(param.coarse_spacing);
  param.beta_coarse = normalise_beta(param.coarse_spacing, options_.max_turn_degrees);
  param.alpha_refine = normalise_alpha(param.refine_spacing);
  param.beta_refine = normalise_beta(param.refine_spacing, options_.max_turn_degrees);
  // gamma normalises E_f so a step of planarity contrast feature_contrast * h
  // scores -1 at l = h; like alpha it scales with 1/l between phases (7.2.3).
  const double contrast = options_.feature_contrast * h_;
  param.gamma = 1.0 / (contrast * contrast);
  param.w_int = w_int;
  param.w_f = 1;
  param.w_d = 4 - 2 * w_int - param.w_f;
  return param;
}

const ScheduleRun& EvolutionSchedule::coarse(const ProgressCallback& progress) {
  if (coarse_done_) return coarse_run_;
  const DerivedParameters param = parameters(options_.w_int);
  PhaseSettings coarse = base_settings(options_);
  coarse.name = "coarse";
  coarse.l = param.coarse_spacing;
  coarse.alpha = param.alpha_coarse;
  coarse.beta = param.beta_coarse;
  coarse.gamma = param.gamma;
  coarse.w_int = coarse.w_f = coarse.w_d = 1;
  coarse.gamma_sigma2 = param.gamma * param.sigma_background * param.sigma_background;

  const auto t_phase = Clock::now();
  coarse_snake_ = std::make_unique<Snake>(mesh_, start_, options_.closed, inside_left_);
  Snake& snake = *coarse_snake_;
  snake.set_nearest_resampling(options_.nearest_resampling);
  FeatureEnergy feature(planarity_, h_, options_.epsilon, options_.q_samples, options_.exact_q);
  feature.set_convex_barrier(options_.convex_barrier);
  snake.reset_state();
  const PhaseOutcome outcome = run_phase(snake, feature, coarse, progress, planarity_.pool());
  ScheduleRun& run = coarse_run_;
  run.cancelled = outcome.cancelled;
  if (!outcome.cancelled && (outcome.collapsed || (options_.closed && snake.length() < 2 * h_))) {
    run.collapsed = true;
    run.collapsed_phase = "coarse";
  }
  PhaseStats stats;
  stats.name = "coarse";
  stats.iterations = outcome.iterations;
  stats.converged = outcome.converged;
  stats.snaxels = snake.size();
  stats.seconds = seconds_since(t_phase);
  run.hit_cap = !outcome.converged && !outcome.cancelled && !run.collapsed;
  run.phases.push_back(stats);
  run.contour = snake.points();
  run.snake = std::make_shared<Snake>(snake);
  coarse_done_ = true;
  return run;
}

ScheduleRun EvolutionSchedule::refine(double w_int, const ProgressCallback& progress, const RefineStop& stop) {
  const ScheduleRun& first = coarse(progress);
  if (first.cancelled || first.collapsed) return first;
  // each refinement starts from the coarse snake
  return refine_snake(*coarse_snake_, true, w_int, progress, stop);
}

ScheduleRun EvolutionSchedule::refine_from(const std::vector<SurfacePoint>& start, double w_int,
                                           const ProgressCallback& progress) {
  const ScheduleRun& first = coarse(progress);
  if (first.cancelled || first.collapsed) return first;
  Snake snake(mesh_, start, options_.closed, inside_left_);
  snake.set_nearest_resampling(options_.nearest_resampling);
  return refine_snake(snake, false, w_int, progress);
}

ScheduleRun EvolutionSchedule::refine_snake(const Snake& start, bool all_levels, double w_int,
                                            const ProgressCallback& progress, const RefineStop& stop) {
  ScheduleRun run = coarse_run_;
  const DerivedParameters param = parameters(w_int);

  // A refinement setting at spacing l: alpha and beta normalised for l, gamma scaled with 1/l.
  auto at_spacing = [&](PhaseSettings settings, double l) {
    settings.l = l;
    settings.alpha = normalise_alpha(l);
    settings.beta = normalise_beta(l, options_.max_turn_degrees);
    settings.gamma = options_.scale_feature_with_spacing ? param.gamma * param.coarse_spacing / l : param.gamma;
    return settings;
  };
  PhaseSettings refine = base_settings(options_);
  refine.name = "refine";
  refine.w_int = param.w_int;
  refine.w_f = param.w_f;
  refine.w_d = param.w_d;
  refine.gamma_sigma2 = 0;
  refine = at_spacing(refine, param.refine_spacing);
  if (!barrier_.empty()) refine.barrier = &barrier_, refine.barrier_level = barrier_level_;

  const double coarse_area = stop.min_area_share > 0 && options_.closed ? vector_area(start.polyline()).norm() : 0.0;
  const auto area_share = [coarse_area](const Snake& s) { return vector_area(s.polyline()).norm() / coarse_area; };
  const StepAnchors* anchors = options_.closed && stop.anchors && stop.anchors->on_step_count() > 0 ? stop.anchors : nullptr;
  const double left_distance = stop.left_distance * h_;
  bool for_area = false;
  if (coarse_area > 0 || anchors)
    refine.abandon = [&](const Snake& s) {
      for_area = coarse_area > 0 && area_share(s) < stop.min_area_share;
      return for_area || (anchors && step_left(*anchors, s, left_distance).share > stop.max_left_share);
    };

  PhaseSettings stabilise = refine;
  stabilise.name = "stabilise";
  stabilise.abandon = nullptr;
  stabilise.w_int = 1;
  stabilise.w_d = 0;

  // The refinement's spacings: the paper goes straight to half an edge; with
  // refine_levels != 1 the snake is refined coarse to fine, from h / 2 down to half an
  // edge in equal ratios of at most 2 (fewer levels if refine_levels says so), each
  // level run to convergence: the long moves into deep concavities happen at the
  // coarse levels, in few iterations of few snaxels.
  std::vector<double> refine_spacings = {refine.l};
  if (all_levels && options_.refine_levels != 1 && 0.5 * h_ > refine.l * 1.05) {
    const double span = 0.5 * h_ / refine.l;
    int levels = static_cast<int>(std::ceil(std::log2(span))) + 1;
    if (options_.refine_levels > 1) levels = std::min(levels, options_.refine_levels);
    refine_spacings.clear();
    for (int k = levels - 1; k >= 0; --k) refine_spacings.push_back(refine.l * std::pow(span, k / double(levels - 1)));
  }
  run.refine_levels = static_cast<int>(refine_spacings.size());

  run.snake = std::make_shared<Snake>(start);
  Snake& snake = *run.snake;
  FeatureEnergy feature(planarity_, h_, options_.epsilon, options_.q_samples, options_.exact_q);
  feature.set_convex_barrier(options_.convex_barrier);
  for (PhaseSettings* phase : {&refine, &stabilise}) {
    const auto t_phase = Clock::now();
    const std::vector<double> spacings = phase == &refine ? refine_spacings : std::vector<double>{phase->l};
    PhaseStats stats;
    stats.name = phase->name;
    for (const double l : spacings) {
      const PhaseSettings settings = phase == &refine ? at_spacing(refine, l) : *phase;
      if (phase == &refine) snake.subdivide(l);
      snake.reset_state();
      const PhaseOutcome outcome = run_phase(snake, feature, settings, progress, planarity_.pool());
      if (outcome.cancelled) {
        run.cancelled = true;
        return run;
      }
      if (outcome.collapsed) {
        run.collapsed = true;
        run.collapsed_phase = phase->name;
        return run;
      }
      stats.iterations += outcome.iterations;
      if (outcome.abandoned) {
        stats.converged = false;
        stats.snaxels = snake.size();
        stats.seconds = seconds_since(t_phase);
        run.phases.push_back(stats);
        run.abandoned = true;
        run.abandoned_for_area = for_area;
        run.abandoned_area_share = coarse_area > 0 ? area_share(snake) : 0.0;
        if (anchors) run.abandoned_left_share = step_left(*anchors, snake, left_distance).share;
        run.contour = snake.points();
        return run;
      }
      stats.converged = stats.converged && outcome.converged;
    }
    stats.snaxels = snake.size();
    stats.seconds = seconds_since(t_phase);
    run.hit_cap = run.hit_cap || !stats.converged;
    run.phases.push_back(stats);
  }
  run.contour = snake.points();
  return run;
}

}  // namespace relief_snake

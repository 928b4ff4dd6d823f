#include "relief_snake/segment.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <unordered_set>

#include "relief_snake/energy.hpp"
#include "relief_snake/error.hpp"
#include "relief_snake/evolution.hpp"
#include "relief_snake/foot.hpp"
#include "relief_snake/initial_contour.hpp"
#include "relief_snake/planarity.hpp"
#include "relief_snake/region.hpp"
#include "relief_snake/snake.hpp"

namespace relief_snake {

const char* to_string(Status status) {
  switch (status) {
    case Status::Converged: return "converged";
    case Status::IterationCap: return "iteration_cap";
    case Status::Cancelled: return "cancelled";
  }
  return "unknown";
}

std::vector<std::pair<const char*, double>> DerivedParameters::named_values() const {
  return {{"coarse_spacing", coarse_spacing}, {"refine_spacing", refine_spacing}, {"alpha_coarse", alpha_coarse},
          {"beta_coarse", beta_coarse},       {"alpha_refine", alpha_refine},     {"beta_refine", beta_refine},
          {"gamma", gamma},                   {"sigma_background", sigma_background}, {"sigma_s", sigma_s},
          {"w_int", w_int},                   {"w_f", w_f},                       {"w_d", w_d},
          {"average_edge", average_edge}};
}

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string fmt(double x) {
  std::ostringstream s;
  s.precision(4);
  s << x;
  return s.str();
}

void validate_options(const Mesh& mesh, const Options& o) {
  const double h = o.step_height;
  if (!std::isfinite(h) || h <= 0)
    throw Error("step height h must be a positive number (got " + fmt(h) +
                "); measure the relief's step with the measure tool");
  if (h > mesh.bbox_diagonal())
    throw Error("step height h = " + fmt(h) + " is larger than the whole mesh (diagonal " +
                fmt(mesh.bbox_diagonal()) + "); check the units of h");
  if (!std::isfinite(o.w_int) || o.w_int <= 0 || o.w_int > 1)
    throw Error("W_int must be in (0, 1] (got " + fmt(o.w_int) + "); try 0.25, then halve it if concavities are missed");
  if (!(o.tau > 0 && o.tau < 1)) throw Error("tau must be in (0, 1) (got " + fmt(o.tau) + ")");
  if (!(o.epsilon >= 0 && o.epsilon < 1)) throw Error("epsilon must be in [0, 1) (got " + fmt(o.epsilon) + ")");
  if (o.q_samples < 1 || o.q_samples > 64) throw Error("q_samples must be between 1 and 64 (the paper uses 5)");
  if (!(o.max_turn_degrees > 0 && o.max_turn_degrees <= 180))
    throw Error("max_turn_degrees must be in (0, 180]");
  if (o.lock_interval < 1) throw Error("lock_interval must be at least 1");
  if (o.refine_levels < 0 || o.refine_levels > 16) throw Error("refine_levels must be between 0 and 16 (1: the paper's)");
  if (o.max_iterations < 1) throw Error("max_iterations must be at least 1 (got " + std::to_string(o.max_iterations) + ")");
  if (o.threads < 0) throw Error("threads must be 0 (all cores) or a positive count (got " + std::to_string(o.threads) + ")");
  if (!(o.feature_contrast > 0) || !std::isfinite(o.feature_contrast))
    throw Error("feature_contrast must be a positive number");
}

std::vector<int> validate_picks(const Mesh& mesh, const std::vector<std::int64_t>& picks, bool closed) {
  const std::size_t needed = closed ? 3 : 2;
  if (picks.size() < needed)
    throw Error(std::string(closed ? "a closed contour" : "an open contour") + " needs at least " +
                std::to_string(needed) + " picked vertices (got " + std::to_string(picks.size()) +
                "); pick vertices around the relief");
  std::vector<int> out;
  std::unordered_set<int> seen;
  for (std::size_t k = 0; k < picks.size(); ++k) {
    const std::int64_t p = picks[k];
    if (p < 0 || static_cast<std::size_t>(p) >= mesh.input_vertex_count())
      throw Error("pick " + std::to_string(p) + " is not a vertex index (the mesh has " +
                  std::to_string(mesh.input_vertex_count()) + " vertices)");
    const int v = mesh.input_to_mesh(static_cast<std::size_t>(p));
    if (v < 0) throw Error("pick " + std::to_string(p) + " is a vertex that belongs to no face; pick another vertex");
    if (!seen.insert(v).second)
      throw Error("pick " + std::to_string(p) + " is repeated; each picked vertex must be different");
    if (!out.empty() && mesh.component(v) != mesh.component(out.front()))
      throw Error("picks " + std::to_string(picks.front()) + " and " + std::to_string(p) +
                  " lie on different parts of the mesh; pick vertices on the surface around one relief");
    out.push_back(v);
  }
  return out;
}

// Vertices to estimate the bilateral sigma_s from: the corners along the initial
// contour plus an even sample of the component, capped for speed.
std::vector<int> planarity_sample(const Mesh& mesh, const std::vector<SurfacePoint>& contour, int component) {
  std::vector<int> sample;
  for (const SurfacePoint& p : contour) sample.push_back(nearest_corner(mesh, p));
  const int stride = std::max(1, mesh.n_vertices() / 2000);
  for (int v = 0; v < mesh.n_vertices(); v += stride)
    if (mesh.component(v) == component) sample.push_back(v);
  std::sort(sample.begin(), sample.end());
  sample.erase(std::unique(sample.begin(), sample.end()), sample.end());
  return sample;
}

}  // namespace

struct Segmenter::Cache {
  std::unique_ptr<PlanarityField> planarity;
  PlanarityOptions options;  // what it was computed with
  std::shared_ptr<const MomentTree> tree;  // does not depend on h: kept across planarity fields
};

Segmenter::Segmenter(const Mesh& mesh) : mesh_(mesh), cache_(std::make_unique<Cache>()) {}
Segmenter::~Segmenter() = default;

Result Segmenter::segment(const std::vector<std::int64_t>& picks, const Options& options,
                          const ProgressCallback& progress) {
  const auto t_start = Clock::now();
  const Mesh& mesh = mesh_;
  validate_options(mesh, options);
  const std::vector<int> pick_vertices = validate_picks(mesh, picks, options.closed);
  const double h = options.step_height;

  Result result;
  result.closed = options.closed;
  DerivedParameters& param = result.parameters;
  param.average_edge = mesh.average_edge_length();

  // --- initial contour (Section 7.1), sampled at l = h ----------------------
  InitialContour initial = initial_contour(mesh, pick_vertices, options.closed);
  if (initial.fallback_legs > 0)
    result.notes.push_back(std::to_string(initial.fallback_legs) +
                           " leg(s) of the initial contour used a shortest path instead of a plane section");
  if (!options.closed) {
    const std::size_t before = initial.path.size();
    if (!extend_to_boundary(mesh, &initial.path))
      throw Error("an open contour must end on the mesh boundary, but this part of the mesh has none; "
                  "use a closed contour");
    if (initial.path.size() != before)
      result.notes.push_back("the open contour's ends were extended to the mesh boundary");
  }
  std::vector<SurfacePoint> start = resample_path(mesh, initial.path, h, options.closed);
  if (static_cast<int>(start.size()) < (options.closed ? 4 : 3))
    throw Error("the picked contour is only " + std::to_string(start.size()) +
                " step heights long; pick vertices further from the relief or check h");
  const bool inside_left = options.closed ? contour_orientation_left(mesh, start)
                                          : options.relief_side == ReliefSide::Left;

  // --- planarity (Sections 5.3, 7.2.1), reused between calls for the same h --
  PlanarityOptions po;
  po.radius = h;
  po.threads = options.threads;
  po.neighbourhood = options.neighbourhood;
  po.fit = options.plane_fit;
  po.include_one_ring = options.planarity_one_ring;
  const PlanarityOptions& was = cache_->options;
  if (!cache_->planarity || was.radius != h || was.neighbourhood != po.neighbourhood || was.fit != po.fit ||
      was.include_one_ring != po.include_one_ring) {
    std::shared_ptr<const MomentTree> tree;
    if (cache_->tree && cache_->tree->elements() == PlanarityField::tree_elements(po.fit)) tree = cache_->tree;
    cache_->planarity = std::make_unique<PlanarityField>(mesh, po, tree);
    if (cache_->planarity->tree()) cache_->tree = cache_->planarity->tree();
    cache_->planarity->estimate_sigma_s(planarity_sample(mesh, start, mesh.component(pick_vertices.front())));
    cache_->options = po;
  }
  PlanarityField& planarity = *cache_->planarity;
  param.sigma_s = planarity.sigma_s();
  {
    // sigma of Eqn. 9: spread of P^ along the initial contour, on the background.
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
    param.sigma_background = std::sqrt(std::max(0.0, sum2 / n - (sum / n) * (sum / n)));
  }
  const double preprocess_seconds = seconds_since(t_start);

  // --- parameters (Section 7.2) ---------------------------------------------
  param.coarse_spacing = h;
  param.refine_spacing = 0.5 * mesh.average_edge_length();
  param.alpha_coarse = normalise_alpha(param.coarse_spacing);
  param.beta_coarse = normalise_beta(param.coarse_spacing, options.max_turn_degrees);
  param.alpha_refine = normalise_alpha(param.refine_spacing);
  param.beta_refine = normalise_beta(param.refine_spacing, options.max_turn_degrees);
  // gamma normalises E_f so a step of planarity contrast feature_contrast * h
  // scores -1 at l = h; like alpha it scales with 1/l between phases (7.2.3).
  const double contrast = options.feature_contrast * h;
  param.gamma = 1.0 / (contrast * contrast);
  param.w_int = options.w_int;
  param.w_f = 1;
  param.w_d = 4 - 2 * options.w_int - param.w_f;

  Snake snake(mesh, start, options.closed, inside_left);
  snake.set_nearest_resampling(options.nearest_resampling);
  FeatureEnergy feature(planarity, h, options.epsilon, options.q_samples, options.exact_q);
  feature.set_convex_barrier(options.convex_barrier);

  PhaseSettings base;
  base.tau = options.tau;
  base.max_turn_degrees = options.max_turn_degrees;
  base.lock_interval = options.lock_interval;
  base.max_iterations = options.max_iterations;
  base.min_snaxels = options.closed ? 4 : 2;
  base.remove_loops = options.remove_loops;

  PhaseSettings coarse = base;
  coarse.name = "coarse";
  coarse.l = param.coarse_spacing;
  coarse.alpha = param.alpha_coarse;
  coarse.beta = param.beta_coarse;
  coarse.gamma = param.gamma;
  coarse.w_int = coarse.w_f = coarse.w_d = 1;
  coarse.gamma_sigma2 = param.gamma * param.sigma_background * param.sigma_background;

  // A refinement setting at spacing l: alpha and beta normalised for l, gamma scaled with 1/l.
  auto at_spacing = [&](PhaseSettings settings, double l) {
    settings.l = l;
    settings.alpha = normalise_alpha(l);
    settings.beta = normalise_beta(l, options.max_turn_degrees);
    settings.gamma = options.scale_feature_with_spacing ? param.gamma * coarse.l / l : param.gamma;
    return settings;
  };
  PhaseSettings refine = base;
  refine.name = "refine";
  refine.w_int = param.w_int;
  refine.w_f = param.w_f;
  refine.w_d = param.w_d;
  refine.gamma_sigma2 = 0;
  refine = at_spacing(refine, param.refine_spacing);

  PhaseSettings stabilise = refine;
  stabilise.name = "stabilise";
  stabilise.w_int = 1;
  stabilise.w_d = 0;

  PhaseStats pre;
  pre.name = "preprocess";
  pre.seconds = preprocess_seconds;
  pre.snaxels = snake.size();
  result.phases.push_back(pre);

  // The refinement's spacings: the paper goes straight to half an edge; with
  // refine_levels != 1 the snake is refined coarse to fine, from h / 2 down to half an
  // edge in equal ratios of at most 2 (fewer levels if refine_levels says so), each
  // level run to convergence: the long moves into deep concavities happen at the
  // coarse levels, in few iterations of few snaxels.
  std::vector<double> refine_spacings = {refine.l};
  if (options.refine_levels != 1 && 0.5 * h > refine.l * 1.05) {
    const double span = 0.5 * h / refine.l;
    int levels = static_cast<int>(std::ceil(std::log2(span))) + 1;
    if (options.refine_levels > 1) levels = std::min(levels, options.refine_levels);
    refine_spacings.clear();
    for (int k = levels - 1; k >= 0; --k) refine_spacings.push_back(refine.l * std::pow(span, k / double(levels - 1)));
  }

  bool hit_cap = false;
  for (PhaseSettings* phase : {&coarse, &refine, &stabilise}) {
    const auto t_phase = Clock::now();
    const std::vector<double> spacings = phase == &refine ? refine_spacings : std::vector<double>{phase->l};
    PhaseStats stats;
    stats.name = phase->name;
    for (const double l : spacings) {
      const PhaseSettings settings = phase == &refine ? at_spacing(refine, l) : *phase;
      if (phase == &refine) snake.subdivide(l);
      snake.reset_state();
      const PhaseOutcome outcome = run_phase(snake, feature, settings, progress, planarity.pool());
      if (outcome.cancelled) {
        Result cancelled;
        cancelled.status = Status::Cancelled;
        cancelled.closed = options.closed;
        return cancelled;
      }
      if (outcome.collapsed || (options.closed && phase == &coarse && snake.length() < 2 * h))
        throw Error("the snake collapsed during the " + std::string(phase->name) +
                    " phase without meeting a relief step; check that h (" + fmt(h) +
                    ") matches the relief's step height and that the picks surround the relief");
      stats.iterations += outcome.iterations;
      stats.converged = stats.converged && outcome.converged;
    }
    stats.snaxels = snake.size();
    stats.seconds = seconds_since(t_phase);
    hit_cap = hit_cap || !stats.converged;
    result.phases.push_back(stats);
  }
  if (refine_spacings.size() > 1)
    result.notes.push_back("refined coarse to fine in " + std::to_string(refine_spacings.size()) + " levels (" +
                           fmt(refine_spacings.front() / h) + " h down to " + fmt(refine_spacings.back() / h) + " h)");

  if (options.foot_snap) {
    FootOptions fo;
    fo.h = h;
    const FootResult foot = settle_at_foot(&snake, fo);
    // Moving out can twist neighbours (rays from a jagged snake cross): cut the loops
    // (each call removes at most 64) and the sharp turns again.
    for (int guard = 0; guard < 100 && snake.remove_loops() > 0; ++guard) {
    }
    snake.remove_sharp_turns(options.max_turn_degrees);
    if (foot.noisy)
      result.notes.push_back("not settled at the foot: the background is too noisy (residual " +
                             fmt(foot.background_residual / h) + " h)");
    else
      result.notes.push_back("settled at the foot: " + std::to_string(foot.moved) + " snaxels moved out by " +
                             fmt(foot.mean_move / h) + " h on average, " + std::to_string(foot.skipped) +
                             " left (no clean background outside)");
  }

  result.status = hit_cap ? Status::IterationCap : Status::Converged;
  result.contour = snake.points();
  result.polyline = snake.polyline();

  // --- the relief region ----------------------------------------------------
  const std::vector<char> inside = relief_region(mesh, result.contour, options.closed, inside_left);
  for (std::size_t i = 0; i < mesh.input_vertex_count(); ++i) {
    const int v = mesh.input_to_mesh(i);
    if (v >= 0 && inside[v]) result.relief_vertices.push_back(static_cast<std::int64_t>(i));
  }
  result.planarity_vertices = planarity.raw_count();
  return result;
}

Result segment(const Mesh& mesh, const std::vector<std::int64_t>& picks, const Options& options,
               const ProgressCallback& progress) {
  Segmenter segmenter(mesh);
  return segmenter.segment(picks, options, progress);
}

}  // namespace relief_snake

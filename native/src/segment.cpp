#include "report_text.hpp"
#include "relief_snake/segment.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <unordered_set>

#include "relief_snake/enclosure.hpp"
#include "relief_snake/energy.hpp"
#include "relief_snake/error.hpp"
#include "relief_snake/background_inside.hpp"
#include "relief_snake/evidence.hpp"
#include "relief_snake/evolution.hpp"
#include "relief_snake/foot.hpp"
#include "relief_snake/holes.hpp"
#include "relief_snake/band.hpp"
#include "relief_snake/initial_contour.hpp"
#include "relief_snake/planarity.hpp"
#include "relief_snake/region.hpp"
#include "relief_snake/mesh_graph.hpp"
#include "relief_snake/relief_mask.hpp"
#include "relief_snake/schedule.hpp"
#include "relief_snake/snake.hpp"
#include "relief_snake/step_height.hpp"
#include "relief_snake/input_checks.hpp"

namespace relief_snake {

const char* to_string(ReliefSide side) {
  switch (side) {
    case ReliefSide::Left: return "left";
    case ReliefSide::Right: return "right";
    case ReliefSide::Auto: return "auto";
  }
  return "unknown";
}

const char* to_string(Status status) {
  switch (status) {
    case Status::Converged: return "converged";
    case Status::Doubtful: return "doubtful";
    case Status::IterationCap: return "iteration_cap";
    case Status::Cancelled: return "cancelled";
  }
  return "unknown";
}

bool refit_wanted(double found, double h_used, const std::vector<double>& tried, const Options& options,
                  double largest) {
  if (!(found > 0) || !(h_used > 0) || found > largest) return false;
  const double ratio = found / h_used;
  if (ratio < std::min(options.refit_ratio_up, options.refit_ratio) && ratio * options.refit_ratio > 1) return false;
  for (const double t : tried)
    if (std::fabs(std::log(found / t)) < std::log(1.15)) return false;
  return true;
}

std::vector<std::pair<const char*, double>> DerivedParameters::named_values() const {
  return {{"coarse_spacing", coarse_spacing}, {"refine_spacing", refine_spacing}, {"alpha_coarse", alpha_coarse},
          {"beta_coarse", beta_coarse},       {"alpha_refine", alpha_refine},     {"beta_refine", beta_refine},
          {"gamma", gamma},                   {"sigma_background", sigma_background}, {"sigma_s", sigma_s},
          {"w_int", w_int},                   {"w_f", w_f},                       {"w_d", w_d},
          {"average_edge", average_edge},    {"step_height", step_height}};
}

namespace {

using Clock = std::chrono::steady_clock;
void validate_options(const Mesh& mesh, const Options& o) {
  const double h = o.step_height;
  if (h != kAuto) checked_step_height(h);
  // A step far below the mesh's resolution cannot be resolved, and the snake would need
  // (length / h) snaxels: refuse instead of running away.
  if (h > 0 && h < 0.1 * mesh.average_edge_length())
    throw Error("step height h = " + fmt(h) + " is below a tenth of the mesh's average edge (" +
                fmt(mesh.average_edge_length()) + "); check the units of h, or leave it to the engine");
  if (h > mesh.bbox_diagonal())
    throw Error("step height h = " + fmt(h) + " is larger than the whole mesh (diagonal " +
                fmt(mesh.bbox_diagonal()) + "); check the units of h");
  if (o.w_int != kAuto) checked_w_int(o.w_int);
  if (!(o.tau > 0 && o.tau < 1)) throw Error("tau must be in (0, 1) (got " + fmt(o.tau) + ")");
  if (!(o.epsilon >= 0 && o.epsilon < 1)) throw Error("epsilon must be in [0, 1) (got " + fmt(o.epsilon) + ")");
  if (o.q_samples < 1 || o.q_samples > 64) throw Error("q_samples must be between 1 and 64 (the paper uses 5)");
  if (!(o.max_turn_degrees > 0 && o.max_turn_degrees <= 180))
    throw Error("max_turn_degrees must be in (0, 180]");
  if (o.lock_interval < 1) throw Error("lock_interval must be at least 1");
  if (o.refine_levels < 0 || o.refine_levels > 16) throw Error("refine_levels must be between 0 and 16 (1: the paper's)");
  if (o.max_iterations < 1) throw Error("max_iterations must be at least 1 (got " + std::to_string(o.max_iterations) + ")");
  if (o.threads < 0) throw Error("threads must be 0 (all cores) or a positive count (got " + std::to_string(o.threads) + ")");
  if (!(o.refit_ratio > 1) || !std::isfinite(o.refit_ratio)) throw Error("refit_ratio must be a number > 1");
  if (!(o.refit_ratio_up > 1) || !std::isfinite(o.refit_ratio_up)) throw Error("refit_ratio_up must be a number > 1");
  if (!(o.feature_contrast > 0) || !std::isfinite(o.feature_contrast))
    throw Error("feature_contrast must be a positive number");
}

std::vector<int> validate_picks(const Mesh& mesh, const std::vector<std::int64_t>& picks, bool closed) {
  check_pick_count(picks.size(), closed);
  std::vector<int> out;
  std::unordered_set<int> seen;
  for (std::size_t k = 0; k < picks.size(); ++k) {
    const std::int64_t p = picks[k];
    const int v = checked_input_vertex(mesh, p, "pick");
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
  std::unique_ptr<BackgroundInsideCheck> background_inside;  // the fills for the region-wide check
};

Segmenter::Segmenter(const Mesh& mesh) : mesh_(mesh), cache_(std::make_unique<Cache>()) {}
Segmenter::~Segmenter() = default;

namespace {

// One refinement tried: the contour, its region and the evidence for it.
struct Attempt {
  double h = 0, w_int = 0;
  ScheduleRun run;
  std::vector<char> region;
  ContourEvidence evidence;
  SelfCheck check;
  DerivedParameters parameters;
  std::vector<std::string> notes;
  bool usable() const { return !run.cancelled && !run.collapsed && !run.contour.empty(); }
};

// The contour sits on a blended step over a clean background: half the step lies at least 1.5
// average edges inside it (StepEvidence::offset_median) or, with h at least 3 edges, the step rises
// over at least 2 edges from a quarter to three quarters of its height (StepEvidence::
// rise_width_median: a sharp or one-triangle step rises within one; on a coarser mesh one-edge bins
// cannot tell them apart), and the background outside is clean: the residual of local quadrics
// under foot_gate_residual of h (StepEvidence::background_quadric_residual; 10% with the pooled
// profiles, 5% before stop 38; the planes' residual also counted a sphere's or a cylinder's
// curvature as roughness). There the feature energy holds the snake part of
// the way up the slope, and the foot stage brings it down to the foot; on sharp steps (already at
// the foot), textured or noisy backgrounds (where the foot test fires on the texture) and coarse
// meshes it only moved right contours off (randomized suite, docs/design.md).
bool blended_and_clean(const StepEvidence& step, double h, double edge, double max_residual) {
  const bool wide_rise = step.rise_width_median >= 2 * edge && h >= 3 * edge;
  return step.step_share > 0 && (step.offset_median >= 1.5 * edge || wide_rise) &&
         step.background_quadric_residual <= max_residual * h;
}

// a is better evidence than b.
bool better(const Attempt& a, const Attempt& b) {
  if (a.usable() != b.usable()) return a.usable();
  if (a.check.holds != b.check.holds) return a.check.holds;
  if (a.check.holds) {  // both hold: the one whose step agrees with its own h
    const double ra = std::fabs(std::log(a.evidence.step.step_height / a.h));
    const double rb = std::fabs(std::log(b.evidence.step.step_height / b.h));
    if (std::fabs(ra - rb) > 0.1) return ra < rb;
  }
  return a.check.score > b.check.score;
}

}  // namespace

// The planarity field for h, reused while h and the planarity options stay the same.
static PlanarityField& planarity_for(const Mesh& mesh, std::unique_ptr<PlanarityField>& field,
                                     PlanarityOptions& was, std::shared_ptr<const MomentTree>& tree_cache,
                                     const Options& options, double h, const std::vector<SurfacePoint>& start,
                                     int component) {
  PlanarityOptions po;
  po.radius = h;
  po.threads = options.threads;
  po.neighbourhood = options.neighbourhood;
  po.fit = options.plane_fit;
  po.include_one_ring = options.planarity_one_ring;
  if (!field || was.radius != h || was.neighbourhood != po.neighbourhood || was.fit != po.fit ||
      was.include_one_ring != po.include_one_ring) {
    std::shared_ptr<const MomentTree> tree;
    if (tree_cache && tree_cache->elements() == PlanarityField::tree_elements(po.fit)) tree = tree_cache;
    field = std::make_unique<PlanarityField>(mesh, po, tree);
    if (field->tree()) tree_cache = field->tree();
    field->estimate_sigma_s(planarity_sample(mesh, start, component));
    was = po;
  }
  return *field;
}

Result Segmenter::segment(const std::vector<std::int64_t>& picks, const Options& options,
                          const ProgressCallback& progress) {
  const Mesh& mesh = mesh_;
  validate_options(mesh, options);
  const std::vector<int> pick_vertices = validate_picks(mesh, picks, options.closed);
  const int component = mesh.component(pick_vertices.front());
  validate_hole_picks(mesh, options, component);
  if (!options.band_picks.empty()) {  // a cyclic relief between two rings (band.cpp)
    const std::vector<int> band_vertices = validate_picks(mesh, options.band_picks, true);
    return segment_band(mesh, pick_vertices, band_vertices, options,
                        [&](double h_band, const std::vector<SurfacePoint>& start) -> PlanarityField& {
                          return planarity_for(mesh, cache_->planarity, cache_->options, cache_->tree, options,
                                               h_band, start, component);
                        },
                        progress);
  }

  if (!options.closed && options.relief_side == ReliefSide::Auto) return segment_deciding_side(picks, options, progress);
  return segment_one_side(picks, options, progress);
}

namespace {

double check_named(const Result& result, const std::string& name, double none) {
  for (const auto& [key, value] : result.checks)
    if (key == name) return value;
  return none;
}

}  // namespace

// A contour mostly on a step that fails for another reason (a near miss, a bridged concavity) is on
// the right side, and the other side's background could only give a wrong region (one that, on
// striations, can even pass the self-check: random scan 1014 did with every failed side swapped).
bool looks_like_the_wrong_side(const Result& result) {
  return looks_like_the_wrong_side(check_named(result, "step_share", 0.0), check_named(result, "measured_share", 0.0),
                                   check_named(result, "other_side_share", 0.0));
}

bool looks_like_the_wrong_side(double step_share, double measured_share, double other_side_share) {
  return step_share < 0.5 || measured_share < SelfCheckOptions().min_measured_share || other_side_share > step_share;
}

// An open contour's side decided with the other side rising at least this share as much along the
// picks (StepHeightEstimate::left_rise/right_rise) is checked against the other side's result.
constexpr double kAmbiguousSideRise = 0.5;

// An open contour's relief side decided from the surface (step_height.hpp: the side that rises
// along the picks) can be wrong: the strip compared may not reach a relief picked far from it, or
// the background may curve away from the fit on the other side. A wrong side gives a region on the
// background, which the self-check flags (a contour off any step, a clearer step from the other
// side). So when the decided side's result fails its self-check that way, or the snake collapses on
// it, the other side is segmented too, and kept if its result passes the self-check.
//
// Each side is first only probed: its result at the first h (with that h's refits). When the decided
// side's probe fails as a wrong side does, the other side's probe follows, and a result of it that
// passes the self-check is kept. Otherwise both sides get their full search (the further guesses of
// h), the decided side first, as without the probes. A wrong side's guesses of h (a curved background
// read as a step at ever larger h) took most of the time of a failing open contour, and a result they
// found could hide that the side was wrong.
Result Segmenter::segment_deciding_side(const std::vector<std::int64_t>& picks, const Options& options,
                                        const ProgressCallback& progress) {
  struct SideRun {
    Result result;
    std::string error;
    bool probe_failed = false;
    bool usable() const { return error.empty(); }
    bool passes() const { return error.empty() && result.status == Status::Converged; }
    bool cancelled() const { return error.empty() && result.status == Status::Cancelled; }
    bool final() const {  // kept without looking at the other side
      return error.empty() && !probe_failed &&
             (result.status == Status::Converged || result.status == Status::Cancelled ||
              !looks_like_the_wrong_side(result));
    }
  };
  ReliefSide decided = ReliefSide::Auto;
  auto run_side = [&](const Options& side_options, bool probe) {
    SideRun run;
    try {
      run.result = segment_one_side(picks, side_options, progress,
                                    side_options.relief_side == ReliefSide::Auto ? &decided : nullptr,
                                    probe ? &run.probe_failed : nullptr);
    } catch (const Error& e) {
      run.error = e.what();
    }
    return run;
  };
  SideRun first = run_side(options, true);
  // An error before the side was decided (bad picks, a mesh without boundary) is the other side's too.
  if (!first.final() && decided == ReliefSide::Auto) throw Error(first.error);
  Options other = options;
  const bool first_left = decided == ReliefSide::Left;
  other.relief_side = first_left ? ReliefSide::Right : ReliefSide::Left;
  const char* first_name = first_left ? "left" : "right";
  const char* other_name = first_left ? "right" : "left";
  if (first.final()) {
    // Both sides rise along the picks (picks along a groove, or between two levels): if the other side
    // also gives a relief that passes the self-check, which one the user meant is a guess.
    const double other_rise = check_named(first.result, "other_side_rise", 0.0);
    if (first.passes() && other_rise >= kAmbiguousSideRise) {
      // At this side's h when it was estimated: the other side's own estimate is a guess too (between
      // two levels the step is the same; on the real eyebrow scan's lower edge the estimate for the
      // other side was x2.3 of its step, and that side failed only for it).
      Options alternative_options = other;
      if (!(options.step_height > 0)) alternative_options.step_height = first.result.parameters.step_height;
      const SideRun alternative = run_side(alternative_options, true);
      if (alternative.cancelled()) return alternative.result;
      first.result.attempts += alternative.result.attempts;
      if (alternative.passes()) {
        Result& r = first.result;
        r.status = Status::Doubtful;
        r.reasons.push_back(std::string("both sides of the picks rise above the background (the ") + other_name +
                            " side " + fmt(100 * other_rise, 2) + "% as much as the " + first_name +
                            ") and each gives a relief that passes the self-check: this is the one on the " +
                            first_name + "; if the relief is on the " + other_name + ", give the side");
        r.message = "Check this result: " + r.reasons.back() + ".";
      } else {
        first.result.notes.push_back(std::string("the ") + other_name + " side rises too (" + fmt(100 * other_rise, 2) +
                                     "% as much) but gives no relief that passes the self-check");
      }
    }
    return first.result;
  }
  SideRun second = run_side(other, first.probe_failed);
  if (second.cancelled()) return second.result;
  if (first.probe_failed && !second.passes()) {
    // Neither probe gives a result that passes: both sides' full searches, the decided side first.
    first = run_side(options, false);
    if (first.final()) return first.result;
    if (second.probe_failed) {
      second = run_side(other, false);
      if (second.cancelled()) return second.result;
    }
  }
  if (!second.usable()) {
    if (!first.usable()) throw Error(first.error);
    first.result.notes.push_back(std::string("the other side (") + other_name + ") was tried too: it gave no result");
    return first.result;
  }
  if (second.passes() || !first.usable()) {
    const std::string why =
        !first.usable() ? "it gave no result (" + first.error + ")"
        : first.probe_failed && first.result.reasons.empty()
            ? std::string("the snake collapsed on it at the first h")
            : "its result failed the self-check (" +
                  (first.result.reasons.empty() ? first.result.message : first.result.reasons.front()) + ")";
    second.result.notes.insert(second.result.notes.begin(),
                               std::string("the relief side was decided from the surface as ") + first_name +
                                   " of the picks, but " + why + "; the " + other_name + " side was segmented instead");
    second.result.attempts += first.result.attempts;
    return second.result;
  }
  first.result.notes.push_back(std::string("the other side (") + other_name +
                               ") was tried too and its result failed the self-check as well");
  first.result.attempts += second.result.attempts;
  return first.result;
}

Result Segmenter::segment_one_side(const std::vector<std::int64_t>& picks, const Options& options,
                                   const ProgressCallback& progress, ReliefSide* side_decided, bool* probe_failed) {
  const auto t_start = Clock::now();
  const Mesh& mesh = mesh_;
  const std::vector<int> pick_vertices = validate_picks(mesh, picks, options.closed);
  const int component = mesh.component(pick_vertices.front());
  Result result;
  result.closed = options.closed;

  // --- initial contour (Section 7.1) -----------------------------------------
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

  // Front ends show "preprocessing" before the estimate and the planarity (seconds on big scans),
  // and can cancel there.
  auto preprocessing = [&](int step) {
    if (!progress) return true;
    Progress p;
    p.phase = "preprocess";
    p.iteration = step;
    p.contour = [] { return std::vector<Vec3>{}; };
    return progress(p);
  };
  auto cancelled_result = [&] {
    Result out;
    out.status = Status::Cancelled;
    out.closed = options.closed;
    return out;
  };
  if (!preprocessing(0)) return cancelled_result();

  // --- step height and relief side --------------------------------------------
  const bool h_given = options.step_height > 0;
  const bool side_given = options.closed || options.relief_side != ReliefSide::Auto;
  bool inside_left = options.closed ? contour_orientation_left(mesh, initial.path)
                                    : options.relief_side != ReliefSide::Right;
  double h = options.step_height;
  // An estimated h, kept within what the mesh can resolve and hold (the self-check judges the rest).
  const auto resolvable = [&](double estimated) {
    return std::clamp(estimated, 0.5 * mesh.average_edge_length(), mesh.bbox_diagonal() / 4);
  };
  StepHeightEstimate estimate;
  if (!h_given || !side_given) {
    StepHeightOptions estimate_options;
    estimate_options.decide_side = !side_given;
    estimate = estimate_step_height(mesh, initial.path, options.closed, inside_left, estimate_options);
    if (!side_given) {
      inside_left = estimate.relief_left;
      result.notes.push_back(std::string("the relief side was decided from the surface: ") +
                             (inside_left ? "left" : "right") + " of the picks (the side that rises)");
    }
    if (!h_given) {
      // None (0): the further guesses below, if any, else an error.
      h = estimate.value > 0 ? resolvable(estimate.value) : 0.0;
      result.step_height_estimate = h;
      result.step_height_confidence = estimate.confidence;
    }
  }
  result.relief_side = inside_left ? ReliefSide::Left : ReliefSide::Right;
  if (side_decided) *side_decided = result.relief_side;
  // What the picks enclose, for the check that they go round a relief at all (enclosure.hpp).
  const Enclosure enclosure = options.closed ? measure_enclosure(mesh, initial.path, inside_left) : Enclosure{};

  // With the refit on, a kept result's step must agree with its own h within x1.5: the refit
  // brings a right contour's h within x1.3, and a contour whose step keeps moving away from
  // its h is on something else (texture, detail).
  SelfCheckOptions self_check;
  if (options.refit_step_height) self_check.max_step_ratio = std::max(1.5, options.refit_ratio * 1.15);
  self_check.max_far_run_checked =
      options.far_run_checked > 0 ? options.far_run_checked : std::numeric_limits<double>::infinity();
  // The contour-wise verdict without the far run, which the region-wide check replaces where it runs.
  SelfCheckOptions contour_wise = self_check;
  contour_wise.max_far_run = std::numeric_limits<double>::infinity();
  // The verdicts with the refit-free step ratio, for a step the refit confirmed (judge_with_confirmed_step).
  SelfCheckOptions step_confirmed = self_check;
  step_confirmed.max_step_ratio = std::max(self_check.max_step_ratio, SelfCheckOptions().max_step_ratio);
  // The step at the edge confirms h as far off as the step found may be.
  step_confirmed.max_edge_step_ratio = std::max(self_check.max_edge_step_ratio, step_confirmed.max_step_ratio);
  SelfCheckOptions step_confirmed_contour_wise = contour_wise;
  step_confirmed_contour_wise.max_step_ratio = step_confirmed.max_step_ratio;
  step_confirmed_contour_wise.max_edge_step_ratio = step_confirmed.max_edge_step_ratio;
  EvidenceOptions evidence_options;
  evidence_options.closed = options.closed;
  evidence_options.quadric_clearance = options.foot_gate_clearance;

  double preprocess_seconds = 0, background_seconds = 0;
  // The region-wide check (background_inside.hpp) of an attempt's region, into its evidence.
  auto measure_region_wide = [&](Attempt& a) {
    BackgroundOptions fill;
    fill.smoothing = options.region_check_smoothing;
    fill.smoothing_band = options.region_check_band;
    TexturedOpinion textured;
    textured.smoothing = options.region_check_textured_smoothing;
    textured.min_roughness = options.region_check_textured_roughness;
    const BackgroundInsideCheck* cached = cache_->background_inside.get();
    if (!cached || cached->fill_options().smoothing != fill.smoothing ||
        cached->fill_options().smoothing_band != fill.smoothing_band || !(cached->textured_opinion() == textured))
      cache_->background_inside = std::make_unique<BackgroundInsideCheck>(mesh, fill, textured);
    a.evidence.background_depth_floor = 2 * mesh.average_edge_length() / a.h;
    BackgroundInside inside = cache_->background_inside->measure(
        a.region, a.h, a.evidence.step.step_height, background_depth_limit(a.evidence, self_check) * a.h,
        a.evidence.step.background_quadric_residual);
    background_seconds += inside.seconds;
    a.evidence.region_checked = inside.checked;
    a.evidence.background_measured = inside.measured && inside.deepest_vertex >= 0;
    a.evidence.background_depth = inside.depth / a.h;
    a.evidence.background_area = inside.area / (a.h * a.h);
    if (inside.deepest_vertex >= 0) a.evidence.background_where = mesh.to_file(mesh.position(inside.deepest_vertex));
    return inside;
  };

  // --- attempts: schedule -> foot -> region -> self-check, for each h and W_int tried
  const std::vector<double> w_steps =
      options.w_int > 0 ? std::vector<double>{options.w_int} : std::vector<double>{0.25, 0.5, 1.0};
  bool cancelled = false;
  std::string collapse_phase;
  // outline_from: instead of the refinements from the coarse snake, refine from just outside what the
  // heights call relief under that attempt's region and the coarse one (relief_mask.hpp).
  // A loop of vertices (region_outer_loop, start_outline: relief on the left) as a snake's start,
  // oriented to the relief side.
  auto snake_start_along = [&](std::vector<int> loop) {
    if (!inside_left) std::reverse(loop.begin(), loop.end());
    return vertex_points(mesh, loop);
  };
  auto attempt_at = [&](double h_try, const Attempt* outline_from = nullptr) {
    Attempt best;
    best.h = h_try;
    const auto t_pre = Clock::now();
    if (!preprocessing(1)) {
      cancelled = true;
      return best;
    }
    std::vector<SurfacePoint> start = resample_path(mesh, initial.path, h_try, options.closed);
    if (static_cast<int>(start.size()) < (options.closed ? 4 : 3)) {
      best.run.collapsed = true;
      collapse_phase = "initial";
      return best;
    }
    PlanarityField& planarity = planarity_for(mesh, cache_->planarity, cache_->options, cache_->tree, options,
                                              h_try, start, component);
    EvolutionSchedule schedule(mesh, planarity, options, h_try, start, inside_left);
    preprocess_seconds += seconds_since(t_pre);
    const ScheduleRun& coarse = schedule.coarse(progress);
    if (coarse.cancelled) {
      cancelled = true;
      return best;
    }
    if (coarse.collapsed) {
      best.run = coarse;
      collapse_phase = "coarse";
      return best;
    }
    const std::vector<char> coarse_region = relief_region(mesh, coarse.contour, options.closed, inside_left);
    const StepEvidence coarse_step = measure_step(mesh, coarse.contour, coarse_region, h_try, evidence_options);
    const double coarse_step_share = coarse_step.step_share;
    // The coarse region's relief, under the background filled in from around it: measured (one sparse
    // solve per h) only for a refined region that strays from the coarse one (coarse_relief_kept).
    std::unique_ptr<BackgroundResult> coarse_fill;
    auto kept_of_coarse_relief = [&](const std::vector<char>& region) {
      if (!coarse_fill) coarse_fill = std::make_unique<BackgroundResult>(fill_background(mesh, coarse_region, h_try));
      return kept_relief_share(mesh, *coarse_fill, region, 0.5 * judged_step(h_try, coarse_step.step_height));
    };
    // The foot stage and the self-check of one refined run (a.run).
    // Outline attempts (outline_from): how far the heights' relief reaches, grown past the start.
    std::vector<char> mask_reach;
    auto settle_and_judge = [&](Attempt& a, BackgroundInside* inside_out) {
      // gated (foot_snap_blended): left alone unless most snaxels have a clean background outside.
      auto settle_at_the_foot = [&](bool gated) {
        Snake& snake = *a.run.snake;
        FootOptions fo;
        fo.h = h_try;
        // Gated on a blended step, the foot test's own threshold (4 x the band's residual) copes with
        // noise up to 5% of h (the gate until stop 38; kept when pooling raised the gate to 10%, and
        // measured so): the plain stage's noise limit is for sharp steps and texture.
        if (gated) fo.max_unclean_share = 0.5, fo.max_noise = 0.05, fo.toe = options.foot_toe;
        if (gated && options.foot_pool > 0) {
          // Snaxels within foot_pool h of each other along the contour, from its mean spacing.
          double length = 0;
          for (int i = 0; i + 1 < snake.size(); ++i) length += (snake[i + 1].position - snake[i].position).norm();
          const double spacing = snake.size() > 1 ? length / (snake.size() - 1) : 0;
          if (spacing > 0) fo.pool = std::clamp(static_cast<int>(std::lround(options.foot_pool * h_try / spacing)), 1, 64);
        }
        const FootResult foot = settle_at_foot(&snake, fo);
        if (foot.unclean) {
          a.notes.push_back("not settled at the foot: most of the contour has no clean background outside");
          return;
        }
        // Moving out can twist neighbours (rays from a jagged snake cross): cut the loops
        // (each call removes at most 64) and the sharp turns again.
        for (int guard = 0; guard < 100 && snake.remove_loops() > 0; ++guard) {
        }
        snake.remove_sharp_turns(options.max_turn_degrees);
        snake.trim_boundary_ends();
        if (foot.noisy)
          a.notes.push_back("not settled at the foot: the background is too noisy (residual " +
                            fmt(foot.background_residual / h_try) + " h)");
        else
          a.notes.push_back("settled at the foot: " + std::to_string(foot.moved) + " snaxels moved out by " +
                            fmt(foot.mean_move / h_try) + " h on average, " + std::to_string(foot.skipped) +
                            " left (no clean background outside)" +
                            (foot.toe_fitted > 0 ? ", " + std::to_string(foot.toe_fitted) + " placed by the step's toe" : ""));
        a.run.contour = snake.points();
      };
      // The region the contour cuts, the snaxels on a sharp wall moved down it, the step measured.
      auto region_and_step = [&] {
        a.region = relief_region(mesh, a.run.contour, options.closed, inside_left);
        if (options.wall_foot) settle_down_walls(mesh, &a.run.contour, a.region);
        a.evidence.step = measure_step(mesh, a.run.contour, a.region, h_try, evidence_options);
      };
      if (options.foot_snap) settle_at_the_foot(false);
      region_and_step();
      if (!options.foot_snap && options.foot_snap_blended && blended_and_clean(a.evidence.step, h_try, mesh.average_edge_length(), options.foot_gate_residual)) {
        settle_at_the_foot(true);
        region_and_step();
      }
      a.evidence.covered_share = covered_share(mesh, enclosure, a.region, h_try, a.evidence.step.step_height);
      if (!mask_reach.empty()) {
        double beyond = 0, all = 0;
        for (int v = 0; v < mesh.n_vertices(); ++v)
          if (a.region[v]) all += mesh.vertex_area(v), beyond += mask_reach[v] ? 0.0 : mesh.vertex_area(v);
        a.evidence.beyond_mask_share = all > 0 ? beyond / all : 0.0;
      }
      a.evidence.coarse_step_share = coarse_step_share;
      a.evidence.abandoned_area_share = a.run.abandoned && a.run.abandoned_for_area ? a.run.abandoned_area_share : -1.0;
      a.evidence.abandoned_left_share = a.run.abandoned && !a.run.abandoned_for_area ? a.run.abandoned_left_share : -1.0;
      a.evidence.coarse_iou = region_iou(mesh, coarse_region, a.region);
      if (options.coarse_relief_kept && strayed_from_coarse(coarse_step_share, a.evidence.coarse_iou, self_check))
        a.evidence.coarse_relief_kept = kept_of_coarse_relief(a.region);
      if (options.closed) {
        std::vector<Vec3> polyline;
        for (const SurfacePoint& p : a.run.contour) polyline.push_back(position(mesh, p));
        const Vec3 enclosed = vector_area(polyline);
        const double norm2 = enclosed.squaredNorm();
        // The region's faces stop half a triangle short of the contour: add that strip back
        // (perimeter x half an edge) so fine and coarse meshes compare alike.
        double perimeter = 0;
        for (std::size_t k = 0; k < polyline.size(); ++k) perimeter += (polyline[(k + 1) % polyline.size()] - polyline[k]).norm();
        const double strip = 0.5 * perimeter * mesh.average_edge_length();
        a.evidence.area_ratio =
            norm2 > 0 ? (std::fabs(region_vector_area(mesh, a.region).dot(enclosed)) / std::sqrt(norm2) + strip) /
                            std::sqrt(norm2)
                      : 0.0;
      } else if (!side_given) {
        const std::vector<char> other = relief_region(mesh, a.run.contour, false, !inside_left);
        a.evidence.other_side_share = measure_step(mesh, a.run.contour, other, h_try, evidence_options).step_share;
      }
      const int far_index = a.evidence.step.far_point;
      const Vec3 far_position = far_index >= 0 ? mesh.to_file(position(mesh, a.run.contour[far_index])) : Vec3::Zero();
      // The region-wide check only where the contour-wise one holds (a failing attempt is doubtful
      // already), and for the repair of a region that took in background.
      if (judge(a.evidence, h_try, contour_wise).holds) {
        BackgroundInside inside = measure_region_wide(a);
        if (inside_out) *inside_out = std::move(inside);
      }
      a.check = judge(a.evidence, h_try, self_check, far_index >= 0 ? &far_position : nullptr);
    };
    // Repair (closed contours; not in the paper): a region that took in a piece of background
    // (a bridged concavity, a lobe round a texture dot) loses it, and the snake is refined again
    // from the rest's outline at the finest spacing, where narrow concavities hold it.
    auto repaired = [&](const Attempt& a, const BackgroundInside& inside, double w) {
      Attempt r;
      const double limit = background_depth_limit(a.evidence, self_check) * h_try;
      std::vector<int> loop = region_outer_loop(mesh, inside.region_without(a.region, limit));
      if (loop.size() < 8) return r;
      r.h = h_try;
      r.w_int = w;
      r.run = schedule.refine_from(snake_start_along(std::move(loop)), w, progress);
      r.parameters = a.parameters;
      ++result.attempts;
      if (r.run.cancelled || r.run.collapsed) return r;
      settle_and_judge(r, nullptr);
      r.notes.insert(r.notes.begin(), "repaired: a piece of background of about " + fmt(a.evidence.background_area) +
                                          " h^2 that the contour took in was cut out, and the snake refined again "
                                          "from the rest");
      return r;
    };
    bool first = true;
    // A refinement from a coarse contour on the step whose contour shrinks well below the
    // coarse-overlap check's share (its region could not pass min_coarse_iou; 0.8 leaves room for
    // vector areas against region areas) is crossing the relief: stop it there.
    // It is also stopped once it has left more than a tenth of the coarse contour's step (no snaxel
    // within 2 h of those points): the final contour can then no longer run along the step over
    // the share the self-check asks for (90%) except on some other step further in (detail), and
    // deflation never brings a stretch back out. On the randomized suite no refinement whose verdict
    // held had left more than 6.3% of the points by 2 h (seeds 0:100; 6.5% on 1000:1050); the
    // 1M-triangle sharp duck on a cylinder at W_int 0.25 passes 10% after 600 iterations, where the
    // area stop waited 1,900 (docs/design.md).
    RefineStop stop;
    StepAnchors anchors;
    if (coarse_step_share >= self_check.min_step_share) {
      stop.min_area_share = 0.8 * self_check.min_coarse_iou;
      anchors = step_anchors(mesh, coarse.contour, coarse_step, options.closed);
      stop.anchors = &anchors;
    }
    // An abandoned refinement fails the verdict whatever its evidence, and it cannot be repaired
    // (the region-wide check only runs where the contour-wise verdict holds): its evidence only
    // ranks it against later attempts that fail too. So it is judged only when one does (or none
    // is left), in order, and a later attempt that holds is kept without it (0.3 s of evidence on
    // the 1M-triangle duck).
    std::vector<Attempt> unjudged;
    auto judge_unjudged = [&] {
      for (Attempt& u : unjudged) {
        settle_and_judge(u, nullptr);
        if (first || better(u, best)) best = std::move(u);
        first = false;
      }
      unjudged.clear();
    };
    for (const double w : outline_from ? std::vector<double>{} : w_steps) {
      Attempt a;
      a.h = h_try;
      a.w_int = w;
      a.run = schedule.refine(w, progress, stop);
      a.parameters = schedule.parameters(w);
      ++result.attempts;
      if (a.run.cancelled) {
        cancelled = true;
        return best;
      }
      if (a.run.abandoned && w != w_steps.back()) {
        unjudged.push_back(std::move(a));
        continue;
      }
      if (a.run.collapsed) {
        judge_unjudged();
        collapse_phase = a.run.collapsed_phase;
        if (first) best = a, first = false;
        continue;
      }
      BackgroundInside inside;
      settle_and_judge(a, &inside);
      if (options.repair_background && options.closed && !a.check.holds && background_taken_in(a.evidence, self_check)) {
        Attempt r = repaired(a, inside, w);
        if (r.run.cancelled) {
          cancelled = true;
          return best;
        }
        if (r.usable() && better(r, a)) a = std::move(r);
      }
      const bool holds = a.check.holds;
      if (holds) {  // it is better than any attempt before it, none of which held
        best = std::move(a);
        unjudged.clear();
        break;
      }
      judge_unjudged();
      if (first || better(a, best)) best = std::move(a);
      first = false;
    }
    judge_unjudged();
    if (outline_from && !cancelled) {
      // Closed: the coarse region with the refined one (the coarse contour bridges what refinement may
      // have cut off). Open: the refined one alone, since an open coarse region is the whole side
      // beyond the coarse contour, background up to the relief included.
      std::vector<char> seed = coarse_region;
      if (outline_from->usable()) {
        if (!options.closed) seed = outline_from->region;
        for (std::size_t v = 0; v < seed.size(); ++v) seed[v] = seed[v] || outline_from->region[v];
      }
      const double found = coarse_step.step_height;
      const double step = found > 0 ? std::clamp(found, 0.5 * h_try, 2 * h_try) : h_try;
      ReliefMaskOptions mask_options;
      if (!options.closed) mask_options.min_share = 0;
      const ReliefMask mask = relief_mask(mesh, seed, h_try, step, mask_options);
      background_seconds += mask.seconds;
      std::vector<int> loop = mask.ok ? start_outline(mesh, mask.start_region, options.closed) : std::vector<int>{};
      if (!loop.empty()) {
        const std::vector<SurfacePoint> outline = snake_start_along(std::move(loop));
        schedule.set_barrier(mask.height, mask.level);
        mask_reach = grown_region(mesh, mask.start_region, std::max(h_try, 3 * mesh.average_edge_length()),
                                  tangential_length(mesh, mask.base_normals));
        for (const double w : w_steps) {
          Attempt a;
          a.h = h_try;
          a.w_int = w;
          a.run = schedule.refine_from(outline, w, progress);
          a.parameters = schedule.parameters(w);
          ++result.attempts;
          if (a.run.cancelled) {
            cancelled = true;
            return best;
          }
          if (!a.usable()) continue;
          settle_and_judge(a, nullptr);
          a.notes.insert(a.notes.begin(), "refined again from just outside what stands " + fmt(mask.level) +
                                              " above the background filled in under the region");
          const bool holds = a.check.holds;
          if (first || better(a, best)) best = std::move(a);
          first = false;
          if (holds) break;
        }
      }
    }
    return best;
  };

  // A kept contour whose step the refit measured again at that step's height, where the refit's
  // contour had weaker evidence: the step is the scan's and h was off, so the contour is judged
  // with the refit-free step ratio (its region-wide check run first, which that ratio had held back).
  auto judge_with_confirmed_step = [&](Attempt& kept, double found, const Attempt& refit) {
    const double again = refit.usable() ? refit.evidence.step.step_height : 0.0;
    if (!(again > 0) || std::fabs(std::log(again / found)) >= std::log(1.15)) return false;
    if (!judge(kept.evidence, kept.h, step_confirmed_contour_wise).holds) return false;
    if (!judge(kept.evidence, kept.h, contour_wise).holds) measure_region_wide(kept);
    SelfCheck loose = judge(kept.evidence, kept.h, step_confirmed);
    if (!loose.holds) return false;
    kept.check = std::move(loose);
    return true;
  };
  // One h, then the refit along the contour; the notes go to the result if it is kept.
  std::vector<double> tried;
  const double largest_h = largest_plausible_step_height(mesh, initial.path, options.closed);
  auto attempt_with_refits = [&](double h_first, std::vector<std::string>* notes) {
    Attempt kept = attempt_at(h_first);
    tried.push_back(h_first);
    for (int refit = 0; refit < 2 && options.refit_step_height && !cancelled && kept.usable(); ++refit) {
      const double found = kept.evidence.step.step_height;
      if (!refit_wanted(found, kept.h, tried, options, largest_h)) break;
      tried.push_back(found);
      Attempt next = attempt_at(found);
      if (cancelled) break;
      const std::string refitted = "the step along the contour measured " + fmt(found) + " against h = " +
                                   fmt(kept.h) + "; segmented again with h = " + fmt(found);
      if (!better(next, kept)) {
        if (options.confirmed_step && !kept.check.holds && judge_with_confirmed_step(kept, found, next))
          notes->push_back(refitted + ", the step measured " + fmt(next.evidence.step.step_height) +
                           " again but that contour's evidence was weaker: this one is kept");
        break;
      }
      notes->push_back(refitted);
      kept = std::move(next);
    }
    // Still failing: the step at the contour's edge (the knee), where it disagrees with h.
    if (options.refit_step_height && options.edge_step_refit && !cancelled && kept.usable() && !kept.check.holds) {
      const double edge_step = kept.evidence.step.edge_step_height;
      if (refit_wanted(edge_step, kept.h, tried, options, largest_h)) {
        tried.push_back(edge_step);
        Attempt next = attempt_at(edge_step);
        if (!cancelled && better(next, kept)) {
          notes->push_back("the step at the contour's edge measured " + fmt(edge_step) + " against h = " +
                           fmt(kept.h) + "; segmented again with h = " + fmt(edge_step));
          kept = std::move(next);
        }
      }
    }
    return kept;
  };
  std::vector<std::string> h_notes;
  Attempt best;
  if (h > 0) best = attempt_with_refits(h, &h_notes);
  // A side being probed (segment_deciding_side) whose first h fails as a wrong side does, or collapses,
  // and that has further guesses of h to leave for later (a given h has none: its search is done).
  if (probe_failed && !h_given && options.retry_estimate != EstimateRetry::Off && h > 0 && !cancelled &&
      (!best.usable() || (!best.check.holds && looks_like_the_wrong_side(best.evidence.step.step_share,
                                                                         best.evidence.step.measured_share(),
                                                                         best.evidence.other_side_share)))) {
    *probe_failed = true;
    Result probe;
    probe.status = Status::Doubtful;
    probe.attempts = result.attempts;
    if (best.usable()) probe.reasons = best.check.reasons;  // none: the snake collapsed
    return probe;
  }
  // An estimated h that gives no result (or, unless retry_estimate=no_result, one that fails the
  // self-check): the estimator's further guesses, each with its refit, the best evidence kept.
  // Guesses within x1.3 of an h tried already would find the same contour.
  const bool retry_doubtful = options.retry_estimate == EstimateRetry::Doubtful ||
                              options.retry_estimate == EstimateRetry::DoubtfulFlagged;
  const bool retry = !h_given && options.retry_estimate != EstimateRetry::Off &&
                     (!best.usable() || (retry_doubtful && !best.check.holds));
  // doubtful_flagged: a result kept from a further guess after the first estimate's failed its
  // self-check is reported doubtful with this reason (each guess is one more chance for a wrong
  // contour to pass).
  std::string second_guess_reason;
  const std::string first_failure =
      best.usable() && !best.check.reasons.empty() ? best.check.reasons.front() : std::string();
  if (retry && !cancelled) {
    for (const StepHeightGuess& guess :
         alternative_step_heights(mesh, initial.path, options.closed, inside_left, estimate)) {
      const double g = resolvable(guess.value);
      bool near_tried = false;
      for (const double t : tried) near_tried = near_tried || std::fabs(std::log(g / t)) < std::log(options.refit_ratio);
      if (near_tried) continue;
      std::vector<std::string> notes = {"the estimated h = " + fmt(h) +
                                        (best.usable() ? " gave a result that failed the self-check"
                                                       : " gave no result (the snake collapsed)") +
                                        "; segmented again with h = " + fmt(g) + " (" + guess.source + ")"};
      if (!(h > 0)) notes.front() = "h = " + fmt(g) + " estimated from " + guess.source;
      Attempt next = attempt_with_refits(g, &notes);
      if (cancelled) break;
      if (!best.usable() || better(next, best)) {
        if (options.retry_estimate == EstimateRetry::DoubtfulFlagged && !first_failure.empty())
          second_guess_reason = "h was guessed again: at the first estimate (" + fmt(h) +
                                ") the result failed the self-check (" + first_failure + "); this one, at h = " +
                                fmt(next.h) + ", passes it only as a further guess";
        best = std::move(next);
        h_notes = std::move(notes);
        if (!(h > 0)) h = g, result.step_height_estimate = g;
      }
      if (best.usable() && best.check.holds) break;
    }
  }
  // Still failing at every h tried: the snake refined from just outside what the heights call relief
  // (relief_mask.hpp), at the kept attempt's h.
  // Not for a side the engine decided whose result looks like the wrong side: the other side is
  // segmented then (segment_deciding_side), and an outline on the background gave a failing result
  // that no longer looked wrong-sided (random scan 12), so the right side was never tried.
  const bool wrong_side_suspect =
      side_decided && best.usable() &&
      looks_like_the_wrong_side(best.evidence.step.step_share, best.evidence.step.measured_share(),
                                best.evidence.other_side_share);
  if (options.height_outline && !cancelled && best.usable() && !best.check.holds && !wrong_side_suspect) {
    // At the step measured at the kept contour's edge where that is higher than h (up to x2): an h too
    // small holds the snake partway up a blended step, and the outline starts outside its foot.
    const double knee = best.evidence.step.edge_step_height;
    const double h_outline = std::clamp(knee, best.h, 2 * best.h);
    Attempt next = attempt_at(h_outline, &best);
    // With its own refit: the start does not depend on h, the step found along it may.
    std::vector<double> outline_tried = {h_outline};
    for (int refit = 0; refit < 2 && options.refit_step_height && !cancelled && next.usable() && !next.check.holds;
         ++refit) {
      const double found = next.evidence.step.step_height;
      if (!refit_wanted(found, next.h, outline_tried, options, largest_h)) break;
      outline_tried.push_back(found);
      Attempt again = attempt_at(found, &best);
      if (cancelled || !better(again, next)) break;
      next = std::move(again);
    }
    if (!cancelled && next.usable() && better(next, best)) best = std::move(next);
  }
  if (!h_given && !(h > 0))
    throw Error("could not estimate the step height: nothing rises above the background inside the picked "
                "contour; give h (measure the step) or pick around the relief");
  for (std::string& n : h_notes) result.notes.push_back(std::move(n));
  if (cancelled) {
    Result out;
    out.status = Status::Cancelled;
    out.closed = options.closed;
    return out;
  }
  if (!best.usable()) {
    const std::string no_relief = enclosure_reason(enclosure, h);
    if (!no_relief.empty() && collapse_phase != "initial")
      throw Error("the snake collapsed during the " + collapse_phase + " phase: " + no_relief);
    if (collapse_phase == "initial")
      throw Error("the picked contour is only a few step heights long; pick vertices further from the relief "
                  "or check h (" + fmt(h) + ")");
    throw Error("the snake collapsed during the " + collapse_phase +
                " phase without meeting a relief step; check that h (" + fmt(h) +
                ") matches the relief's step height and that the picks surround the relief");
  }

  // --- the result ---------------------------------------------------------------
  PhaseStats pre;
  pre.name = "preprocess";
  pre.seconds = preprocess_seconds;
  pre.snaxels = best.run.phases.empty() ? 0 : best.run.phases.front().snaxels;
  result.phases.push_back(pre);
  for (const PhaseStats& p : best.run.phases) result.phases.push_back(p);
  if (best.run.refine_levels > 1)
    result.notes.push_back("refined coarse to fine in " + std::to_string(best.run.refine_levels) + " levels");
  for (const std::string& n : best.notes) result.notes.push_back(n);
  if (options.w_int <= 0 && best.w_int != w_steps.front())
    result.notes.push_back("W_int " + fmt(best.w_int) + " chosen: the self-check failed with smaller values");
  result.parameters = best.parameters;
  result.parameters.step_height = best.h;
  result.step_height_measured = best.evidence.step.edge_step_height;
  result.planarity_vertices = cache_->planarity ? cache_->planarity->raw_count() : 0;
  if (!h_given) {
    // As sure as the step found along the contour is even; a refitted h rests on that alone.
    const double from_contour =
        std::clamp(1.0 - best.evidence.step.step_spread, 0.0, 1.0) * best.evidence.step.step_share;
    const bool refitted = std::fabs(std::log(best.h / h)) > 1e-12;
    result.step_height_confidence = refitted ? from_contour : std::max(result.step_height_confidence, from_contour);
  }

  // --- inner holes (holes.cpp): cleared from the region; a failed hole makes the result doubtful
  if (options.closed && (options.holes == HoleMode::Auto || !options.hole_picks.empty())) {
    PlanarityField& planarity = planarity_for(mesh, cache_->planarity, cache_->options, cache_->tree, options,
                                              best.h, best.run.contour, component);
    const HoleSearch holes = segment_holes(mesh, planarity, options, best.h, &best.region, progress);
    if (holes.cancelled) return cancelled_result();
    add_holes(mesh, holes, &result, &best.check);
  }

  result.contour = best.run.contour;
  result.polyline.reserve(result.contour.size());
  for (const SurfacePoint& p : result.contour) result.polyline.push_back(mesh.to_file(position(mesh, p)));
  for (std::size_t i = 0; i < mesh.input_vertex_count(); ++i) {
    const int v = mesh.input_to_mesh(i);
    if (v >= 0 && best.region[v]) result.relief_vertices.push_back(static_cast<std::int64_t>(i));
  }

  const StepEvidence& step = best.evidence.step;
  result.checks.insert(result.checks.begin(), {{"step_share", step.step_share},
                   {"step_height", step.step_height},
                   {"edge_step_height", step.edge_step_height},
                   {"rise_median", step.rise_median},
                   {"step_spread", step.step_spread},
                   {"foot_share", step.foot_share},
                   {"background_residual", step.background_residual},
                   {"background_quadric_residual", step.background_quadric_residual},
                   {"measured_share", step.measured_share()},
                   {"coarse_step_share", best.evidence.coarse_step_share},
                   {"coarse_iou", best.evidence.coarse_iou},
                   {"area_ratio", best.evidence.area_ratio},
                   {"region_area", region_area(mesh, best.region)},
                   {"front_low_share", step.front_low_share},
                   {"front_low_run", step.longest_front_low / best.h},
                   {"offset_median", step.offset_median / best.h},
                   {"offset_q75", step.offset_q75 / best.h},
                   {"offset_q90", step.offset_q90 / best.h},
                   {"offset_q95", step.offset_q95 / best.h},
                   {"far_share", step.far_share},
                   {"far_run", step.longest_far / best.h},
                   {"foot_gap_median", step.foot_gap_median / best.h},
                   {"foot_gap_q75", step.foot_gap_q75 / best.h},
                   {"rise_width", step.rise_width_median / best.h},
                   {"background_depth", best.evidence.background_depth},
                   {"background_area", best.evidence.background_area}});
  if (best.evidence.coarse_relief_kept >= 0)
    result.checks.push_back({"coarse_relief_kept", best.evidence.coarse_relief_kept});
  if (best.evidence.other_side_share >= 0) result.checks.push_back({"other_side_share", best.evidence.other_side_share});
  if (best.evidence.beyond_mask_share >= 0) result.checks.push_back({"beyond_mask_share", best.evidence.beyond_mask_share});
  if (!side_given) {
    // The side decision's margin: the side not taken's rise along the picks over the side taken's.
    const double taken = inside_left ? estimate.left_rise : estimate.right_rise;
    const double other_rise = inside_left ? estimate.right_rise : estimate.left_rise;
    if (taken > 0) result.checks.push_back({"other_side_rise", std::max(other_rise, 0.0) / taken});
  }
  result.reasons = best.check.reasons;
  if (!second_guess_reason.empty() && result.reasons.empty()) result.reasons.push_back(second_guess_reason);
  if (options.closed) {
    // Picks on one side of the relief can still leave a snake that settles on something. Judged
    // with the step found along the contour where it is lower than h (a rough h given too large,
    // or a background the quadric follows only roughly: the step is there, the snake measured it).
    const double judged = judged_step(best.h, best.evidence.step.step_height);
    const double risen = risen_area(enclosure, EnclosureOptions().rise * judged);
    result.checks.push_back({"enclosed_risen_area", risen / (judged * judged)});
    result.checks.push_back({"enclosed_risen_share", enclosure.enclosed_area > 0 ? risen / enclosure.enclosed_area : 0.0});
    result.checks.push_back({"covered_share", best.evidence.covered_share});
    result.checks.push_back({"enclosed_background_residual", enclosure.background_residual / best.h});
    // Named when nothing else is wrong (a snake holding on texture or noise inside picks beside the
    // relief), or when the snake found little step either; a contour mostly on a step with picks
    // that "enclose nothing" says more about the quadric (a wavy background under a wide ring).
    const std::string no_relief = enclosure_reason(enclosure, judged);
    if (!no_relief.empty() && (result.reasons.empty() || best.evidence.step.step_share < 0.5))
      result.reasons.push_back(no_relief);
  }
  if (best.run.hit_cap) {
    result.status = Status::IterationCap;
    result.reasons.insert(result.reasons.begin(), "a phase stopped at the iteration cap (" +
                                                      std::to_string(options.max_iterations) +
                                                      ") before the snake settled");
  } else {
    result.status = result.reasons.empty() ? Status::Converged : Status::Doubtful;
  }
  if (result.status != Status::Converged) {
    std::string message = result.status == Status::IterationCap ? "The snake did not settle: " : "Check this result: ";
    for (std::size_t k = 0; k < result.reasons.size(); ++k) message += (k ? "; " : "") + result.reasons[k];
    message += ". Try picks closer around the relief";
    // With h estimated, giving it is the other remedy (the estimate, or a further guess of it, may be off).
    message += h_given ? ", or a different step height" : ", or give the step height";
    message += ".";
    result.message = message;
  }
  result.checks.push_back({"background_seconds", background_seconds});
  result.checks.push_back({"seconds", seconds_since(t_start)});
  return result;
}

Result segment(const Mesh& mesh, const std::vector<std::int64_t>& picks, const Options& options,
               const ProgressCallback& progress) {
  Segmenter segmenter(mesh);
  return segmenter.segment(picks, options, progress);
}

}  // namespace relief_snake

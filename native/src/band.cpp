#include "report_text.hpp"
#include "relief_snake/band.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "relief_snake/error.hpp"
#include "relief_snake/evidence.hpp"
#include "relief_snake/region.hpp"
#include "relief_snake/schedule.hpp"

namespace relief_snake {

namespace {

using Clock = std::chrono::steady_clock;

// One step from the two rings' measurements of it: their geometric mean, or the one measured.
double both_rings(double a, double b) { return a > 0 && b > 0 ? std::sqrt(a * b) : std::max(a, b); }

// One ring's snake, as the outer contour's attempts: schedule, region side, evidence, verdict.
struct RingRun {
  ScheduleRun run;
  std::vector<char> side;  // #V: the ring's relief side
  ContourEvidence evidence;
  SelfCheck check;
  DerivedParameters parameters;
  double w_int = 0;
  int attempts = 0;
  bool usable() const { return !run.cancelled && !run.collapsed && !run.contour.empty(); }
};

RingRun run_ring(const Mesh& mesh, PlanarityField& planarity, const Options& options, double h,
                 const SurfacePath& path, bool relief_left, const SelfCheckOptions& self_check,
                 const ProgressCallback& progress) {
  RingRun best;
  const std::vector<SurfacePoint> start = resample_path(mesh, path, h, true);
  if (start.size() < 4) {
    best.run.collapsed = true;
    best.run.collapsed_phase = "initial";
    return best;
  }
  Options ring_options = options;
  ring_options.closed = true;
  ring_options.foot_snap = false;
  EvolutionSchedule schedule(mesh, planarity, ring_options, h, start, relief_left);
  const ScheduleRun& coarse = schedule.coarse(progress);
  if (coarse.cancelled || coarse.collapsed) {
    best.run = coarse;
    return best;
  }
  const std::vector<char> coarse_side = relief_region(mesh, coarse.contour, true, relief_left);
  const double coarse_share = measure_step(mesh, coarse.contour, coarse_side, h).step_share;
  const std::vector<double> w_steps =
      options.w_int > 0 ? std::vector<double>{options.w_int} : std::vector<double>{0.25, 0.5, 1.0};
  bool first = true;
  int attempts = 0;
  for (const double w : w_steps) {
    RingRun a;
    a.run = schedule.refine(w, progress);
    a.w_int = w;
    a.parameters = schedule.parameters(w);
    a.attempts = ++attempts;
    if (a.run.cancelled) return a;
    if (a.run.collapsed) {
      if (first) best = a, first = false;
      continue;
    }
    a.side = relief_region(mesh, a.run.contour, true, relief_left);
    a.evidence.step = measure_step(mesh, a.run.contour, a.side, h);
    a.evidence.coarse_step_share = coarse_share;
    a.evidence.coarse_iou = region_iou(mesh, coarse_side, a.side);
    a.check = judge(a.evidence, h, self_check);
    const bool holds = a.check.holds;
    if (first || !best.usable() || (holds && !best.check.holds) ||
        (holds == best.check.holds && a.check.score > best.check.score))
      best = std::move(a);
    first = false;
    best.attempts = attempts;
    if (holds) break;
  }
  return best;
}

// Which side of ring `a` ring `b` lies on: the share of b's corners on a's left.
double share_left_of(const Mesh& mesh, const SurfacePath& a, const SurfacePath& b) {
  const std::vector<char> left = relief_region(mesh, a, true, true);
  int on_left = 0;
  for (const SurfacePoint& p : b) on_left += left[nearest_corner(mesh, p)] != 0;
  return b.empty() ? 0.0 : static_cast<double>(on_left) / static_cast<double>(b.size());
}

// The step seen from a ring into one side: local planes outside, the rise inside (evidence.hpp).
// The pick rings lie a few h beside the step, so the ball grows (from 6 edges, doubling) until
// half the ring sees a step, while the rise that counts stays that of the first ball (0.3 x 6
// edges): a growing threshold would pass over a small step.
StepEvidence side_step(const Mesh& mesh, const SurfacePath& path, const std::vector<char>& side) {
  const double first = 6 * mesh.average_edge_length();
  StepEvidence found;
  for (double ball = first; ball <= 16 * first; ball *= 2) {
    EvidenceOptions eo;
    eo.min_rise = 0.3 * first / ball;
    eo.outside_from = 0.5 * first / ball;
    found = measure_step(mesh, path, side, ball, eo);
    if (found.step_share >= 0.5) break;
  }
  return found;
}

struct BandAttempt {
  double h = 0;
  double estimate = 0;    // the h the configuration started from
  bool engraved = false;  // the walls rise away from the other ring (a groove)
  std::vector<std::string> notes;
  RingRun first, second;
  std::vector<char> region;
  bool usable() const { return first.usable() && second.usable(); }
  // Snakes that passed each other (rings on a groove's floor run as a frieze end at the far walls)
  // leave nothing between them: no verdict holds then.
  bool between() const {
    for (const char f : region)
      if (f) return true;
    return false;
  }
  int holds() const { return between() ? int(first.check.holds) + int(second.check.holds) : 0; }
  double score() const { return first.check.score + second.check.score; }
  double step_found() const {
    return both_rings(first.evidence.step.step_height, second.evidence.step.step_height);
  }
};

bool better(const BandAttempt& a, const BandAttempt& b) {
  if (a.usable() != b.usable()) return a.usable();
  if (a.holds() != b.holds()) return a.holds() > b.holds();
  return a.score() > b.score();
}

}  // namespace

SurfacePath ring_path(const Mesh& mesh, const std::vector<int>& picks) {
  if (picks.size() < 3) throw Error("a pick ring needs at least 3 vertices round the surface");
  std::vector<int> there_and_back = picks;
  there_and_back.push_back(picks.front());
  InitialContour joined = initial_contour(mesh, there_and_back, false);
  SurfacePath path = std::move(joined.path);
  path.pop_back();  // the first pick again
  return path;
}

Result segment_band(const Mesh& mesh, const std::vector<int>& first_ring, const std::vector<int>& second_ring,
                    const Options& options, const PlanarityProvider& planarity, const ProgressCallback& progress) {
  const auto t_start = Clock::now();
  if (!options.closed) throw Error("a band between two pick rings is closed on both sides; drop the open option");
  if (!options.hole_picks.empty()) throw Error("hole picks are not supported for a band; segment the band without them");
  for (const int v : second_ring)
    if (mesh.component(v) != mesh.component(first_ring.front()))
      throw Error("the two pick rings lie on different parts of the mesh; pick both rings round one surface");
  const SurfacePath path_a = ring_path(mesh, first_ring), path_b = ring_path(mesh, second_ring);

  // Each ring's relief side is the side the other ring lies on.
  const double b_left_of_a = share_left_of(mesh, path_a, path_b), a_left_of_b = share_left_of(mesh, path_b, path_a);
  auto decided = [](double share) { return share > 0.9 || share < 0.1; };
  if (!decided(b_left_of_a) || !decided(a_left_of_b))
    throw Error("the two pick rings cross or touch; pick one ring on the background on each side of the band, "
                "each going right round the surface");
  const bool toward_left_a = b_left_of_a > 0.5, toward_left_b = a_left_of_b > 0.5;
  const std::vector<char> toward_a = relief_region(mesh, path_a, true, toward_left_a);
  const std::vector<char> toward_b = relief_region(mesh, path_b, true, toward_left_b);

  Result result;
  result.closed = true;
  const bool h_given = options.step_height > 0;
  SelfCheckOptions self_check;
  if (options.refit_step_height) self_check.max_step_ratio = std::max(1.5, options.refit_ratio * 1.15);
  bool cancelled = false;

  // One configuration: raised (a frieze, rings on the background beside it: each snake's relief
  // side is towards the other ring) or engraved (a groove, rings on its floor: the walls rise away
  // from the other ring). h estimated for it when not given, then refitted.
  auto run_configuration = [&](bool engraved) {
    const bool left_a = engraved ? !toward_left_a : toward_left_a, left_b = engraved ? !toward_left_b : toward_left_b;
    double h = options.step_height;
    BandAttempt none;
    if (!h_given) {
      std::vector<char> side_a = toward_a, side_b = toward_b;
      if (engraved) {
        for (char& f : side_a) f = !f;
        for (char& f : side_b) f = !f;
      }
      const double a = side_step(mesh, path_a, side_a).step_height, b = side_step(mesh, path_b, side_b).step_height;
      const double found = both_rings(a, b);
      if (!(found > 0)) return none;
      h = std::clamp(found, 0.5 * mesh.average_edge_length(), mesh.bbox_diagonal() / 4);
      none.h = h;
    }
    auto attempt_at = [&](double h_try) {
      BandAttempt a;
      a.h = h_try;
      a.engraved = engraved;
      a.estimate = h;
      PlanarityField& field = planarity(h_try, resample_path(mesh, path_a, h_try, true));
      a.first = run_ring(mesh, field, options, h_try, path_a, left_a, self_check, progress);
      if (a.first.run.cancelled) {
        cancelled = true;
        return a;
      }
      a.second = run_ring(mesh, field, options, h_try, path_b, left_b, self_check, progress);
      if (a.second.run.cancelled) {
        cancelled = true;
        return a;
      }
      result.attempts += a.first.attempts + a.second.attempts;
      if (a.usable()) {
        // The band lies towards the other ring from each contour: the relief side of a frieze's
        // contours, the other side of a groove's.
        a.region.assign(mesh.n_vertices(), 0);
        for (int v = 0; v < mesh.n_vertices(); ++v)
          a.region[v] = engraved ? (!a.first.side[v] && !a.second.side[v]) : (a.first.side[v] && a.second.side[v]);
      }
      return a;
    };
    BandAttempt best = attempt_at(h);
    std::vector<double> tried = {h};
    for (int refit = 0; refit < 2 && options.refit_step_height && !cancelled && best.usable(); ++refit) {
      const double found = best.step_found();
      if (!refit_wanted(found, best.h, tried, options)) break;
      tried.push_back(found);
      BandAttempt next = attempt_at(found);
      if (cancelled) break;
      if (!better(next, best)) break;
      best.notes.push_back("the step along the band measured " + fmt(found) + " against h = " + fmt(best.h) +
                           "; segmented again with h = " + fmt(found));
      next.notes = best.notes;
      best = std::move(next);
    }
    return best;
  };
  // A frieze first; a groove when the frieze's verdicts do not hold on both rings.
  BandAttempt best = run_configuration(false);
  if (!cancelled && best.holds() < 2) {
    BandAttempt groove = run_configuration(true);
    if (!cancelled && better(groove, best)) best = std::move(groove);
  }
  const bool engraved = best.engraved;
  const double h = best.estimate;
  result.relief_side = (engraved ? !toward_left_a : toward_left_a) ? ReliefSide::Left : ReliefSide::Right;
  if (!h_given && best.usable()) {
    result.step_height_estimate = h;
    result.step_height_confidence = 0.5;
    result.notes.push_back("h estimated from the step beside the pick rings: " + fmt(h));
  }
  for (const std::string& n : best.notes) result.notes.push_back(n);
  if (cancelled) {
    Result out;
    out.status = Status::Cancelled;
    return out;
  }
  if (!best.usable() && !h_given && !(best.h > 0))
    throw Error("could not estimate the step height of the band: nothing rises beside the pick rings; give h, "
                "and pick each ring on the background beside a frieze (on the floor near each wall of a groove)");
  if (!best.usable())
    throw Error("a band snake collapsed without meeting a relief step; check that h (" + fmt(best.h) +
                ") matches the band's step and that each pick ring goes right round the surface beside the band");

  result.parameters = best.first.parameters;
  result.parameters.step_height = best.h;
  PhaseStats pre;
  pre.name = "preprocess";
  result.phases.push_back(pre);
  for (const PhaseStats& p : best.first.run.phases) result.phases.push_back(p);
  for (PhaseStats p : best.second.run.phases) {
    p.name = "band_" + p.name;
    result.phases.push_back(p);
  }
  result.contour = best.first.run.contour;
  result.band_contour = best.second.run.contour;
  for (const SurfacePoint& p : result.contour) result.polyline.push_back(mesh.to_file(position(mesh, p)));
  for (const SurfacePoint& p : result.band_contour) result.band_polyline.push_back(mesh.to_file(position(mesh, p)));
  for (std::size_t i = 0; i < mesh.input_vertex_count(); ++i) {
    const int v = mesh.input_to_mesh(i);
    if (v >= 0 && best.region[v]) result.relief_vertices.push_back(static_cast<std::int64_t>(i));
  }
  auto add_checks = [&](const std::string& prefix, const RingRun& ring) {
    const StepEvidence& step = ring.evidence.step;
    const std::vector<std::pair<std::string, double>> named = {
        {"step_share", step.step_share},         {"step_height", step.step_height},
        {"edge_step_height", step.edge_step_height},
        {"rise_median", step.rise_median},       {"step_spread", step.step_spread},
        {"foot_share", step.foot_share},         {"background_residual", step.background_residual},
        {"measured_share", step.measured_share()}, {"coarse_step_share", ring.evidence.coarse_step_share},
        {"coarse_iou", ring.evidence.coarse_iou}};
    for (const auto& [name, value] : named) result.checks.push_back({prefix + name, value});
  };
  add_checks("", best.first);
  add_checks("band_", best.second);
  result.step_height_measured =
      both_rings(best.first.evidence.step.edge_step_height, best.second.evidence.step.edge_step_height);
  const double area = region_area(mesh, best.region);
  result.checks.push_back({"region_area", area});
  for (const std::string& r : best.first.check.reasons) result.reasons.push_back("first ring: " + r);
  for (const std::string& r : best.second.check.reasons) result.reasons.push_back("second ring: " + r);
  if (!(area > 0)) result.reasons.push_back("nothing lies between the two contours");
  const bool hit_cap = best.first.run.hit_cap || best.second.run.hit_cap;
  if (hit_cap) {
    result.status = Status::IterationCap;
    result.reasons.insert(result.reasons.begin(), "a phase stopped at the iteration cap (" +
                                                      std::to_string(options.max_iterations) +
                                                      ") before the snake settled");
  } else {
    result.status = result.reasons.empty() ? Status::Converged : Status::Doubtful;
  }
  if (result.status != Status::Converged) {
    std::string message = result.status == Status::IterationCap ? "The snakes did not settle: " : "Check this result: ";
    for (std::size_t k = 0; k < result.reasons.size(); ++k) message += (k ? "; " : "") + result.reasons[k];
    message += ". Try pick rings closer beside the band";
    message += h_given ? ", or a different step height" : ", or give the step height";
    result.message = message + ".";
  }
  if (!h_given) {
    const double spread = 0.5 * (best.first.evidence.step.step_spread + best.second.evidence.step.step_spread);
    result.step_height_confidence = std::clamp(1.0 - spread, 0.0, 1.0) *
                                    std::min(best.first.evidence.step.step_share, best.second.evidence.step.step_share);
  }
  result.notes.push_back(engraved ? "an engraved band: the groove between the two contours (contour and band_contour), "
                                    "its walls rising away from the middle"
                                  : "a band: the relief lies between the two contours (contour and band_contour)");
  result.checks.push_back({"band_engraved", engraved ? 1.0 : 0.0});
  result.checks.push_back({"seconds", seconds_since(t_start)});
  return result;
}

}  // namespace relief_snake

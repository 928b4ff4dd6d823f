#pragma once
// The evolution schedule (Sections 6, 7.2): the coarse phase at l = h, the
// refinement at half an edge (optionally coarse to fine) with W_int's weights,
// and the stabilisation. A solver object: it runs the coarse phase once and then
// any number of refinements from the coarse snake, so W_int can be chosen by
// trying several (segment.hpp) without repeating the coarse phase.
#include <memory>
#include <string>
#include <vector>

#include "relief_snake/planarity.hpp"
#include "relief_snake/segment.hpp"
#include "relief_snake/snake.hpp"
#include "relief_snake/step_anchors.hpp"
#include "relief_snake/surface_point.hpp"

namespace relief_snake {

/// Where a schedule run ended.
struct ScheduleRun {
  std::vector<SurfacePoint> contour;   ///< snaxels at the end, in order
  std::shared_ptr<Snake> snake;        ///< the snake at the end (the foot stage moves it further)
  std::vector<PhaseStats> phases;      ///< the phases that ran (coarse; refine, stabilise)
  bool hit_cap = false;                ///< a phase stopped at Options::max_iterations
  bool cancelled = false;              ///< the progress callback asked to stop
  bool collapsed = false;              ///< the snake collapsed (collapsed_phase says where)
  std::string collapsed_phase;
  /// The refinement was stopped early (refine(), RefineStop): contour holds where it was; no
  /// stabilisation ran. abandoned_area_share: the share of the coarse contour's vector area the
  /// contour enclosed then; abandoned_left_share: the share of the coarse contour's step it had
  /// left (-1: anchors were not given).
  bool abandoned = false;
  bool abandoned_for_area = false;  ///< the area share fell below RefineStop::min_area_share (else: the step was left)
  double abandoned_area_share = 0;
  double abandoned_left_share = -1;
  int refine_levels = 1;               ///< refinement spacings used
};

/// When a refinement from the coarse snake is stopped early (closed contours): it is carrying the
/// snake across the relief, and finishing it would only cost time. Checked every lock_interval
/// iterations.
struct RefineStop {
  /// Stop once the contour encloses less than this share of the coarse contour's vector area (0: never).
  double min_area_share = 0;
  /// The coarse contour's measured points and which sit on the step (null: no step check). Stop
  /// once more than max_left_share of the on-step points have no snaxel within left_distance h.
  const StepAnchors* anchors = nullptr;
  double left_distance = 2;
  double max_left_share = 0.1;
};

class EvolutionSchedule {
 public:
  /// start: the initial contour resampled at l = h; inside_left: the relief side.
  /// options: the segmentation's options (tau, epsilon, ... ; w_int is given per refinement).
  /// The planarity field must have been built for radius h; it must outlive this object.
  EvolutionSchedule(const Mesh& mesh, PlanarityField& planarity, const Options& options, double h,
                    const std::vector<SurfacePoint>& start, bool inside_left);

  /// The derived parameters for a W_int (Section 7.2.3), also the coarse phase's.
  DerivedParameters parameters(double w_int) const;

  /// The coarse phase (runs once; later calls return the same run).
  const ScheduleRun& coarse(const ProgressCallback& progress);
  /// Refinement and stabilisation with this W_int, from the coarse snake. Runs the
  /// coarse phase first if needed. The returned phases include the coarse one.
  /// stop (closed contours): when to abandon the refinement (ScheduleRun::abandoned).
  ScheduleRun refine(double w_int, const ProgressCallback& progress, const RefineStop& stop = {});
  /// Refinement and stabilisation with this W_int from another start (a repaired contour, already
  /// near the step: only the finest spacing runs). Runs the coarse phase first if needed (its
  /// phase is reported like refine()'s).
  ScheduleRun refine_from(const std::vector<SurfacePoint>& start, double w_int, const ProgressCallback& progress);
  /// Refinements and stabilisations from now on keep every snaxel from moving onto a point that
  /// stands above `level` in `height` (#V; PhaseSettings::barrier). Empty height: none.
  void set_barrier(std::vector<double> height, double level) {
    barrier_ = std::move(height);
    barrier_level_ = level;
  }

 private:
  const Mesh& mesh_;
  PlanarityField& planarity_;
  Options options_;
  double h_;
  bool inside_left_;
  std::vector<SurfacePoint> start_;
  double sigma_background_ = 0;
  bool coarse_done_ = false;
  ScheduleRun coarse_run_;
  std::unique_ptr<Snake> coarse_snake_;  // as the coarse phase left it
  std::vector<double> barrier_;          // set_barrier()
  double barrier_level_ = 0;
  ScheduleRun refine_snake(const Snake& start, bool all_levels, double w_int, const ProgressCallback& progress,
                           const RefineStop& stop = {});
};

}  // namespace relief_snake

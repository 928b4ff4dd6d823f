#pragma once
// Where the coarse contour sat on the step: the refinement's early stop (schedule.hpp). A
// refinement from a coarse contour on the step only moves the stretches off the step (bridges
// over concavities) and settles the rest within about an h of where it was; deflation cannot
// bring a stretch back out once it has been carried inwards across the step.
#include <vector>

#include "relief_snake/evidence.hpp"
#include "relief_snake/mesh.hpp"
#include "relief_snake/snake.hpp"

namespace relief_snake {

/// Measured points of the coarse contour, in contour order, and which of them sit on a step.
struct StepAnchors {
  std::vector<Vec3> points;
  std::vector<char> on_step;
  double spacing = 0;   ///< contour length between consecutive points
  bool closed = true;   ///< runs wrap around
  int on_step_count() const;
};

/// The anchors of a contour from its step evidence (measure_step on it): its measured points.
StepAnchors step_anchors(const Mesh& mesh, const std::vector<SurfacePoint>& contour, const StepEvidence& evidence,
                         bool closed);

/// The on-step anchors that no snaxel comes within `distance` of.
struct StepLeft {
  double share = 0;    ///< of the on-step anchors
  double longest = 0;  ///< longest run of consecutive left on-step anchors, as contour length
};

StepLeft step_left(const StepAnchors& anchors, const Snake& snake, double distance);

}  // namespace relief_snake

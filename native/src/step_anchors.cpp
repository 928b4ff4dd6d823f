#include "relief_snake/step_anchors.hpp"

#include <algorithm>

#include "grid.hpp"
#include "relief_snake/initial_contour.hpp"

namespace relief_snake {

int StepAnchors::on_step_count() const {
  return static_cast<int>(std::count(on_step.begin(), on_step.end(), char(1)));
}

StepAnchors step_anchors(const Mesh& mesh, const std::vector<SurfacePoint>& contour, const StepEvidence& evidence,
                         bool closed) {
  StepAnchors anchors;
  anchors.closed = closed;
  const int n = static_cast<int>(contour.size());
  const double length = path_length(mesh, contour, closed);
  for (const StepProfile& p : evidence.profiles) {
    if (p.contour_index < 0 || p.contour_index >= n) continue;
    anchors.points.push_back(position(mesh, contour[p.contour_index]));
    anchors.on_step.push_back(p.on_step ? 1 : 0);
  }
  anchors.spacing = evidence.attempted > 0 ? length / evidence.attempted : 0.0;
  return anchors;
}

StepLeft step_left(const StepAnchors& anchors, const Snake& snake, double distance) {
  StepLeft out;
  const int m = static_cast<int>(anchors.points.size());
  const int on = anchors.on_step_count();
  if (m == 0 || on == 0 || snake.size() == 0 || !(distance > 0)) return out;
  // The snaxels in a grid of cells `distance` wide; each on-step anchor looks at the 27 cells
  // around its own until one is close enough (a few hundred anchors against thousands of snaxels).
  HashGrid grid(anchors.points[0], distance);
  for (int i = 0; i < snake.size(); ++i) grid.add(grid.cell_of(snake[i].position), i);
  grid.build();
  std::vector<char> reached(m, 0);
  const double d2 = distance * distance;
  for (int k = 0; k < m; ++k) {
    if (!anchors.on_step[k]) continue;
    const Vec3& a = anchors.points[k];
    const HashGrid::Cell c = grid.cell_of(a);
    for (int x = -1; x <= 1 && !reached[k]; ++x)
      for (int y = -1; y <= 1 && !reached[k]; ++y)
        for (int z = -1; z <= 1 && !reached[k]; ++z)
          grid.for_each(c + HashGrid::Cell(x, y, z), [&](int i) {
            if ((snake[i].position - a).squaredNorm() <= d2) reached[k] = 1;
          });
  }
  // Left: on the step and not reached (an off-step or reached anchor ends a run).
  std::vector<char> left(m, 0);
  for (int k = 0; k < m; ++k) left[k] = anchors.on_step[k] && !reached[k];
  out.share = double(std::count(left.begin(), left.end(), char(1))) / on;
  out.longest = longest_run(left, anchors.closed).length * anchors.spacing;
  return out;
}

}  // namespace relief_snake

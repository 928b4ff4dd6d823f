#pragma once
// The snake: an ordered list of snaxels (surface points) with the paper's
// housekeeping (Sections 6 and 7.2.2): split/merge to keep spacing in
// [0.5 l, 1.5 l], removal of sharp turns, and sliding of open ends along the
// mesh boundary.
#include <cstdint>
#include <vector>

#include "relief_snake/mesh.hpp"
#include "relief_snake/surface_point.hpp"

namespace relief_snake {

struct Snaxel {
  SurfacePoint point;
  Vec3 position = Vec3::Zero();
  bool moved = true;        ///< moved in the last iteration (or is new)
  bool locked = false;      ///< oscillation lock (Section 6.1)
  Vec3 anchor = Vec3::Zero();  ///< position at the last lock check
  int age = 0;              ///< iterations since creation or the last lock check
  /// The snake's change count when this snaxel, or its place in the snake, last
  /// changed: housekeeping only re-examines what changed since it last looked.
  std::uint64_t stamp = 0;
};

class Snake {
 public:
  Snake(const Mesh& mesh, const std::vector<SurfacePoint>& points, bool closed, bool inside_left);

  int size() const { return static_cast<int>(snaxels_.size()); }
  bool closed() const { return closed_; }
  bool inside_left() const { return inside_left_; }
  /// Read-only: snaxels change only through the calls below, which keep the change stamps
  /// housekeeping relies on.
  const Snaxel& operator[](int i) const { return snaxels_[i]; }
  /// Neighbour indices; -1 past the ends of an open snake.
  int prev(int i) const { return i > 0 ? i - 1 : (closed_ ? size() - 1 : -1); }
  int next(int i) const { return i + 1 < size() ? i + 1 : (closed_ ? 0 : -1); }
  bool is_end(int i) const { return !closed_ && (i == 0 || i == size() - 1); }

  /// Moves snaxel i to p (stamped as changed; its moved flag is left as it is).
  void move(int i, const SurfacePoint& p);

  // The greedy evolution's interface (evolution.cpp): the moved flags and the oscillation lock.
  /// Starts a greedy iteration: (*moved_before)[i] = snaxel i's moved flag, and every flag cleared.
  /// Returns true if a loop was cut since the last call (remove_loops()): the iteration then looks
  /// at every snaxel again, as if every flag were set (see evolution.cpp for how it skips those
  /// whose energies provably stand).
  bool take_moved_flags(std::vector<char>* moved_before);
  /// A greedy move: move(i, p), and i flagged as moved (the next iteration looks at it and its
  /// neighbours again).
  void step(int i, const SurfacePoint& p);
  /// The oscillation lock (Section 6.1), after each iteration: every `interval` iterations of its
  /// own, a snaxel that got less than `distance` from where it was at its last check is frozen for
  /// the phase (reset_state() thaws it).
  void update_locks(int interval, double distance);
  /// Unit direction towards the inside (relief side) at snaxel i, in the tangent
  /// plane: along the bisector of its two segments.
  Vec3 inward(int i) const;
  /// l_i = 0.5 (|v_{i-1} v_i| + |v_i v_{i+1}|) (one segment at an open end).
  double local_length(int i) const;
  /// Turning angle theta_i in degrees (0 for a straight snake, 0 at open ends).
  double turn_degrees(int i) const;
  double length() const;

  /// Removes snaxels turning more than max_degrees; returns how many. Only the
  /// snaxels whose turn changed since the last call are examined.
  int remove_sharp_turns(double max_degrees);
  /// Splits segments longer than 1.5 l and merges those shorter than 0.5 l;
  /// returns the number of snaxels added plus removed. Only segments that changed
  /// since the last call (with the same l) are examined.
  int resample(double l);
  /// Cuts off loops where the snake crosses itself (the side enclosing the
  /// smaller area goes); returns the number of snaxels removed. Only segments
  /// that changed since the last call are checked against the others, so the
  /// snake must have had no crossing then. Not in the paper: see Options::remove_loops.
  int remove_loops();
  /// Open snakes: drops the snaxels at either end that lie on the mesh boundary behind the
  /// next one, so each end is the last boundary point before the snake leaves the boundary;
  /// returns how many went. Interior snaxels stuck along the boundary hold an end back (their
  /// inward moves leave the mesh) and add nothing to the region, which closes along the
  /// boundary anyway. At least three snaxels stay.
  int trim_boundary_ends();
  /// Resamples every segment to spacing ~l by walking between consecutive snaxels
  /// (used when the refinement phase starts with a shorter l).
  void subdivide(double l);
  /// Clears moved/locked state for a new phase.
  void reset_state();
  /// Where splits, merges and subdivide() put new snaxels: nearest the chord (true,
  /// the default) or at the end of a straight surface walk (see surface_between()).
  void set_nearest_resampling(bool on) { nearest_resampling_ = on; }

  /// True if every snaxel lies within `tolerance` of `old` (a polyline of this
  /// snake, closed or open like it, e.g. an earlier polyline()): the shape has not
  /// changed, whichever snaxels moved along it or were resampled.
  bool within(const std::vector<Vec3>& old, double tolerance) const;

  std::vector<Vec3> polyline() const;
  std::vector<SurfacePoint> points() const;
  const Mesh& mesh() const { return mesh_; }

 private:
  Snaxel make(const SurfacePoint& p);
  /// Appends the pieces - 1 points that cut segment (i, j) into equal pieces; returns how many.
  int append_between(int i, int j, int pieces, std::vector<Snaxel>* out);
  /// Marks snaxel i as changed (and moved, so the greedy step looks at it again).
  void touch(int i);
  bool changed_since(int i, std::uint64_t version) const { return snaxels_[i].stamp > version; }
  /// cos of the turning angle at i (1 for a straight snake, an open end or a zero-length segment).
  double turn_cos(int i) const;
  const Mesh& mesh_;
  std::vector<Snaxel> snaxels_;
  bool closed_, inside_left_;
  bool nearest_resampling_ = true;
  std::uint64_t version_ = 0;  // changes so far (stamps)
  std::uint64_t turns_checked_ = 0, spacing_checked_ = 0, loops_checked_ = 0;  // version_ when each last looked
  bool revisit_all_ = false;  // a loop was cut since take_moved_flags()
  double spacing_l_ = -1;      // the l of the last resample()
};

/// Points on the surface between a and b at fractions t_k of their distance: the
/// surface points nearest the chord points a + t_k (b - a) (nearest = true), or the
/// ends of straight surface walks from a towards b (nearest = false).
std::vector<SurfacePoint> surface_between(const Mesh& mesh, const SurfacePoint& a, const SurfacePoint& b,
                                          const std::vector<double>& fractions, bool nearest = true);
/// surface_between() at the fraction 0.5.
SurfacePoint surface_midpoint(const Mesh& mesh, const SurfacePoint& a, const SurfacePoint& b, bool nearest = true);

/// If p lies on a mesh boundary edge, sets (*face, *edge) to it (edge = opposite corner) and returns true.
bool boundary_edge_of(const Mesh& mesh, const SurfacePoint& p, int* face, int* edge);
/// Slides a point on the mesh boundary by `distance` along the boundary loop
/// (positive: in the loop's direction, i.e. counter-clockwise around the faces).
SurfacePoint slide_along_boundary(const Mesh& mesh, const SurfacePoint& p, double distance);

}  // namespace relief_snake

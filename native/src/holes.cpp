#include "report_text.hpp"
#include "relief_snake/holes.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include <Eigen/Dense>

#include "relief_snake/background.hpp"
#include "relief_snake/error.hpp"
#include "relief_snake/initial_contour.hpp"
#include "relief_snake/mesh_graph.hpp"
#include "relief_snake/region.hpp"
#include "relief_snake/schedule.hpp"

namespace relief_snake {

const char* to_string(HoleMode mode) { return mode == HoleMode::Off ? "off" : "auto"; }

namespace {

using Clock = std::chrono::steady_clock;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Region vertices with a neighbour outside the region: where the outer contour cut the mesh.
std::vector<char> region_border(const Mesh& mesh, const std::vector<char>& region) {
  std::vector<char> border(mesh.n_vertices(), 0);
  for (int v = 0; v < mesh.n_vertices(); ++v) {
    if (!region[v]) continue;
    if (mesh.is_boundary_vertex(v)) border[v] = 1;
    for (const int* w = mesh.neighbors_begin(v); w != mesh.neighbors_end(v) && !border[v]; ++w)
      if (!region[*w]) border[v] = 1;
  }
  return border;
}

// The screen's heights: region vertices above a quadric height field fitted (least squares) to
// the background ring over the ring's best-fit plane. Returns false when the ring is too small.
bool quadric_heights(const Mesh& mesh, const std::vector<char>& region, const std::vector<int>& ring,
                     std::vector<double>* height, double* rms) {
  if (ring.size() < 12) return false;
  Vec3 centroid = Vec3::Zero(), normal_sum = Vec3::Zero();
  for (const int v : ring) centroid += mesh.position(v), normal_sum += mesh.vertex_normal(v);
  centroid /= static_cast<double>(ring.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const int v : ring) {
    const Vec3 d = mesh.position(v) - centroid;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Vec3 n = eig.eigenvectors().col(0);
  if (n.dot(normal_sum) < 0) n = -n;
  const Vec3 ex = eig.eigenvectors().col(2), ey = n.cross(ex);
  auto local = [&](int v) {
    const Vec3 d = mesh.position(v) - centroid;
    return Vec3(d.dot(ex), d.dot(ey), d.dot(n));
  };
  Eigen::MatrixXd A(ring.size(), 6);
  Eigen::VectorXd b(ring.size());
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const Vec3 p = local(ring[k]);
    A.row(k) << 1, p.x(), p.y(), p.x() * p.x(), p.x() * p.y(), p.y() * p.y();
    b[k] = p.z();
  }
  const Eigen::VectorXd c = A.colPivHouseholderQr().solve(b);
  *rms = std::sqrt((A * c - b).squaredNorm() / static_cast<double>(ring.size()));
  height->assign(mesh.n_vertices(), 0.0);
  for (int v = 0; v < mesh.n_vertices(); ++v) {
    if (!region[v]) continue;
    const Vec3 p = local(v);
    (*height)[v] = p.z() - (c[0] + c[1] * p.x() + c[2] * p.y() + c[3] * p.x() * p.x() + c[4] * p.x() * p.y() +
                            c[5] * p.y() * p.y());
  }
  return true;
}

double area_of(const Mesh& mesh, const std::vector<int>& vertices) {
  double a = 0;
  for (const int v : vertices) a += mesh.vertex_area(v);
  return a;
}

double median_height(const std::vector<int>& set, const std::vector<double>& height) {
  std::vector<double> x;
  x.reserve(set.size());
  for (const int v : set) x.push_back(height[v]);
  if (x.empty()) return 0;
  std::nth_element(x.begin(), x.begin() + static_cast<long>(x.size() / 2), x.end());
  return x[x.size() / 2];
}

// Low sets of the region (height < level) that do not reach the outer contour.
std::vector<std::vector<int>> low_sets(const Mesh& mesh, const std::vector<char>& region,
                                       const std::vector<char>& border, const std::vector<double>& height,
                                       double level) {
  std::vector<char> low(mesh.n_vertices(), 0);
  for (int v = 0; v < mesh.n_vertices(); ++v) low[v] = region[v] && height[v] < level;
  std::vector<std::vector<int>> out;
  for (std::vector<int>& comp : vertex_components(mesh, low)) {
    bool touches = false;
    for (const int v : comp) touches = touches || border[v];
    if (!touches) out.push_back(std::move(comp));
  }
  return out;
}


double quantile(std::vector<double> x, double q) {
  if (x.empty()) return 0;
  const std::size_t k = std::min(x.size() - 1, static_cast<std::size_t>(q * static_cast<double>(x.size())));
  std::nth_element(x.begin(), x.begin() + static_cast<long>(k), x.end());
  return x[k];
}

// The start of an island's snake: its outline, eroded by up to an h so the snake starts on the
// floor, not on the wall (the coarse phase must approach the step from the background).
std::vector<SurfacePoint> island_start(const Mesh& mesh, const std::vector<int>& island, double h) {
  std::vector<char> in(mesh.n_vertices(), 0);
  for (const int v : island) in[v] = 1;
  std::vector<int> edge;
  for (const int v : island) {
    bool e = false;
    for (const int* w = mesh.neighbors_begin(v); w != mesh.neighbors_end(v) && !e; ++w) e = !in[*w];
    if (e) edge.push_back(v);
  }
  const std::vector<double> d = edge_distances(mesh, edge, kInf, [&](int w) { return in[w] != 0; });
  for (const double erosion : {1.0, 0.5, 0.0}) {
    std::vector<char> kept(mesh.n_vertices(), 0);
    for (const int v : island) kept[v] = d[v] >= erosion * h;
    std::vector<std::vector<int>> parts = vertex_components(mesh, kept);
    if (parts.empty()) continue;
    const auto largest = std::max_element(parts.begin(), parts.end(),
                                          [](const auto& a, const auto& b) { return a.size() < b.size(); });
    std::vector<char> part(mesh.n_vertices(), 0);
    for (const int v : *largest) part[v] = 1;
    std::vector<SurfacePoint> outline = vertex_set_outline(mesh, part);
    if (path_length(mesh, outline, true) >= 4 * h) return outline;
  }
  return {};
}

struct HoleRun {
  HoleOutcome outcome;
  bool usable = false;
  bool cancelled = false;
};

// One hole's snake from its start (relief outside), W_int as the outer contour's: the given one,
// or 0.25, 0.5, 1 until the verdict holds.
HoleRun run_hole(const Mesh& mesh, PlanarityField& planarity, const Options& options, double h,
                 const std::vector<SurfacePoint>& path, const std::vector<char>& outer_region,
                 const ProgressCallback& progress) {
  HoleRun best;
  const std::vector<SurfacePoint> start = resample_path(mesh, path, h, true);
  if (start.size() < 4) return best;
  // The relief is outside the hole: on the right of a counter-clockwise outline.
  const bool relief_left = !contour_orientation_left(mesh, start);
  Options hole_options = options;
  hole_options.closed = true;
  hole_options.foot_snap = false;
  EvolutionSchedule schedule(mesh, planarity, hole_options, h, start, relief_left);
  const ScheduleRun& coarse = schedule.coarse(progress);
  if (coarse.cancelled) {
    best.cancelled = true;
    return best;
  }
  if (coarse.collapsed || coarse.contour.size() < 4) return best;
  const std::vector<char> coarse_interior = relief_region(mesh, coarse.contour, true, !relief_left);
  std::vector<char> coarse_side(coarse_interior.size());
  for (std::size_t v = 0; v < coarse_side.size(); ++v) coarse_side[v] = !coarse_interior[v];
  const double coarse_share = measure_step(mesh, coarse.contour, coarse_side, h).step_share;
  const double outer_area = region_area(mesh, outer_region);
  const std::vector<double> w_steps =
      options.w_int > 0 ? std::vector<double>{options.w_int} : std::vector<double>{0.25, 0.5, 1.0};
  SelfCheckOptions self_check;
  int attempts = 0;
  for (const double w : w_steps) {
    ScheduleRun run = schedule.refine(w, progress);
    ++attempts;
    if (run.cancelled) {
      best.cancelled = true;
      return best;
    }
    if (run.collapsed || run.contour.size() < 4) continue;
    HoleRun a;
    a.usable = true;
    HoleOutcome& o = a.outcome;
    o.contour = run.contour;
    o.interior = relief_region(mesh, run.contour, true, !relief_left);
    std::vector<char> side(o.interior.size());
    for (std::size_t v = 0; v < side.size(); ++v) side[v] = !o.interior[v];
    o.evidence.step = measure_step(mesh, run.contour, side, h);
    o.evidence.coarse_step_share = coarse_share;
    o.evidence.coarse_iou = region_iou(mesh, coarse_interior, o.interior);
    o.check = judge(o.evidence, h, self_check);
    o.area = region_area(mesh, o.interior);
    // A hole lies inside the relief: one that took in the background around it leaked.
    double inside = 0;
    for (int v = 0; v < mesh.n_vertices(); ++v)
      if (o.interior[v] && outer_region[v]) inside += mesh.vertex_area(v);
    if (!(o.area > 0) || inside < 0.9 * o.area || o.area > 0.8 * outer_area) {
      o.check.holds = false;
      o.check.score -= 10;
      o.leaked = true;
      o.check.reasons.push_back("its contour leaves the relief (it encloses " + fmt(o.area, 3) +
                                " of area, " + fmt(outer_area > 0 ? o.area / outer_area : 0, 3) +
                                " of the region), so it was not cut out");
    }
    o.attempts = attempts;
    const bool holds = o.check.holds;
    if (!best.usable || (holds && !best.outcome.check.holds) ||
        (holds == best.outcome.check.holds && o.check.score > best.outcome.check.score))
      best = std::move(a);
    best.outcome.attempts = attempts;
    if (holds) break;
  }
  return best;
}

}  // namespace

std::vector<SurfacePoint> vertex_set_outline(const Mesh& mesh, const std::vector<char>& set) {
  // Directed edges of the set's faces (counter-clockwise); an edge whose twin is absent is on the outline.
  std::unordered_map<std::uint64_t, int> edge_face;  // (a, b) -> face
  auto key = [](int a, int b) { return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b); };
  for (int f = 0; f < mesh.n_faces(); ++f) {
    const int a = mesh.face_vertex(f, 0), b = mesh.face_vertex(f, 1), c = mesh.face_vertex(f, 2);
    if (!set[a] || !set[b] || !set[c]) continue;
    edge_face[key(a, b)] = f, edge_face[key(b, c)] = f, edge_face[key(c, a)] = f;
  }
  std::unordered_map<int, std::pair<int, int>> next;  // a -> (b, face) along the outline
  for (const auto& [k, f] : edge_face) {
    const int a = static_cast<int>(k >> 32), b = static_cast<int>(k & 0xffffffffu);
    if (!edge_face.count(key(b, a))) next[a] = {b, f};
  }
  std::vector<SurfacePoint> best;
  double best_length = -1;
  std::unordered_set<int> used;
  for (const auto& [a0, unused] : next) {
    (void)unused;
    if (used.count(a0)) continue;
    std::vector<SurfacePoint> loop;
    int a = a0;
    bool closed = false;
    for (std::size_t guard = 0; guard <= next.size(); ++guard) {
      if (used.count(a)) {
        closed = a == a0;
        break;
      }
      used.insert(a);
      const auto it = next.find(a);
      if (it == next.end()) break;
      const int f = it->second.second;
      SurfacePoint p;
      p.face = f;
      p.bary = Vec3::Zero();
      for (int c = 0; c < 3; ++c)
        if (mesh.face_vertex(f, c) == a) p.bary[c] = 1;
      loop.push_back(p);
      a = it->second.first;
    }
    if (!closed || loop.size() < 3) continue;
    const double length = path_length(mesh, loop, true);
    if (length > best_length) best_length = length, best = std::move(loop);
  }
  return best;
}

void validate_hole_picks(const Mesh& mesh, const Options& options, int component) {
  for (std::size_t k = 0; k < options.hole_picks.size(); ++k) {
    const std::vector<std::int64_t>& picks = options.hole_picks[k];
    const std::string which = "hole " + std::to_string(k + 1) + "'s picks";
    if (!options.closed) throw Error("holes need a closed contour; drop the hole picks or the open option");
    if (picks.size() < 3)
      throw Error(which + " need at least 3 vertices on the hole's floor around it (got " +
                  std::to_string(picks.size()) + ")");
    std::unordered_set<std::int64_t> seen;
    for (const std::int64_t p : picks) {
      if (p < 0 || static_cast<std::size_t>(p) >= mesh.input_vertex_count())
        throw Error(which + ": " + std::to_string(p) + " is not a vertex index (the mesh has " +
                    std::to_string(mesh.input_vertex_count()) + " vertices)");
      const int v = mesh.input_to_mesh(static_cast<std::size_t>(p));
      if (v < 0) throw Error(which + ": vertex " + std::to_string(p) + " belongs to no face; pick another vertex");
      if (mesh.component(v) != component)
        throw Error(which + ": vertex " + std::to_string(p) + " is not on the relief's part of the mesh");
      if (!seen.insert(p).second) throw Error(which + ": vertex " + std::to_string(p) + " is repeated");
    }
  }
}

HoleSearch segment_holes(const Mesh& mesh, PlanarityField& planarity, const Options& options, double h,
                         std::vector<char>* region_flags, const ProgressCallback& progress,
                         const HoleSearchOptions& search_options) {
  const auto t0 = Clock::now();
  HoleSearch search;
  std::vector<char>& region = *region_flags;
  const std::vector<char> outer_region = region;
  HoleSearchOptions so = search_options;
  so.min_area = options.min_hole_area;

  // Starts: from the hole picks, or from the islands found.
  struct Start {
    std::vector<SurfacePoint> path;
    bool from_picks = false;
    double island_area = 0;
  };
  std::vector<Start> starts;
  if (!options.hole_picks.empty()) {
    for (const std::vector<std::int64_t>& picks : options.hole_picks) {
      std::vector<int> vertices;
      for (const std::int64_t p : picks) vertices.push_back(mesh.input_to_mesh(static_cast<std::size_t>(p)));
      starts.push_back({initial_contour(mesh, vertices, true).path, true, 0});
    }
  } else if (options.holes == HoleMode::Auto) {
    const std::vector<char> border = region_border(mesh, region);
    std::vector<int> seeds;
    for (int v = 0; v < mesh.n_vertices(); ++v)
      if (border[v]) seeds.push_back(v);
    const std::vector<double> ring_d =
        edge_distances(mesh, seeds, so.ring_width * h, [&](int w) { return !region[w]; });
    std::vector<int> ring;
    for (int v = 0; v < mesh.n_vertices(); ++v)
      if (!region[v] && ring_d[v] < kInf) ring.push_back(v);
    std::vector<double> height;
    double rms = 0;
    if (!quadric_heights(mesh, region, ring, &height, &rms)) {
      search.notes.push_back("holes not searched: too little background around the relief");
    } else {
      std::vector<std::vector<int>> screened = low_sets(mesh, region, border, height, so.screen_level * h);
      // Too small to be holes; the note counts those of at least 1 h^2 (not single low vertices).
      screened.erase(std::remove_if(screened.begin(), screened.end(),
                                    [&](const std::vector<int>& s) {
                                      const double a = area_of(mesh, s);
                                      if (a < so.min_area * h * h && a >= h * h) ++search.ignored_small;
                                      return a < so.min_area * h * h || median_height(s, height) > so.screen_median * h;
                                    }),
                     screened.end());
      search.screened = static_cast<int>(screened.size());
      if (!screened.empty()) {
        // The precise background: the extraction's thin-plate fill from the ring.
        const BackgroundSolver solver(mesh);
        const BackgroundResult background = solver.solve(region, h);
        if (background.ok()) height = background.height;
        std::vector<std::vector<int>> islands = low_sets(mesh, region, border, height, so.low_level * h);
        std::sort(islands.begin(), islands.end(),
                  [&](const auto& a, const auto& b) { return area_of(mesh, a) > area_of(mesh, b); });
        for (const std::vector<int>& island : islands) {
          const double area = area_of(mesh, island);
          if (area < so.min_area * h * h) continue;  // (counted by the screen)
          if (median_height(island, height) > so.island_median * h) {
            ++search.ignored_no_rim;  // not down at the background: a dip in the relief
            continue;
          }
          // A hole is surrounded by relief: the rim around it stands clearly above the background.
          std::vector<char> in(mesh.n_vertices(), 0);
          for (const int v : island) in[v] = 1;
          const std::vector<double> rim_d =
              edge_distances(mesh, island, so.rim_width * h, [&](int w) { return region[w] != 0; });
          std::vector<double> rim;
          for (int v = 0; v < mesh.n_vertices(); ++v)
            if (!in[v] && rim_d[v] < kInf) rim.push_back(height[v]);
          if (rim.empty() || quantile(rim, 0.75) < so.rim_level * h) {
            ++search.ignored_no_rim;
            continue;
          }
          if (static_cast<int>(starts.size()) >= so.max_holes) break;
          std::vector<SurfacePoint> path = island_start(mesh, island, h);
          if (path.empty()) {
            ++search.ignored_small;
            continue;
          }
          starts.push_back({std::move(path), false, area});
        }
      }
    }
  }

  for (std::size_t k = 0; k < starts.size(); ++k) {
    HoleRun run = run_hole(mesh, planarity, options, h, starts[k].path, outer_region, progress);
    if (run.cancelled) {
      search.cancelled = true;
      return search;
    }
    if (!run.usable) {
      // A snake that collapsed leaves no contour; say so rather than drop the hole silently.
      HoleOutcome failed;
      failed.from_picks = starts[k].from_picks;
      failed.island_area = starts[k].island_area;
      failed.check.holds = false;
      failed.check.reasons.push_back("its snake collapsed before it met a step (" +
                                     std::string(starts[k].from_picks ? "check the hole picks or h" :
                                                 "an island of area " + fmt(starts[k].island_area, 3) +
                                                     " stays in the relief") + ")");
      search.holes.push_back(std::move(failed));
      continue;
    }
    run.outcome.from_picks = starts[k].from_picks;
    run.outcome.island_area = starts[k].island_area;
    if (!run.outcome.leaked)  // cutting a leaked hole would take the relief (or all of it) with it
      for (int v = 0; v < mesh.n_vertices(); ++v)
        if (run.outcome.interior[v]) region[v] = 0;
    search.holes.push_back(std::move(run.outcome));
  }
  if (search.ignored_small > 0)
    search.notes.push_back(std::to_string(search.ignored_small) +
                           " low area(s) inside the relief (over 1 h^2) were below the minimum hole area (" +
                           fmt(so.min_area, 3) + " h^2) and were not taken as holes");
  if (search.ignored_no_rim > 0)
    search.notes.push_back(std::to_string(search.ignored_no_rim) +
                           " low area(s) inside the relief were not taken as holes (not down at the background, or no relief round them)");
  search.seconds = seconds_since(t0);
  return search;
}

void add_holes(const Mesh& mesh, const HoleSearch& search, Result* result, SelfCheck* check) {
  int found = 0;
  for (std::size_t k = 0; k < search.holes.size(); ++k) {
    const HoleOutcome& hole = search.holes[k];
    const std::string name = "hole " + std::to_string(k + 1);
    if (!hole.check.holds) {
      check->holds = false;
      for (const std::string& reason : hole.check.reasons) check->reasons.push_back(name + ": " + reason);
    }
    if (hole.contour.empty() || hole.leaked) continue;  // not cut out: no hole in the result
    ++found;
    std::vector<Vec3> polyline;
    for (const SurfacePoint& p : hole.contour) polyline.push_back(mesh.to_file(position(mesh, p)));
    result->holes.push_back(hole.contour);
    result->hole_polylines.push_back(std::move(polyline));
    const StepEvidence& step = hole.evidence.step;
    result->hole_checks.push_back({{"holds", hole.check.holds ? 1.0 : 0.0},
                                   {"from_picks", hole.from_picks ? 1.0 : 0.0},
                                   {"step_share", step.step_share},
                                   {"step_height", step.step_height},
                                   {"foot_share", step.foot_share},
                                   {"measured_share", step.measured_share()},
                                   {"coarse_iou", hole.evidence.coarse_iou},
                                   {"area", hole.area},
                                   {"island_area", hole.island_area},
                                   {"attempts", static_cast<double>(hole.attempts)}});
  }
  for (const std::string& note : search.notes) result->notes.push_back(note);
  if (found > 0)
    result->notes.push_back(std::to_string(found) + " inner hole(s) segmented and left out of the relief");
  result->checks.push_back({"holes", static_cast<double>(found)});
  result->checks.push_back({"hole_seconds", search.seconds});
}

}  // namespace relief_snake

#include "report_text.hpp"
#include "relief_snake/background.hpp"
#include "relief_snake/plane_fit.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "sparse_spd.hpp"

namespace relief_snake {

const char* to_string(BackgroundStatus status) {
  switch (status) {
    case BackgroundStatus::Ok: return "ok";
    case BackgroundStatus::EmptyRegion: return "empty_region";
    case BackgroundStatus::NoRing: return "no_ring";
    case BackgroundStatus::SizeMismatch: return "size_mismatch";
    case BackgroundStatus::BadParameter: return "bad_parameter";
  }
  return "unknown";
}

namespace {

BackgroundResult failure(BackgroundStatus status, std::string message) {
  BackgroundResult r;
  r.status = status;
  r.message = std::move(message);
  return r;
}

/// Cotangent of the angle at c in triangle (a, b, c), clamped so near-degenerate
/// triangles cannot dominate the system.
double cotangent(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 u = a - c, w = b - c;
  const double s = u.cross(w).norm();
  const double d = u.dot(w);
  constexpr double kMax = 1e3;
  if (s <= std::abs(d) / kMax) return d >= 0 ? kMax : -kMax;
  return d / s;
}

/// The ring's best-fit plane and a quadric w = P(s, t) fitted to the ring over it.
using Vec2d = Eigen::Vector2d;

struct HeightFieldFrame {
  Vec3 origin = Vec3::Zero(), e1 = Vec3::UnitX(), e2 = Vec3::UnitY(), n = Vec3::UnitZ();
  double scale = 1;  // coordinates divided by it in the quadric (conditioning)
  Eigen::Matrix<double, 6, 1> coefficients = Eigen::Matrix<double, 6, 1>::Zero();

  static Eigen::Matrix<double, 6, 1> monomials(double s, double t) {
    Eigen::Matrix<double, 6, 1> m;
    m << 1, s, t, s * s, s * t, t * t;
    return m;
  }
  double quadric(double s, double t) const { return coefficients.dot(monomials(s / scale, t / scale)); }
  /// (s, t, 0) in the frame (for the planar Laplacian).
  Vec3 plane_point(const Vec3& x) const {
    const Vec3 d = x - origin;
    return Vec3(d.dot(e1), d.dot(e2), 0);
  }
  /// Height of x above the quadric along n.
  double offset(const Vec3& x) const {
    const Vec3 d = x - origin;
    return d.dot(n) - quadric(d.dot(e1), d.dot(e2));
  }
  /// The point over plane coordinates (s, t) at `offset` above the quadric.
  Vec3 point(const Vec2d& st, double offset_value) const {
    return origin + st.x() * e1 + st.y() * e2 + (quadric(st.x(), st.y()) + offset_value) * n;
  }
  /// Plane coordinates of the quadric's point nearest x (the foot of x along the quadric's
  /// normal), so a relief vertex keeps its place over the base even where the plane tilts
  /// away from the surface. A few fixed-point steps: the quadric is gentle at this scale.
  Vec2d foot(const Vec3& x) const {
    const Vec3 d0 = x - origin;
    Vec2d st(d0.dot(e1), d0.dot(e2));
    for (int it = 0; it < 4; ++it) {
      const double s = st.x() / scale, t = st.y() / scale;
      const double ps = (coefficients[1] + 2 * coefficients[3] * s + coefficients[4] * t) / scale;
      const double pt = (coefficients[2] + coefficients[4] * s + 2 * coefficients[5] * t) / scale;
      const Vec3 normal = (n - ps * e1 - pt * e2).normalized();
      const Vec3 d = x - point(st, 0);
      const Vec3 tangential = d - d.dot(normal) * normal;
      st += Vec2d(tangential.dot(e1), tangential.dot(e2));
    }
    return st;
  }
};

/// Fits the frame to the ring; false if the surface around the region folds over the plane
/// (a projected face turns over), so it is no height field there.
bool make_height_field(const Mesh& mesh, const std::vector<char>& region, const std::vector<int>& ring,
                       const std::vector<int>& rows, HeightFieldFrame* frame) {
  // The plane: unit weights (the ring is one band of vertices, sampled like the scan).
  const VertexPlaneFit plane = fit_vertex_plane(mesh, ring, false);
  if (plane.weight <= 0) return false;  // no ring: no frame to fit
  const Vec3 centroid = plane.centroid, n = plane.normal;
  frame->origin = centroid;
  frame->n = n;
  frame->e1 = plane.axes.col(2);
  frame->e1 = (frame->e1 - frame->e1.dot(n) * n).normalized();
  frame->e2 = n.cross(frame->e1);
  frame->scale = std::sqrt(std::max(plane.eigenvalues(2) / static_cast<double>(ring.size()), 1e-30));
  // Every face around the rows must keep its orientation in the plane.
  std::vector<char> seen(static_cast<std::size_t>(mesh.n_faces()), 0);
  for (const int v : rows)
    for (const int* f = mesh.faces_begin(v); f != mesh.faces_end(v); ++f) {
      if (seen[*f]) continue;
      seen[*f] = 1;
      // The relief's own faces may fold (steep walls lean over in the projection); the background must not.
      if (region[mesh.face_vertex(*f, 0)] || region[mesh.face_vertex(*f, 1)] || region[mesh.face_vertex(*f, 2)]) continue;
      const Vec3 a = frame->plane_point(mesh.position(mesh.face_vertex(*f, 0)));
      const Vec3 b = frame->plane_point(mesh.position(mesh.face_vertex(*f, 1)));
      const Vec3 c = frame->plane_point(mesh.position(mesh.face_vertex(*f, 2)));
      if ((b - a).cross(c - a).z() <= 0) return false;
    }
  // Least-squares quadric through the ring.
  Eigen::Matrix<double, 6, 6> normal_matrix = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> right = Eigen::Matrix<double, 6, 1>::Zero();
  for (const int v : ring) {
    const Vec3 d = mesh.position(v) - centroid;
    const Eigen::Matrix<double, 6, 1> m = HeightFieldFrame::monomials(d.dot(frame->e1) / frame->scale, d.dot(frame->e2) / frame->scale);
    normal_matrix += m * m.transpose();
    right += m * d.dot(n);
  }
  frame->coefficients = normal_matrix.ldlt().solve(right);
  if (!frame->coefficients.allFinite()) frame->coefficients.setZero();
  return true;
}

}  // namespace

BackgroundSolver::BackgroundSolver(const Mesh& mesh, const BackgroundOptions& options)
    : mesh_(mesh), options_(options) {
  // Only the one-ring offsets: each solve() computes the Laplacian weights of the faces its rows
  // touch (a relief's few percent of the mesh), not the whole mesh's up front.
  const int nv = mesh.n_vertices();
  ring_offset_.resize(static_cast<std::size_t>(nv) + 1, 0);
  for (int v = 0; v < nv; ++v)
    ring_offset_[v + 1] = ring_offset_[v] + static_cast<std::size_t>(mesh.neighbors_end(v) - mesh.neighbors_begin(v));
}

BackgroundResult BackgroundSolver::solve_vertices(const std::vector<int>& region_vertices, double h) const {
  std::vector<char> region(static_cast<std::size_t>(mesh_.n_vertices()), 0);
  for (const int v : region_vertices) {
    if (v < 0 || v >= mesh_.n_vertices())
      return failure(BackgroundStatus::SizeMismatch,
                     "region vertex " + std::to_string(v) + " is out of range: the mesh has " +
                         std::to_string(mesh_.n_vertices()) + " vertices; give a region of this mesh");
    region[v] = 1;
  }
  return solve(region, h);
}

BackgroundResult BackgroundSolver::solve(const std::vector<char>& region_in, double h) const {
  const auto start = std::chrono::steady_clock::now();
  const Mesh& mesh = mesh_;
  const int nv = mesh.n_vertices();
  if (region_in.size() != static_cast<std::size_t>(nv))
    return failure(BackgroundStatus::SizeMismatch, "the region has " + std::to_string(region_in.size()) +
                                                       " vertex flags but the mesh has " + std::to_string(nv) +
                                                       " vertices; give a region of this mesh");
  if (!(h > 0) || !std::isfinite(h))
    return failure(BackgroundStatus::BadParameter, "the step height h must be a positive number");
  if (!(options_.ring_width > 0) || !(options_.smoothing >= 0) || !(options_.smoothing_band >= 0))
    return failure(BackgroundStatus::BadParameter,
                   "ring_width must be > 0, smoothing and smoothing_band >= 0 (in units of h)");

  BackgroundResult r;
  r.region.assign(region_in.begin(), region_in.end());
  for (char& c : r.region) c = c ? 1 : 0;
  for (int v = 0; v < nv; ++v)
    if (r.region[v]) r.region_vertices.push_back(v);
  if (r.region_vertices.empty())
    return failure(BackgroundStatus::EmptyRegion, "the relief region is empty; segment the relief first");

  // A component covered entirely by the region has no background to continue.
  {
    std::vector<char> has_region, has_outside;
    for (int v = 0; v < nv; ++v) {
      const std::size_t c = static_cast<std::size_t>(mesh.component(v));
      if (c >= has_region.size()) {
        has_region.resize(c + 1, 0);
        has_outside.resize(c + 1, 0);
      }
      (r.region[v] ? has_region : has_outside)[c] = 1;
    }
    for (std::size_t c = 0; c < has_region.size(); ++c)
      if (has_region[c] && !has_outside[c])
        return failure(BackgroundStatus::NoRing,
                       "the relief region covers a whole connected part of the mesh (component " + std::to_string(c) +
                           "): there is no background around it to continue under the relief; segment a smaller region");
  }

  // --- the ring: background vertices within ring_width * h of the region (along edges),
  // and at least the two edge rings the Laplacian rows reach.
  const double width = options_.ring_width * h;
  std::vector<double> dist(static_cast<std::size_t>(nv), std::numeric_limits<double>::infinity());
  std::vector<int> hops(static_cast<std::size_t>(nv), std::numeric_limits<int>::max());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  // Seeds: the background vertices next to the region (distances through the relief's step
  // would count its height).
  for (const int v : r.region_vertices)
    for (const int* it = mesh.neighbors_begin(v); it != mesh.neighbors_end(v); ++it)
      if (!r.region[*it] && hops[*it] != 1) {
        dist[*it] = 0;
        hops[*it] = 1;
        queue.push({0.0, *it});
      }
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    for (const int* it = mesh.neighbors_begin(v); it != mesh.neighbors_end(v); ++it) {
      const int w = *it;
      if (r.region[w]) continue;
      const double dw = d + (mesh.position(v) - mesh.position(w)).norm();
      hops[w] = std::min(hops[w], hops[v] + 1);
      if (dw < dist[w] && (dw <= width || hops[w] <= 2)) {
        dist[w] = dw;
        queue.push({dw, w});
      }
    }
  }
  std::vector<char> in_ring(static_cast<std::size_t>(nv), 0);
  for (int v = 0; v < nv; ++v)
    if (!r.region[v] && std::isfinite(dist[v])) {
      in_ring[v] = 1;
      r.ring_vertices.push_back(v);
    }
  if (r.ring_vertices.empty())
    return failure(BackgroundStatus::NoRing, "no background around the relief region; segment a smaller region");

  r.timings.ring = seconds_since(start);
  const auto assembly_start = std::chrono::steady_clock::now();

  // --- unknowns, rows (vertices whose Laplacian involves an unknown), fixed columns.
  const bool soft = options_.smoothing > 0;
  std::vector<int> unknown_id(static_cast<std::size_t>(nv), -1), fixed_id(static_cast<std::size_t>(nv), -1);
  std::vector<int> unknowns;
  for (int v = 0; v < nv; ++v)
    if (r.region[v] || (soft && in_ring[v] && dist[v] <= options_.smoothing_band * h)) {
      unknown_id[v] = static_cast<int>(unknowns.size());
      unknowns.push_back(v);
    }
  std::vector<char> is_row(static_cast<std::size_t>(nv), 0);
  std::vector<int> rows;
  auto add_row = [&](int v) {
    // Boundary vertices get rows too (their one-sided Laplacian): without them the values along a
    // mesh border the region reaches would be underdetermined.
    if (!is_row[v]) {
      is_row[v] = 1;
      rows.push_back(v);
    }
  };
  for (const int v : unknowns) {
    add_row(v);
    for (const int* it = mesh.neighbors_begin(v); it != mesh.neighbors_end(v); ++it) add_row(*it);
  }
  std::vector<int> fixed;
  auto touch_fixed = [&](int v) {
    if (unknown_id[v] < 0 && fixed_id[v] < 0) {
      fixed_id[v] = static_cast<int>(fixed.size());
      fixed.push_back(v);
    }
  };
  for (const int v : rows) {
    touch_fixed(v);
    for (const int* it = mesh.neighbors_begin(v); it != mesh.neighbors_end(v); ++it) touch_fixed(*it);
  }

  // --- the model: a height field over the ring's best-fit plane (a quadric fitted to the ring
  // plus a thin-plate fill of the ring's offsets from it), or the vertex positions themselves.
  HeightFieldFrame frame;
  bool height_field = options_.model != BackgroundModel::Surface &&
                      make_height_field(mesh, r.region, r.ring_vertices, rows, &frame);
  if (!height_field && options_.model == BackgroundModel::HeightField)
    return failure(BackgroundStatus::BadParameter,
                   "the background folds over its best-fit plane, so it is no height field; use the surface model");
  r.model = height_field ? BackgroundModel::HeightField : BackgroundModel::Surface;

  // Plane coordinates of each vertex involved: the foot along the quadric's normal for region
  // vertices (lifted by the relief), the plain projection for the background's.
  std::vector<Vec2d> footprint;
  if (height_field) {
    footprint.resize(static_cast<std::size_t>(nv));
    auto set_footprint = [&](int v) {
      if (r.region[v]) {
        footprint[v] = frame.foot(mesh.position(v));
      } else {
        const Vec3 q = frame.plane_point(mesh.position(v));
        footprint[v] = Vec2d(q.x(), q.y());
      }
    };
    for (const int v : unknowns) set_footprint(v);
    for (const int v : fixed) set_footprint(v);
  }

  // Laplacian weights per one-ring entry (aligned with Mesh::neighbors_begin(v)) and areas, from
  // the faces around the rows: the scan's own triangles (Surface) or their plane projection
  // (HeightField: a planar parameterisation, so linear offsets fill exactly).
  const bool uniform = options_.laplacian == BackgroundLaplacian::Uniform;
  std::vector<double> weights(ring_offset_[nv], uniform ? 1.0 : 0.0);
  std::vector<double> area(static_cast<std::size_t>(nv), 0.0);
  {
    std::vector<char> face_done(static_cast<std::size_t>(mesh.n_faces()), 0);
    // Entry of b in a's one-ring (degrees are small: a linear search).
    auto slot = [&](int a, int b) -> double& {
      const int* begin = mesh.neighbors_begin(a);
      const int* it = std::find(begin, mesh.neighbors_end(a), b);
      return weights[ring_offset_[a] + static_cast<std::size_t>(it - begin)];
    };
    for (const int v : rows)
      for (const int* f = mesh.faces_begin(v); f != mesh.faces_end(v); ++f) {
        if (face_done[*f]) continue;
        face_done[*f] = 1;
        const int c[3] = {mesh.face_vertex(*f, 0), mesh.face_vertex(*f, 1), mesh.face_vertex(*f, 2)};
        Vec3 q[3];
        if (height_field) {
          for (int k = 0; k < 3; ++k) q[k] = Vec3(footprint[c[k]].x(), footprint[c[k]].y(), 0);
          const double signed_third = (q[1] - q[0]).cross(q[2] - q[0]).z() / 6.0;
          for (int k = 0; k < 3; ++k) area[c[k]] += std::abs(signed_third);
          // Folded faces (steep relief walls) get no cotangent weight: they are not part of the base.
          if (signed_third <= 0) continue;
        } else {
          for (int k = 0; k < 3; ++k) q[k] = mesh.position(c[k]);
        }
        if (uniform) continue;
        for (int k = 0; k < 3; ++k) {
          const int i = (k + 1) % 3, j = (k + 2) % 3;
          const double half_cot = 0.5 * cotangent(q[i], q[j], q[k]);
          slot(c[i], c[j]) += half_cot;
          slot(c[j], c[i]) += half_cot;
        }
      }
  }
  if (!height_field)
    for (const int v : rows) area[v] = mesh.vertex_area(v);
  const int dims = height_field ? 1 : 3;
  // Known values: the offset from the quadric (HeightField) or the position (Surface).
  auto value = [&](int v) -> Eigen::Vector3d {
    if (height_field) return Eigen::Vector3d(frame.offset(mesh.position(v)), 0, 0);  // background: over its projection
    return mesh.position(v);
  };

  // --- the normal equations Q X = rhs of the thin-plate energy sum_rows |W X + W_fixed X_fixed|^2 / A:
  // Q = WU^T diag(1/A) WU and rhs = -WU^T diag(1/A) (WF XF), WU and WF being the rows' Laplacian
  // weights on the unknowns and on the fixed vertices. Assembled from the rows directly (each row
  // holds a one-ring, so column u of Q gathers the rows through u) instead of through sparse
  // products of the weight matrices; the sums run in the same order as Eigen's products did
  // (rows ascending, fixed vertices ascending), so Q and rhs are the same numbers.
  const Eigen::Index nr = static_cast<Eigen::Index>(rows.size()), nu = static_cast<Eigen::Index>(unknowns.size()),
                     nf = static_cast<Eigen::Index>(fixed.size());
  Eigen::MatrixXd XF(nf, dims);
  for (Eigen::Index j = 0; j < nf; ++j) XF.row(j) = value(fixed[j]).head(dims).transpose();
  // Row r's entries on the unknowns (row_start[r] to row_start[r + 1]) and WF XF's row r.
  std::vector<int> row_start(rows.size() + 1, 0), entry_unknown;
  std::vector<double> entry_weight, inverse_area(rows.size());
  entry_unknown.reserve(rows.size() * 8);
  entry_weight.reserve(rows.size() * 8);
  Eigen::MatrixXd fixed_part = Eigen::MatrixXd::Zero(nr, dims);
  std::vector<std::pair<int, double>> fixed_entries;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const int v = rows[i];
    fixed_entries.clear();
    double diagonal = 0;
    auto add = [&](int w, double weight) {
      if (unknown_id[w] >= 0) {
        entry_unknown.push_back(unknown_id[w]);
        entry_weight.push_back(weight);
      } else {
        fixed_entries.emplace_back(fixed_id[w], weight);
      }
    };
    for (std::size_t k = ring_offset_[v]; k < ring_offset_[v + 1]; ++k) {
      diagonal -= weights[k];
      add(mesh.neighbors_begin(v)[k - ring_offset_[v]], weights[k]);
    }
    add(v, diagonal);
    row_start[i + 1] = static_cast<int>(entry_unknown.size());
    std::sort(fixed_entries.begin(), fixed_entries.end());
    for (const auto& [j, weight] : fixed_entries) fixed_part.row(static_cast<Eigen::Index>(i)) += weight * XF.row(j);
    inverse_area[i] = area[v] > 0 ? 1.0 / area[v] : 0.0;
  }
  // The rows through each unknown, ascending (WU's columns).
  std::vector<int> column_start(static_cast<std::size_t>(nu) + 1, 0);
  for (const int u : entry_unknown) ++column_start[static_cast<std::size_t>(u) + 1];
  for (Eigen::Index u = 0; u < nu; ++u) column_start[u + 1] += column_start[u];
  std::vector<int> column_row(entry_unknown.size()), fill(column_start.begin(), column_start.end() - 1);
  std::vector<double> column_weight(entry_unknown.size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (int e = row_start[i]; e < row_start[i + 1]; ++e) {
      const int at = fill[entry_unknown[e]]++;
      column_row[at] = static_cast<int>(i);
      column_weight[at] = entry_weight[e];
    }
  using SparseMatrix = Eigen::SparseMatrix<double>;
  SparseMatrix Q(nu, nu);
  Q.reserve(static_cast<Eigen::Index>(entry_unknown.size()) * 4);
  Eigen::MatrixXd rhs(nu, dims);
  {
    std::vector<char> seen(static_cast<std::size_t>(nu), 0);
    std::vector<double> sum(static_cast<std::size_t>(nu), 0.0);
    std::vector<int> pattern;
    for (Eigen::Index u = 0; u < nu; ++u) {
      pattern.clear();
      Eigen::RowVectorXd right = Eigen::RowVectorXd::Zero(dims);
      for (int c = column_start[u]; c < column_start[u + 1]; ++c) {
        const int row = column_row[c];
        const double x = inverse_area[row] * column_weight[c];  // (diag(1/A) WU)(row, u)
        right += x * fixed_part.row(row);
        for (int e = row_start[row]; e < row_start[row + 1]; ++e) {
          const int i = entry_unknown[e];
          if (!seen[i]) {
            seen[i] = 1;
            sum[i] = entry_weight[e] * x;
            pattern.push_back(i);
          } else {
            sum[i] += entry_weight[e] * x;
          }
        }
      }
      rhs.row(u) = -right;
      std::sort(pattern.begin(), pattern.end());
      Q.startVec(u);
      for (const int i : pattern) {
        Q.insertBack(i, u) = sum[i];
        seen[i] = 0;
      }
    }
    Q.finalize();
  }
  if (soft) {
    const double s = options_.smoothing * h;
    const double stiffness = 1.0 / (s * s * s * s);
    for (const int v : r.ring_vertices) {
      const int u = unknown_id[v];
      if (u < 0) continue;  // beyond the fitted band: fixed
      const double weight = stiffness * (area[v] > 0 ? area[v] : mesh.vertex_area(v));
      Q.coeffRef(u, u) += weight;
      rhs.row(u) += weight * value(v).head(dims).transpose();
    }
  }
  r.timings.assembly = seconds_since(assembly_start);
  Eigen::MatrixXd X;
  SpdTimings spd;
  const bool solved = solve_spd(Q, rhs, &X, &spd);
  r.timings.ordering = spd.ordering;
  r.timings.factorisation = spd.factorisation;
  r.timings.solve = spd.solve;
  if (!solved)
    return failure(BackgroundStatus::NoRing,
                   "the background fill is singular: the region has too little background around it; segment a smaller "
                   "region or use a larger ring");

  // --- base positions, normals and heights.
  const auto height_start = std::chrono::steady_clock::now();
  r.base_positions.resize(static_cast<std::size_t>(nv));
  for (int v = 0; v < nv; ++v) r.base_positions[v] = mesh.position(v);
  for (Eigen::Index u = 0; u < nu; ++u) {
    const int v = unknowns[u];
    r.base_positions[v] = height_field ? frame.point(footprint[v], X(u, 0)) : Vec3(X.row(u).transpose());
  }
  r.base_normals.resize(static_cast<std::size_t>(nv));
  for (int v = 0; v < nv; ++v) r.base_normals[v] = mesh.vertex_normal(v);
  // Vertices whose faces moved: the unknowns and their neighbours.
  std::vector<char> moved_normal(static_cast<std::size_t>(nv), 0);
  for (const int v : unknowns) {
    moved_normal[v] = 1;
    for (const int* it = mesh.neighbors_begin(v); it != mesh.neighbors_end(v); ++it) moved_normal[*it] = 1;
  }
  for (int v = 0; v < nv; ++v) {
    if (!moved_normal[v]) continue;
    Vec3 n = Vec3::Zero();
    for (const int* f = mesh.faces_begin(v); f != mesh.faces_end(v); ++f) {
      const Vec3& a = r.base_positions[mesh.face_vertex(*f, 0)];
      const Vec3& b = r.base_positions[mesh.face_vertex(*f, 1)];
      const Vec3& c = r.base_positions[mesh.face_vertex(*f, 2)];
      n += (b - a).cross(c - a);  // twice the area times the unit normal
    }
    const double length = n.norm();
    if (length > 0) r.base_normals[v] = n / length;
  }
  r.height.assign(static_cast<std::size_t>(nv), 0.0);
  for (int v = 0; v < nv; ++v)
    if (r.region[v] || in_ring[v]) r.height[v] = (mesh.position(v) - r.base_positions[v]).dot(r.base_normals[v]);
  // The residual over the fitted (soft) part of the ring; the rest is fixed, at height 0.
  double sum2 = 0;
  std::size_t fitted = 0;
  for (const int v : r.ring_vertices) {
    if (unknown_id[v] < 0) continue;
    ++fitted;
    sum2 += r.height[v] * r.height[v];
    r.ring_max_residual = std::max(r.ring_max_residual, std::abs(r.height[v]));
  }
  r.ring_rms_residual = fitted ? std::sqrt(sum2 / static_cast<double>(fitted)) : 0.0;
  r.timings.height = seconds_since(height_start);
  r.seconds = seconds_since(start);
  return r;
}

BackgroundResult fill_background(const Mesh& mesh, const std::vector<char>& region, double h,
                                 const BackgroundOptions& options) {
  BackgroundResult fill = BackgroundSolver(mesh, options).solve(region, h);
  if (fill.ok() || options.laplacian == BackgroundLaplacian::Uniform) return fill;
  BackgroundOptions uniform = options;
  uniform.laplacian = BackgroundLaplacian::Uniform;
  return BackgroundSolver(mesh, uniform).solve(region, h);
}

std::vector<double> height_above(const Mesh& mesh, const BackgroundResult& result,
                                 const std::vector<SurfacePoint>& points) {
  std::vector<double> heights(points.size(), 0.0);
  if (!result.ok() || result.base_positions.size() != static_cast<std::size_t>(mesh.n_vertices())) return heights;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const SurfacePoint& p = points[i];
    if (!p.valid() || p.face >= mesh.n_faces()) continue;
    Vec3 base = Vec3::Zero(), n = Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.face_vertex(p.face, k);
      base += p.bary[k] * result.base_positions[v];
      n += p.bary[k] * result.base_normals[v];
    }
    const double length = n.norm();
    if (length > 0) heights[i] = (position(mesh, p) - base).dot(n / length);
  }
  return heights;
}

}  // namespace relief_snake

#include "report_text.hpp"
#include "relief_snake/height_map.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <numeric>

#include <Eigen/Eigenvalues>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "relief_snake/error.hpp"
#include "sparse_spd.hpp"

namespace relief_snake {

const char* to_string(Flattening flattening) {
  switch (flattening) {
    case Flattening::Auto: return "auto";
    case Flattening::Plane: return "plane";
    case Flattening::Conformal: return "conformal";
  }
  return "?";
}

Flattening parse_flattening(const std::string& name) {
  if (name == "auto") return Flattening::Auto;
  if (name == "plane") return Flattening::Plane;
  if (name == "conformal") return Flattening::Conformal;
  throw Error("flattening must be 'auto', 'plane' or 'conformal', got '" + name + "'");
}

std::size_t HeightMap::covered_pixels() const {
  return static_cast<std::size_t>(std::count(mask.begin(), mask.end(), std::uint8_t(1)));
}

namespace {

void check_patch(const HeightPatch& patch) {
  if (patch.triangles.empty() || patch.positions.empty())
    throw Error("the relief region has no whole triangle to make a height map from; segment a larger region");
  if (patch.triangles.size() % 3 != 0) throw Error("patch triangles must come in threes");
  if (patch.heights.size() != patch.positions.size())
    throw Error("the patch has " + std::to_string(patch.heights.size()) + " heights for " +
                std::to_string(patch.positions.size()) + " vertices");
  for (const int i : patch.triangles)
    if (i < 0 || static_cast<std::size_t>(i) >= patch.positions.size())
      throw Error("patch triangle index " + std::to_string(i) + " is out of range");
}

/// Best-fit plane of the patch vertices: origin at the centroid, normal oriented with the
/// triangles' (area-weighted) normal, axis_u along the largest spread.
void fit_plane(const HeightPatch& patch, Flattened* out) {
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& p : patch.positions) centroid += p;
  centroid /= static_cast<double>(patch.positions.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Vec3& p : patch.positions) covariance += (p - centroid) * (p - centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  Vec3 normal = eigen.eigenvectors().col(0), axis_u = eigen.eigenvectors().col(2);
  Vec3 area_normal = Vec3::Zero();
  for (std::size_t t = 0; t < patch.triangles.size(); t += 3) {
    const Vec3 &a = patch.positions[patch.triangles[t]], &b = patch.positions[patch.triangles[t + 1]],
               &c = patch.positions[patch.triangles[t + 2]];
    area_normal += (b - a).cross(c - a);
  }
  // A patch that is nearly a line or closes around (tube): the area normal is the better normal.
  if (area_normal.norm() > 0 && normal.dot(area_normal) < 0) normal = -normal;
  axis_u = (axis_u - axis_u.dot(normal) * normal).normalized();
  out->origin = centroid;
  out->normal = normal;
  out->axis_u = axis_u;
  out->axis_v = normal.cross(axis_u);
}

Distortion measure_distortion(const HeightPatch& patch, const std::vector<Vec2>& uv) {
  Distortion d;
  double area3 = 0, area2 = 0;
  const std::size_t nt = patch.triangles.size() / 3;
  std::vector<double> s1(nt), s2(nt), a3(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const int i0 = patch.triangles[3 * t], i1 = patch.triangles[3 * t + 1], i2 = patch.triangles[3 * t + 2];
    const Vec3 e1 = patch.positions[i1] - patch.positions[i0], e2 = patch.positions[i2] - patch.positions[i0];
    const Vec3 n = e1.cross(e2);
    a3[t] = 0.5 * n.norm();
    area3 += a3[t];
    if (a3[t] <= 0) continue;
    // Local 2D frame of the triangle, then the Jacobian from it to uv.
    const Vec3 x = e1.normalized(), y = n.normalized().cross(x);
    Eigen::Matrix2d local, image;
    local << e1.dot(x), e2.dot(x), e1.dot(y), e2.dot(y);
    const Vec2 f1 = uv[i1] - uv[i0], f2 = uv[i2] - uv[i0];
    image << f1.x(), f2.x(), f1.y(), f2.y();
    const Eigen::Matrix2d J = image * local.inverse();
    const double det = J.determinant();
    area2 += 0.5 * std::abs(f1.x() * f2.y() - f1.y() * f2.x());
    if (det < 0) ++d.flipped_faces;
    const Eigen::JacobiSVD<Eigen::Matrix2d> svd(J);
    s1[t] = svd.singularValues()(0);
    s2[t] = svd.singularValues()(1);
  }
  const double scale = area3 > 0 ? area2 / area3 : 1;
  for (std::size_t t = 0; t < nt; ++t) {
    if (a3[t] <= 0) continue;
    const double angle = s2[t] > 0 ? s1[t] / s2[t] - 1 : std::numeric_limits<double>::infinity();
    const double area = scale > 0 ? std::abs(s1[t] * s2[t] / scale - 1) : 0;
    d.angle_mean += a3[t] * angle;
    d.area_mean += a3[t] * area;
    d.angle_max = std::max(d.angle_max, angle);
    d.area_max = std::max(d.area_max, area);
  }
  if (area3 > 0) {
    d.angle_mean /= area3;
    d.area_mean /= area3;
  }
  return d;
}

std::vector<Vec2> plane_uv(const HeightPatch& patch, const Flattened& frame) {
  std::vector<Vec2> uv(patch.positions.size());
  for (std::size_t i = 0; i < uv.size(); ++i) {
    const Vec3 d = patch.positions[i] - frame.origin;
    uv[i] = Vec2(d.dot(frame.axis_u), d.dot(frame.axis_v));
  }
  return uv;
}

/// Least-squares conformal map with two vertices of each connected part pinned at their plane
/// coordinates (the extremes along axis_u), then scaled about the plane centroid so the uv area
/// equals the 3D area. Returns false if the solve fails. timings gets the conformal stages'.
bool conformal_uv(const HeightPatch& patch, const std::vector<Vec2>& plane, std::vector<Vec2>* uv,
                  FlattenTimings* timings) {
  auto start = std::chrono::steady_clock::now();
  const int n = static_cast<int>(patch.positions.size());
  const std::size_t nt = patch.triangles.size() / 3;
  // Connected parts (union-find over triangles).
  std::vector<int> parent(static_cast<std::size_t>(n));
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 1; k < 3; ++k) parent[find(patch.triangles[3 * t + k])] = find(patch.triangles[3 * t]);
  std::vector<int> lo(static_cast<std::size_t>(n), -1), hi(static_cast<std::size_t>(n), -1);
  for (int i = 0; i < n; ++i) {
    const int r = find(i);
    if (lo[r] < 0 || plane[i].x() < plane[lo[r]].x()) lo[r] = i;
    if (hi[r] < 0 || plane[i].x() > plane[hi[r]].x()) hi[r] = i;
  }
  std::vector<char> pinned(static_cast<std::size_t>(n), 0);
  for (int i = 0; i < n; ++i)
    if (find(i) == i) pinned[lo[i]] = pinned[hi[i]] = 1;
  // Unknowns: z = u + i v of each free vertex. Per triangle the energy is |sum_j W_j z_j|^2 with
  // complex W_j (the real form's two rows, re and im, are one complex row), so the normal
  // equations are Hermitian with n unknowns instead of 2n real ones, for the same minimiser.
  std::vector<int> id(static_cast<std::size_t>(n), -1);
  int nfree = 0;
  for (int i = 0; i < n; ++i)
    if (!pinned[i]) id[i] = nfree++;
  if (nfree == 0) {
    *uv = plane;
    return true;
  }
  using Complex = std::complex<double>;
  using Triplet = Eigen::Triplet<Complex>;
  std::vector<Triplet> entries;
  entries.reserve(nt * 3);
  Eigen::VectorXcd rhs = Eigen::VectorXcd::Zero(static_cast<Eigen::Index>(nt));
  double area3 = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    const int c[3] = {patch.triangles[3 * t], patch.triangles[3 * t + 1], patch.triangles[3 * t + 2]};
    const Vec3 e1 = patch.positions[c[1]] - patch.positions[c[0]], e2 = patch.positions[c[2]] - patch.positions[c[0]];
    const Vec3 normal = e1.cross(e2);
    const double twice_area = normal.norm();
    area3 += 0.5 * twice_area;
    if (!(twice_area > 0)) continue;
    const Vec3 x = e1.normalized(), y = normal.normalized().cross(x);
    const Vec2 p[3] = {Vec2(0, 0), Vec2(e1.norm(), 0), Vec2(e2.dot(x), e2.dot(y))};
    const double w = 1.0 / std::sqrt(twice_area);
    const int row = static_cast<int>(t);
    for (int j = 0; j < 3; ++j) {
      const Vec2 W = p[(j + 2) % 3] - p[(j + 1) % 3];  // sum_j W_j z_j = 0: z holomorphic in the triangle
      const Complex a(w * W.x(), w * W.y());
      const int vtx = c[j];
      if (pinned[vtx])
        rhs[row] -= a * Complex(plane[vtx].x(), plane[vtx].y());
      else
        entries.emplace_back(row, id[vtx], a);
    }
  }
  Eigen::SparseMatrix<Complex> A(static_cast<Eigen::Index>(nt), nfree);
  A.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SparseMatrix<Complex> AhA = A.adjoint() * A;
  const Eigen::MatrixXcd Ahb = A.adjoint() * rhs;
  timings->conformal_assembly = seconds_since(start);
  Eigen::MatrixXcd solution;
  SpdTimings spd;
  const bool solved = solve_hpd(AhA, Ahb, &solution, &spd);
  timings->conformal_ordering = spd.ordering;
  timings->conformal_factorisation = spd.factorisation;
  timings->conformal_solve = spd.solve;
  if (!solved) return false;
  start = std::chrono::steady_clock::now();
  uv->resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    (*uv)[i] = pinned[i] ? plane[i] : Vec2(solution(id[i], 0).real(), solution(id[i], 0).imag());
  double area2 = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    const Vec2 f1 = (*uv)[patch.triangles[3 * t + 1]] - (*uv)[patch.triangles[3 * t]];
    const Vec2 f2 = (*uv)[patch.triangles[3 * t + 2]] - (*uv)[patch.triangles[3 * t]];
    area2 += 0.5 * std::abs(f1.x() * f2.y() - f1.y() * f2.x());
  }
  if (!(area2 > 0)) return false;
  const double scale = std::sqrt(area3 / area2);
  for (Vec2& q : *uv) q *= scale;  // about the plane's origin (the patch centroid)
  timings->conformal_assembly += seconds_since(start);
  return true;
}

}  // namespace

Flattened flatten(const HeightPatch& patch, const HeightMapOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  check_patch(patch);
  Flattened out;
  fit_plane(patch, &out);
  const std::vector<Vec2> plane = plane_uv(patch, out);
  const Distortion plane_distortion = measure_distortion(patch, plane);
  Flattening method = options.flattening;
  if (method == Flattening::Auto) {
    const bool gentle = plane_distortion.flipped_faces == 0 && plane_distortion.angle_max <= options.plane_tolerance;
    method = gentle ? Flattening::Plane : Flattening::Conformal;
    char text[160];
    std::snprintf(text, sizeof text, "auto: plane projection's angle distortion up to %.3g, %d folded faces: %s",
                  plane_distortion.angle_max, plane_distortion.flipped_faces, gentle ? "plane" : "conformal");
    out.note = text;
  }
  out.method = method;
  out.timings.plane = seconds_since(start);
  if (method == Flattening::Plane) {
    out.uv = plane;
    out.distortion = plane_distortion;
    return out;
  }
  if (!conformal_uv(patch, plane, &out.uv, &out.timings)) {
    out.method = Flattening::Plane;
    out.uv = plane;
    out.distortion = plane_distortion;
    out.note += (out.note.empty() ? "" : "; ") + std::string("the conformal map failed, used the plane projection");
    return out;
  }
  const auto distortion_start = std::chrono::steady_clock::now();
  out.distortion = measure_distortion(patch, out.uv);
  out.timings.conformal_distortion = seconds_since(distortion_start);
  return out;
}

HeightMap rasterise(const HeightPatch& patch, const Flattened& flat, double pixel_size,
                    const HeightMapOptions& options) {
  check_patch(patch);
  if (flat.uv.size() != patch.positions.size()) throw Error("the flattening does not match the patch");
  if (!(pixel_size > 0) || !std::isfinite(pixel_size)) throw Error("the pixel size must be a positive number");
  double umin = std::numeric_limits<double>::infinity(), vmin = umin, umax = -umin, vmax = -umin;
  for (const Vec2& q : flat.uv) {
    umin = std::min(umin, q.x());
    umax = std::max(umax, q.x());
    vmin = std::min(vmin, q.y());
    vmax = std::max(vmax, q.y());
  }
  const double w = std::ceil((umax - umin) / pixel_size), h = std::ceil((vmax - vmin) / pixel_size);
  if (!(w * h <= static_cast<double>(options.max_pixels)))
    throw Error("the height map would have " + std::to_string(static_cast<long long>(w)) + " x " +
                std::to_string(static_cast<long long>(h)) + " pixels (more than " +
                std::to_string(options.max_pixels) + "); give a larger pixel size");
  HeightMap map;
  map.width = std::max(1, static_cast<int>(w));
  map.height = std::max(1, static_cast<int>(h));
  map.pixel_size = pixel_size;
  map.u_left = umin;
  map.v_top = vmax;
  map.frame = flat;
  const std::size_t n = static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height);
  map.values.assign(n, 0.0f);
  map.mask.assign(n, 0);
  // Pixel coordinates: pixel (i, j) has its centre at (i, j).
  auto to_pixel = [&](const Vec2& q) { return Vec2((q.x() - umin) / pixel_size - 0.5, (vmax - q.y()) / pixel_size - 0.5); };
  for (std::size_t t = 0; t < patch.triangles.size(); t += 3) {
    const int c[3] = {patch.triangles[t], patch.triangles[t + 1], patch.triangles[t + 2]};
    const Vec2 p0 = to_pixel(flat.uv[c[0]]), p1 = to_pixel(flat.uv[c[1]]), p2 = to_pixel(flat.uv[c[2]]);
    const double area = (p1 - p0).x() * (p2 - p0).y() - (p1 - p0).y() * (p2 - p0).x();
    if (area == 0 || !std::isfinite(area)) continue;
    const int i0 = std::max(0, static_cast<int>(std::ceil(std::min({p0.x(), p1.x(), p2.x()}))));
    const int i1 = std::min(map.width - 1, static_cast<int>(std::floor(std::max({p0.x(), p1.x(), p2.x()}))));
    const int j0 = std::max(0, static_cast<int>(std::ceil(std::min({p0.y(), p1.y(), p2.y()}))));
    const int j1 = std::min(map.height - 1, static_cast<int>(std::floor(std::max({p0.y(), p1.y(), p2.y()}))));
    const double eps = -1e-9;
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const Vec2 q(i, j);
        const double b0 = ((p1 - q).x() * (p2 - q).y() - (p1 - q).y() * (p2 - q).x()) / area;
        const double b1 = ((p2 - q).x() * (p0 - q).y() - (p2 - q).y() * (p0 - q).x()) / area;
        const double b2 = 1 - b0 - b1;
        if (b0 < eps || b1 < eps || b2 < eps) continue;
        const std::size_t k = static_cast<std::size_t>(j) * static_cast<std::size_t>(map.width) + static_cast<std::size_t>(i);
        map.values[k] = static_cast<float>(b0 * patch.heights[c[0]] + b1 * patch.heights[c[1]] + b2 * patch.heights[c[2]]);
        map.mask[k] = 1;
      }
  }
  bool any = false;
  for (std::size_t k = 0; k < n; ++k) {
    if (!map.mask[k]) continue;
    if (!any) map.min_height = map.max_height = map.values[k];
    any = true;
    map.min_height = std::min(map.min_height, static_cast<double>(map.values[k]));
    map.max_height = std::max(map.max_height, static_cast<double>(map.values[k]));
  }
  return map;
}

}  // namespace relief_snake

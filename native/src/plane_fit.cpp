#include "relief_snake/plane_fit.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace relief_snake {

void PlaneMoments::add_point(const Vec3& x, double w) {
  weight += w;
  first += w * x;
  second.noalias() += w * (x * x.transpose());
}

void PlaneMoments::add_triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
  add_triangle(a, b, c, 0.5 * (b - a).cross(c - a).norm());
}

void PlaneMoments::add_triangle(const Vec3& a, const Vec3& b, const Vec3& c, double area) {
  if (!(area > 0)) return;
  const Vec3 s = a + b + c;
  weight += area;
  first += (area / 3.0) * s;
  // Uniform density over the triangle: integral of x x^T dA = A/12 (sum_i p_i p_i^T + s s^T).
  // The six distinct entries only (this is the planarity's inner loop).
  const double k = area / 12.0;
  auto entry = [&](int i, int j) { return k * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j]); };
  const double xx = entry(0, 0), yy = entry(1, 1), zz = entry(2, 2), xy = entry(0, 1), xz = entry(0, 2),
               yz = entry(1, 2);
  second(0, 0) += xx;
  second(1, 1) += yy;
  second(2, 2) += zz;
  second(0, 1) += xy;
  second(1, 0) += xy;
  second(0, 2) += xz;
  second(2, 0) += xz;
  second(1, 2) += yz;
  second(2, 1) += yz;
}

void PlaneMoments::add(const PlaneMoments& o) {
  weight += o.weight;
  first += o.first;
  second += o.second;
}

PlaneMoments PlaneMoments::shifted(const Vec3& o) const {
  PlaneMoments out;
  out.weight = weight;
  out.first = first - weight * o;
  // sum w (x - o)(x - o)^T = second - first o^T - o first^T + w o o^T
  out.second = second - first * o.transpose() - o * first.transpose() + weight * (o * o.transpose());
  return out;
}

double planarity_about_vertex(const PlaneMoments& m, const Vec3& vn) {
  if (!(m.weight > 0)) return 0.0;
  const Vec3 centroid = m.first / m.weight;  // relative to v
  const Eigen::Matrix3d cov = m.second / m.weight - centroid * centroid.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(cov);
  const Vec3 evals = solver.eigenvalues();  // increasing
  if (!(evals(2) > 0)) return 0.0;          // every point at the centroid
  Vec3 normal;
  // Collinear points leave the normal undetermined: use the surface's. (The closed-form
  // solver's rounding puts a zero eigenvalue at about 1e-8 of the largest.)
  if (evals(1) <= 1e-6 * evals(2)) {
    normal = vn;
  } else {
    normal = solver.eigenvectors().col(0);
    if (normal.dot(vn) < 0) normal = -normal;
  }
  return centroid.dot(normal);
}

double VertexPlaneFit::residual() const {
  return weight > 0 ? std::sqrt(std::max(0.0, eigenvalues[0]) / weight) : 0.0;
}

VertexPlaneFit fit_vertex_plane(const Mesh& mesh, const std::vector<int>& vertices, bool area_weighted) {
  VertexPlaneFit fit;
  double weight = 0;
  Vec3 mean = Vec3::Zero(), normal_sum = Vec3::Zero();
  for (const int v : vertices) {
    const double a = area_weighted ? mesh.vertex_area(v) : 1.0;
    weight += a;
    mean += a * mesh.position(v);
    normal_sum += a * mesh.vertex_normal(v);
  }
  if (weight <= 0) return fit;
  mean /= weight;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const int v : vertices) {
    const Vec3 d = mesh.position(v) - mean;
    cov += (area_weighted ? mesh.vertex_area(v) : 1.0) * d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  fit.weight = weight;
  fit.centroid = mean;
  fit.axes = solver.eigenvectors();
  fit.eigenvalues = solver.eigenvalues();
  fit.normal = fit.axes.col(0);
  if (fit.normal.dot(normal_sum) < 0) fit.normal = -fit.normal;
  return fit;
}

}  // namespace relief_snake

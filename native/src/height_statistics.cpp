// Polynomial backgrounds over a plane (plain and iteratively reweighted), weighted quantiles, Otsu.
#include "relief_snake/height_statistics.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "relief_snake/error.hpp"

namespace relief_snake {

namespace {
/// Degree 6 at most: 28 monomials.
constexpr int kMaxTerms = 28;

/// The monomials 1, x, y, x^2, xy, y^2, ... of total degree <= degree into out (no allocation:
/// the robust fit evaluates them for every vertex in every round).
void monomials(int degree, double x, double y, double* out) {
  double xp[8], yp[8];
  xp[0] = yp[0] = 1;
  for (int k = 1; k <= degree; ++k) xp[k] = xp[k - 1] * x, yp[k] = yp[k - 1] * y;
  int k = 0;
  for (int total = 0; total <= degree; ++total)
    for (int px = total; px >= 0; --px) out[k++] = xp[px] * yp[total - px];
}
}  // namespace

Eigen::VectorXd PolynomialBackground::basis(int degree, double x, double y) {
  Eigen::VectorXd b((degree + 1) * (degree + 2) / 2);
  monomials(degree, x, y, b.data());
  return b;
}

double PolynomialBackground::height(const Vec3& p) const {
  const Vec3 d = p - origin;
  if (c.size() == 0) return d.dot(normal);
  double phi[kMaxTerms];
  monomials(degree, d.dot(e1), d.dot(e2), phi);
  double sum = 0;
  for (int k = 0; k < c.size(); ++k) sum += phi[k] * c[k];
  return d.dot(normal) - sum;
}

PolynomialBackground fit_polynomial_background(const Mesh& mesh, const std::vector<int>& samples, int degree,
                                               const std::vector<double>* weights) {
  if (degree < 0 || degree > 6) throw Error("the background polynomial's degree must be between 0 and 6");
  PolynomialBackground fit;
  fit.degree = degree;
  const int terms = (degree + 1) * (degree + 2) / 2;
  fit.c = Eigen::VectorXd::Zero(terms);
  auto weight_of = [&](std::size_t i) { return mesh.vertex_area(samples[i]) * (weights ? (*weights)[i] : 1.0); };
  double weight = 0;
  Vec3 mean = Vec3::Zero(), normal_sum = Vec3::Zero();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double w = weight_of(i);
    weight += w;
    mean += w * mesh.position(samples[i]);
    normal_sum += w * mesh.vertex_normal(samples[i]);
  }
  if (weight <= 0) return fit;
  mean /= weight;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Vec3 d = mesh.position(samples[i]) - mean;
    cov += weight_of(i) * d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  fit.origin = mean;
  fit.normal = solver.eigenvectors().col(0);
  if (fit.normal.dot(normal_sum) < 0) fit.normal = -fit.normal;
  fit.e1 = solver.eigenvectors().col(2);
  fit.e2 = fit.normal.cross(fit.e1);
  // Scale the plane coordinates to about 1 so the normal equations are well conditioned.
  const double scale = std::sqrt(std::max(solver.eigenvalues()[2] / weight, 1e-300));
  fit.e1 /= scale;
  fit.e2 /= scale;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(terms, terms);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(terms);
  double phi[kMaxTerms];
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double w = weight_of(i);
    if (w <= 0) continue;
    const Vec3 d = mesh.position(samples[i]) - mean;
    monomials(degree, d.dot(fit.e1), d.dot(fit.e2), phi);
    const double z = w * d.dot(fit.normal);
    for (int r = 0; r < terms; ++r) {
      const double wr = w * phi[r];
      for (int col = 0; col <= r; ++col) A(r, col) += wr * phi[col];
      b[r] += z * phi[r];
    }
  }
  A = A.selfadjointView<Eigen::Lower>();
  fit.c = A.ldlt().solve(b);
  if (!fit.c.allFinite()) fit.c.setZero();
  double sum2 = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) sum2 += weight_of(i) * std::pow(fit.height(mesh.position(samples[i])), 2);
  fit.residual = std::sqrt(sum2 / weight);
  return fit;
}

RobustFit fit_robust_background(const Mesh& mesh, const std::vector<int>& samples, const RobustFitOptions& options) {
  RobustFit out;
  std::vector<double> weights(samples.size(), 1.0), heights(samples.size(), 0.0);
  out.background = fit_polynomial_background(mesh, samples, options.degree, &weights);
  for (int round = 0; round < options.iterations; ++round) {
    std::vector<WeightedHeight> magnitudes;
    magnitudes.reserve(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i) {
      heights[i] = out.background.height(mesh.position(samples[i]));
      magnitudes.push_back({std::fabs(heights[i]), mesh.vertex_area(samples[i])});
    }
    // sigma from all the samples' median |height|: the background is the majority.
    const double sigma = 1.4826 * weighted_quantile(magnitudes, 0.5);
    out.sigma = sigma;
    if (!(sigma > 0)) break;
    double change = 0, inliers = 0, total = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const double r = heights[i] / (options.tukey_c * sigma);
      const double w = std::fabs(r) < 1 ? (1 - r * r) * (1 - r * r) : 0.0;
      change = std::max(change, std::fabs(w - weights[i]));
      weights[i] = w;
      total += mesh.vertex_area(samples[i]);
      if (w > 0) inliers += mesh.vertex_area(samples[i]);
    }
    out.inlier_share = total > 0 ? inliers / total : 0;
    out.background = fit_polynomial_background(mesh, samples, options.degree, &weights);
    out.iterations = round + 1;
    if (change < 1e-2) break;  // no weight moved by more than 1%
  }
  return out;
}

double weighted_quantile(std::vector<WeightedHeight> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end(),
            [](const WeightedHeight& a, const WeightedHeight& b) { return a.height < b.height; });
  double total = 0;
  for (const auto& v : values) total += v.weight;
  double acc = 0;
  for (const auto& v : values) {
    acc += v.weight;
    if (acc >= q * total) return v.height;
  }
  return values.back().height;
}

OtsuSplit otsu_split(const std::vector<WeightedHeight>& values, int bins) {
  OtsuSplit split;
  if (values.size() < 2 || bins < 2) return split;
  const double lo = weighted_quantile(values, 0.005), hi = weighted_quantile(values, 0.995);
  if (!(hi > lo)) return split;
  std::vector<double> w(bins, 0), m(bins, 0);
  double total = 0, total_mean = 0;
  for (const auto& v : values) {
    const int k = std::clamp(static_cast<int>((v.height - lo) / (hi - lo) * bins), 0, bins - 1);
    w[k] += v.weight;
    m[k] += v.weight * v.height;
    total += v.weight;
    total_mean += v.weight * v.height;
  }
  double var_total = 0;
  for (const auto& v : values) var_total += v.weight * std::pow(v.height - total_mean / total, 2);
  double w0 = 0, m0 = 0, best = -1;
  for (int k = 0; k + 1 < bins; ++k) {
    w0 += w[k];
    m0 += m[k];
    const double w1 = total - w0;
    if (w0 <= 0 || w1 <= 0) continue;
    const double mu0 = m0 / w0, mu1 = (total_mean - m0) / w1;
    const double between = w0 * w1 * (mu1 - mu0) * (mu1 - mu0) / total;
    if (between > best) {
      best = between;
      split.threshold = lo + (k + 1) * (hi - lo) / bins;
    }
  }
  split.separation = var_total > 0 ? std::clamp(best / var_total, 0.0, 1.0) : 0;
  return split;
}

}  // namespace relief_snake

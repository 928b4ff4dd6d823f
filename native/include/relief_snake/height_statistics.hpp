#pragma once
// Heights above a smooth background and how they split: a polynomial height field over a
// best-fit plane (weighted least squares, optionally iteratively reweighted so reliefs standing
// on the background do not pull it up), area-weighted quantiles and Otsu's threshold. Used by the
// step-height estimate (step_height.hpp, a quadric along the initial contour) and by automatic
// detection (detect.hpp, a robust fit over a whole region).
#include <vector>

#include <Eigen/Core>

#include "relief_snake/mesh.hpp"

namespace relief_snake {

struct WeightedHeight {
  double height = 0, weight = 0;
};

/// A polynomial height field over a plane: height(p) = (p - origin) . normal - poly(x, y), with
/// x, y the plane coordinates (scaled to about 1) and poly of total degree `degree` in the basis
/// 1, x, y, x^2, xy, y^2, x^3, ... (degree 2: the quadric of the step-height estimate).
struct PolynomialBackground {
  Vec3 origin = Vec3::Zero(), e1 = Vec3::UnitX(), e2 = Vec3::UnitY(), normal = Vec3::UnitZ();
  int degree = 2;
  Eigen::VectorXd c;      ///< coefficients, (degree + 1)(degree + 2) / 2 of them
  double residual = 0;    ///< weighted RMS height of the samples above the fit

  static Eigen::VectorXd basis(int degree, double x, double y);
  /// Signed height of p above the fitted surface, along `normal` (oriented like the samples' vertex normals).
  double height(const Vec3& p) const;
};

/// Weighted least-squares fit to mesh vertices `samples` (each weighted by its vertex area times
/// weights[i] when weights is given; weights: one per sample). The plane is the area-weighted
/// best-fit plane of the samples (weights included).
PolynomialBackground fit_polynomial_background(const Mesh& mesh, const std::vector<int>& samples, int degree = 2,
                                               const std::vector<double>* weights = nullptr);

struct RobustFitOptions {
  int degree = 2;
  int iterations = 10;        ///< reweighting rounds at most (stops earlier when the weights settle)
  double tukey_c = 4.685;     ///< Tukey's biweight: heights beyond tukey_c robust sigmas get weight 0
};

struct RobustFit {
  PolynomialBackground background;
  double sigma = 0;           ///< robust noise level: 1.4826 x the area-weighted median |height| of the inliers' fit
  double inlier_share = 1;    ///< area share of the samples with weight > 0 in the last round
  int iterations = 0;
};

/// Iteratively reweighted least squares with Tukey's biweight on the heights (sigma from their
/// median absolute value): reliefs, which stand clearly above the background, end with weight 0,
/// so the fit is the background under them as long as they cover well under half the samples.
RobustFit fit_robust_background(const Mesh& mesh, const std::vector<int>& samples, const RobustFitOptions& options = {});

/// The q-quantile (0..1) of area-weighted values (0 when empty).
double weighted_quantile(std::vector<WeightedHeight> values, double q);

struct OtsuSplit {
  double threshold = 0;   ///< values above it are the upper class
  double separation = 0;  ///< between-class share of the variance (0..1): 1 = two clean spikes
};

/// Otsu's threshold on an area-weighted histogram of `bins` bins between the 0.5% and 99.5% quantiles.
OtsuSplit otsu_split(const std::vector<WeightedHeight>& values, int bins);

}  // namespace relief_snake

#pragma once
// Ground truth for the extraction tests: the analytic background of a generated scan
// (tests/synthetic), the distance of a point from it, and error statistics of a fill.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "relief_snake/background.hpp"
#include "synthetic.hpp"

namespace relief_snake::test {

/// Distance of p from the scan's true background surface (the analytic plane, cylinder,
/// sphere or saddle the generator offsets the relief from).
inline double distance_to_background(const synthetic::Scan& scan, const Vec3& p) {
  const double R = scan.spec.radius;
  switch (scan.spec.background) {
    case synthetic::Background::Plane: return std::abs(p.z());
    case synthetic::Background::Cylinder: return std::abs(std::hypot(p.x(), p.z() + R) - R);
    case synthetic::Background::Sphere: return std::abs((p - Vec3(0, 0, -R)).norm() - R);
    case synthetic::Background::Saddle: {
      // z = (x^2 - y^2) / 2R: nearest point by a few Newton steps on the parameters.
      double u = p.x(), v = p.y();
      for (int it = 0; it < 20; ++it) {
        const Vec3 s(u, v, (u * u - v * v) / (2 * R));
        const Vec3 su(1, 0, u / R), sv(0, 1, -v / R);
        const Vec3 d = s - p;
        const double gu = d.dot(su), gv = d.dot(sv);
        const double huu = su.dot(su) + d.z() / R, hvv = sv.dot(sv) - d.z() / R, huv = su.dot(sv);
        const double det = huu * hvv - huv * huv;
        if (std::abs(det) < 1e-12) break;
        u -= (hvv * gu - huv * gv) / det;
        v -= (huu * gv - huv * gu) / det;
      }
      return (Vec3(u, v, (u * u - v * v) / (2 * R)) - p).norm();
    }
    case synthetic::Background::Vase:
    case synthetic::Background::Wavy:
      break;  // no closed form here: NaN, so a test that measures them fails instead of passing on 0
  }
  return std::numeric_limits<double>::quiet_NaN();
}

struct FillErrors {
  double mean_base = 0, max_base = 0;      ///< distance of the base from the true background
  double mean_height = 0, max_height = 0;  ///< |height - true height|
  std::size_t vertices = 0;                ///< region vertices scored (away from the contour)
};

/// Errors over the region's vertices deeper than `margin` inside the true boundary. True heights:
/// h for a sharp step without detail (the generator's construction).
inline FillErrors fill_errors(const synthetic::Scan& scan, const BackgroundResult& fill, double margin) {
  FillErrors e;
  for (const int v : fill.region_vertices) {
    const double u = scan.UV[2 * v], w = scan.UV[2 * v + 1];
    if (scan.signed_distance(u, w) > -margin) continue;
    const double base = distance_to_background(scan, fill.base_positions[v]);
    const double height = std::abs(fill.height[v] - scan.h);
    e.mean_base += base;
    e.mean_height += height;
    e.max_base = std::max(e.max_base, base);
    e.max_height = std::max(e.max_height, height);
    ++e.vertices;
  }
  if (e.vertices) {
    e.mean_base /= static_cast<double>(e.vertices);
    e.mean_height /= static_cast<double>(e.vertices);
  }
  return e;
}

}  // namespace relief_snake::test

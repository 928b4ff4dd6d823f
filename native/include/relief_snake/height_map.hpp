#pragma once
// The relief's height map: a flattening of the base patch under the relief (projection
// onto its best-fit plane, or a least-squares conformal map for curved backgrounds) and a
// raster of the height above the base over it, masked outside the relief.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "relief_snake/mesh.hpp"

namespace relief_snake {

using Vec2 = Eigen::Vector2d;

enum class Flattening {
  Auto,       ///< Plane when its angle distortion stays under HeightMapOptions::plane_tolerance, else Conformal
  Plane,      ///< orthogonal projection onto the best-fit plane of the base patch
  Conformal,  ///< least-squares conformal map (Levy et al. 2002), aligned with and scaled to the plane's frame
};
const char* to_string(Flattening flattening);
/// "auto", "plane" or "conformal"; throws Error otherwise.
Flattening parse_flattening(const std::string& name);

/// How much a flattening distorts the base patch, per face from the singular values
/// s1 >= s2 of its Jacobian (3D triangle to its uv image).
struct Distortion {
  double angle_mean = 0, angle_max = 0;  ///< s1 / s2 - 1, area-weighted mean and largest (0: conformal)
  double area_mean = 0, area_max = 0;    ///< |s1 s2 / (total uv area / total 3D area) - 1|: local scale change
  int flipped_faces = 0;                 ///< faces whose uv image is turned over
};

/// Where flatten() spends its wall time (seconds; for benchmarks). The conformal stages stay 0
/// when the plane projection is used.
struct FlattenTimings {
  double plane = 0;                    ///< best-fit plane, projection and its distortion
  double conformal_assembly = 0;       ///< the least-squares conformal system and the final scaling
  double conformal_ordering = 0;       ///< its fill-reducing ordering and symbolic analysis
  double conformal_factorisation = 0;  ///< its numeric factorisation
  double conformal_solve = 0;          ///< its triangular solves
  double conformal_distortion = 0;     ///< the conformal map's distortion
};

/// A flattening of a patch: uv coordinates in a 3D frame (origin + u axis_u + v axis_v is
/// where a uv point lies on the best-fit plane).
struct Flattened {
  Flattening method = Flattening::Plane;
  std::vector<Vec2> uv;  ///< one per patch vertex, in the order given
  Vec3 origin = Vec3::Zero(), axis_u = Vec3::UnitX(), axis_v = Vec3::UnitY(), normal = Vec3::UnitZ();
  Distortion distortion;
  std::string note;  ///< why Auto chose what it chose
  FlattenTimings timings;
};

struct HeightMapOptions {
  double pixel_size = 0;  ///< mesh units per pixel; <= 0: half the mesh's average edge
  Flattening flattening = Flattening::Auto;
  double plane_tolerance = 0.05;       ///< Auto: largest angle distortion (s1/s2 - 1) accepted for Plane
  std::size_t max_pixels = 64u << 20;  ///< larger rasters are refused (give a larger pixel size)
};

/// A patch: base positions P (#P by 3), triangles T (#T by 3, indices into P), heights (#P).
struct HeightPatch {
  std::vector<Vec3> positions;
  std::vector<int> triangles;  ///< 3 per triangle
  std::vector<double> heights;
};

/// Flattens a patch (throws Error on an empty or degenerate patch).
Flattened flatten(const HeightPatch& patch, const HeightMapOptions& options);

struct HeightMap {
  int width = 0, height = 0;  ///< pixels
  double pixel_size = 0;
  /// Pixel (i, j) (column i, row j from the top) has its centre at
  /// u = u_left + (i + 0.5) pixel_size, v = v_top - (j + 0.5) pixel_size.
  double u_left = 0, v_top = 0;
  std::vector<float> values;  ///< width * height heights, row-major from the top row; 0 where masked
  std::vector<std::uint8_t> mask;  ///< width * height: 1 inside the relief
  double min_height = 0, max_height = 0;  ///< over the unmasked pixels
  Flattened frame;
  std::size_t covered_pixels() const;
};

/// Rasterises the patch's heights over its flattening: each pixel centre inside a triangle's uv
/// image gets the height interpolated linearly there. Throws Error on an empty patch or a
/// raster larger than max_pixels.
HeightMap rasterise(const HeightPatch& patch, const Flattened& flat, double pixel_size, const HeightMapOptions& options);

}  // namespace relief_snake

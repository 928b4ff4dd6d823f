#pragma once
// Small analytic meshes for the unit tests.
#include <cmath>
#include <functional>
#include <vector>

#include "relief_snake/mesh.hpp"

namespace relief_snake::test {

/// An nu x nv grid over [0, su] x [0, sv], each vertex mapped by f(u, v) -> 3D.
/// Quads are split along alternating diagonals.
inline Mesh grid_mesh(int nu, int nv, double su, double sv, const std::function<Vec3(double, double)>& f) {
  std::vector<double> V;
  std::vector<std::int64_t> F;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const Vec3 p = f(su * i / (nu - 1), sv * j / (nv - 1));
      V.insert(V.end(), {p.x(), p.y(), p.z()});
    }
  for (int j = 0; j + 1 < nv; ++j)
    for (int i = 0; i + 1 < nu; ++i) {
      const std::int64_t a = j * nu + i, b = a + 1, c = a + nu, d = c + 1;
      if ((i + j) % 2 == 0) F.insert(F.end(), {a, b, d, a, d, c});
      else F.insert(F.end(), {a, b, c, b, d, c});
    }
  return Mesh::from_triangles(V.data(), V.size() / 3, F.data(), F.size() / 3);
}

inline Mesh plane_mesh(int n = 41, double size = 10) {
  return grid_mesh(n, n, size, size, [](double u, double v) { return Vec3(u, v, 0); });
}

/// Cylinder of radius r around the y axis, outward normals; u is arc length.
inline Mesh cylinder_mesh(double r, int nu, int nv, double length, double arc) {
  return grid_mesh(nu, nv, arc, length, [r](double u, double v) {
    return Vec3(r * std::sin(u / r), v, r * std::cos(u / r));
  });
}

}  // namespace relief_snake::test

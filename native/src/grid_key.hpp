#pragma once
// Cells of a uniform 3D grid and their 64-bit keys, for the hash grids of the
// snake's housekeeping (internal).
#include <cstdint>

#include <Eigen/Core>

#include "relief_snake/mesh.hpp"

namespace relief_snake {

/// The integer cell of p in a grid of cells of size `cell`.
inline Eigen::Array3i grid_cell(const Vec3& p, double cell) {
  return (p / cell).array().floor().cast<int>();
}

/// A key for cell c: 21 bits per axis (cells more than a million apart may share a key,
/// which the grids' users tolerate: they compare the geometry, not only the keys).
inline std::uint64_t grid_key(const Eigen::Array3i& c) {
  auto bits = [](int x) { return static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) & 0x1FFFFFu; };
  return (bits(c.x()) << 42) | (bits(c.y()) << 21) | bits(c.z());
}

}  // namespace relief_snake

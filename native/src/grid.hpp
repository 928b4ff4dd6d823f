#pragma once
// The one hash grid of the engine (internal): a uniform grid of cubes over 3D points, items filed
// by cell, for the snake's neighbour searches (loop removal, the convergence check, the foot snap's
// distance to the far side of a slot).
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "relief_snake/mesh.hpp"

namespace relief_snake {

/// A uniform 3D grid: cubes of side `cell`, counted from `origin`, with items filed under the
/// cells they belong to. Fill with add(), then build(), then look cells up with for_each().
///
/// Cells are counted from an origin near the items (the callers pass one of their points), so
/// georeferenced coordinates (1e7 in file units, cells of a millimetre) give small cell indices;
/// every index is also clamped to +-2^30 before it becomes an int (a NaN position goes to cell
/// 0), so no coordinate can overflow the cast. Keys hold 21 bits per axis: cells 2^21 apart share
/// a key, and users must compare the geometry of what they find, not only its cell (they do).
class HashGrid {
 public:
  using Cell = Eigen::Array3i;

  HashGrid() = default;
  HashGrid(const Vec3& origin, double cell) { reset(origin, cell); }

  /// Empties the grid (keeping its buffers) and sets its frame.
  void reset(const Vec3& origin, double cell) {
    origin_ = origin;
    cell_ = cell;
    pending_.clear();
    entries_.clear();
    start_.assign(2, 0);
    buckets_ = 1;
  }

  double cell_size() const { return cell_; }

  /// The cell holding p.
  Cell cell_of(const Vec3& p) const {
    const Vec3 q = (p - origin_) / cell_;
    return Cell(index(q.x()), index(q.y()), index(q.z()));
  }

  /// Files `item` under cell c (once per call; an item may be filed under several cells).
  void add(const Cell& c, int item) { pending_.emplace_back(key(c), item); }

  /// Sorts what add() filed into buckets (a counting sort); for_each() sees it afterwards.
  void build() {
    buckets_ = 1;
    while (buckets_ < 2u * static_cast<std::uint32_t>(pending_.size())) buckets_ <<= 1;
    start_.assign(buckets_ + 1, 0);
    for (const auto& e : pending_) ++start_[bucket(e.first) + 1];
    for (std::uint32_t k = 0; k < buckets_; ++k) start_[k + 1] += start_[k];
    entries_.resize(pending_.size());
    fill_.assign(start_.begin(), start_.end() - 1);
    for (const auto& e : pending_) entries_[fill_[bucket(e.first)]++] = e;
    pending_.clear();
  }

  /// visit(item) for every item filed under cell c's key, in the order they were added.
  template <class Visit>
  void for_each(const Cell& c, const Visit& visit) const {
    const std::uint64_t k = key(c);
    const std::uint32_t b = bucket(k);
    for (std::uint32_t e = start_[b]; e < start_[b + 1]; ++e)
      if (entries_[e].first == k) visit(entries_[e].second);
  }

  /// The key of cell c: 21 bits per axis.
  static std::uint64_t key(const Cell& c) {
    auto bits = [](int x) { return static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) & 0x1FFFFFu; };
    return (bits(c.x()) << 42) | (bits(c.y()) << 21) | bits(c.z());
  }

  /// The largest cell index magnitude (indices are clamped to it, so neighbours c +- a few stay ints).
  static constexpr double kMaxIndex = 1073741824.0;  // 2^30

 private:
  static int index(double x) {
    const double f = std::floor(x);
    if (f >= kMaxIndex) return static_cast<int>(kMaxIndex);
    if (f <= -kMaxIndex) return -static_cast<int>(kMaxIndex);
    if (!(f == f)) return 0;  // NaN
    return static_cast<int>(f);
  }
  std::uint32_t bucket(std::uint64_t k) const {
    return static_cast<std::uint32_t>((k * 0x9E3779B97F4A7C15ull) >> 32) & (buckets_ - 1);
  }

  Vec3 origin_ = Vec3::Zero();
  double cell_ = 1;
  std::uint32_t buckets_ = 1;
  std::vector<std::pair<std::uint64_t, int>> pending_, entries_;
  std::vector<std::uint32_t> start_ = {0, 0}, fill_;
};

}  // namespace relief_snake

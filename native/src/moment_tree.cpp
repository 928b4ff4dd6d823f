#include "relief_snake/moment_tree.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace relief_snake {

namespace {

constexpr int kLeafSize = 8;

// Spreads the low 10 bits of x to every third bit (Morton code helper).
unsigned spread_bits(unsigned x) {
  x &= 0x3ff;
  x = (x | (x << 16)) & 0x030000ff;
  x = (x | (x << 8)) & 0x0300f00f;
  x = (x | (x << 4)) & 0x030c30c3;
  x = (x | (x << 2)) & 0x09249249;
  return x;
}

int leading_zeros(unsigned x) { return x == 0 ? 32 : __builtin_clz(x); }

double cone_angle(double c) { return std::acos(std::clamp(c, -1.0, 1.0)); }

}  // namespace

Vec3 MomentTree::element_normal(int e) const {
  return elements_ == Elements::Faces ? mesh_.face_normal(e) : mesh_.vertex_normal(e);
}

double MomentTree::element_weight(int e) const {
  return elements_ == Elements::WeightedVertices ? mesh_.vertex_area(e) : 1.0;
}

int MomentTree::element_component(int e) const {
  return mesh_.component(elements_ == Elements::Faces ? mesh_.face_vertex(e, 0) : e);
}

MomentTree::MomentTree(const Mesh& mesh, Elements elements) : mesh_(mesh), elements_(elements) {
  const int n = elements == Elements::Faces ? mesh.n_faces() : mesh.n_vertices();
  if (n == 0) return;
  std::vector<Vec3> centre(n);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int e = 0; e < n; ++e) {
    if (elements == Elements::Faces)
      centre[e] = (mesh.position(mesh.face_vertex(e, 0)) + mesh.position(mesh.face_vertex(e, 1)) +
                   mesh.position(mesh.face_vertex(e, 2))) / 3.0;
    else
      centre[e] = mesh.position(e);
    lo = lo.cwiseMin(centre[e]);
    hi = hi.cwiseMax(centre[e]);
  }
  origin_ = 0.5 * (lo + hi);
  const Vec3 extent = (hi - lo).cwiseMax(1e-300);
  // Morton order: elements near in space are near in the order, so every index
  // range of the tree is a compact box.
  std::vector<std::pair<unsigned, int>> keyed(n);
  for (int e = 0; e < n; ++e) {
    const Vec3 t = ((centre[e] - lo).array() / extent.array()).cwiseMax(0.0).cwiseMin(1.0) * 1023.0;
    keyed[e] = {(spread_bits(static_cast<unsigned>(t.x())) << 2) | (spread_bits(static_cast<unsigned>(t.y())) << 1) |
                    spread_bits(static_cast<unsigned>(t.z())),
                e};
  }
  std::sort(keyed.begin(), keyed.end());
  order_.resize(n);
  std::vector<unsigned> codes(n);
  for (int k = 0; k < n; ++k) {
    order_[k] = keyed[k].second;
    codes[k] = keyed[k].first;
  }
  nodes_.reserve(2 * (n / kLeafSize + 2));
  build(0, n, codes);
}

int MomentTree::build(int begin, int end, const std::vector<unsigned>& codes) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  nodes_[index].begin = begin;
  nodes_[index].end = end;
  if (end - begin <= kLeafSize) {
    finish_leaf(nodes_[index]);
    return index;
  }
  // Split where the highest differing Morton bit changes (a spatial split);
  // a run of equal codes is cut in the middle.
  int split = (begin + end) / 2;
  const unsigned first = codes[begin], last = codes[end - 1];
  if (first != last) {
    const int common = leading_zeros(first ^ last);
    int lo = begin, hi = end - 1;  // codes[lo] shares more than `common` leading bits with first, codes[hi] not
    while (lo + 1 < hi) {
      const int mid = lo + (hi - lo) / 2;
      if (leading_zeros(first ^ codes[mid]) > common) lo = mid;
      else hi = mid;
    }
    split = hi;
  }
  const int left = build(begin, split, codes);
  const int right = build(split, end, codes);
  Node& node = nodes_[index];  // nodes_ may have grown: take the reference now
  node.left = left;
  node.right = right;
  finish_inner(node, nodes_[left], nodes_[right]);
  return index;
}

namespace {

float down(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float up(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

}  // namespace

void MomentTree::set_box(Node& node, const Vec3& lo, const Vec3& hi) {
  for (int k = 0; k < 3; ++k) {
    node.lo[k] = down(lo[k]);
    node.hi[k] = up(hi[k]);
  }
}

void MomentTree::set_cone(Node& node, const Vec3& axis, double cos_spread) {
  for (int k = 0; k < 3; ++k) node.axis[k] = static_cast<float>(axis[k]);
  // The float axis is off by ~1e-7 rad: widen the cone by 1e-6 rad to stay conservative.
  const double spread = cos_spread <= -1 ? M_PI : std::min(M_PI, cone_angle(cos_spread) + 1e-6);
  node.cone_cos = spread >= M_PI ? -1.0f : down(std::cos(spread));
  node.cone_sin = spread >= M_PI ? 0.0f : up(std::sin(spread));
}

void MomentTree::set_moments(Node& node, const PlaneMoments& m) {
  node.weight = m.weight;
  for (int k = 0; k < 3; ++k) node.first[k] = m.first[k];
  const Eigen::Matrix3d& q = m.second;
  const double entries[6] = {q(0, 0), q(1, 1), q(2, 2), q(0, 1), q(0, 2), q(1, 2)};
  std::copy(entries, entries + 6, node.second);
}

void MomentTree::add_moments(const Node& node, PlaneMoments* m) {
  m->weight += node.weight;
  m->first += Vec3(node.first[0], node.first[1], node.first[2]);
  const double* e = node.second;
  m->second(0, 0) += e[0];
  m->second(1, 1) += e[1];
  m->second(2, 2) += e[2];
  m->second(0, 1) += e[3];
  m->second(1, 0) += e[3];
  m->second(0, 2) += e[4];
  m->second(2, 0) += e[4];
  m->second(1, 2) += e[5];
  m->second(2, 1) += e[5];
}

PlaneMoments MomentTree::moments_of(const Node& node) const {
  PlaneMoments m;
  add_moments(node, &m);
  return m;
}

void MomentTree::finish_leaf(Node& node) const {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  Vec3 normal_sum = Vec3::Zero();
  PlaneMoments m;
  node.component = element_component(order_[node.begin]);
  for (int k = node.begin; k < node.end; ++k) {
    const int e = order_[k];
    if (elements_ == Elements::Faces) {
      const Vec3 a = mesh_.position(mesh_.face_vertex(e, 0)), b = mesh_.position(mesh_.face_vertex(e, 1)),
                 c = mesh_.position(mesh_.face_vertex(e, 2));
      lo = lo.cwiseMin(a).cwiseMin(b).cwiseMin(c);
      hi = hi.cwiseMax(a).cwiseMax(b).cwiseMax(c);
      m.add_triangle(a - origin_, b - origin_, c - origin_, mesh_.face_area(e));
      normal_sum += mesh_.face_area(e) * mesh_.face_normal(e);
    } else {
      const Vec3& p = mesh_.position(e);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      m.add_point(p - origin_, element_weight(e));
      normal_sum += mesh_.vertex_normal(e);
    }
    if (element_component(e) != node.component) node.component = -1;
  }
  set_box(node, lo, hi);
  set_moments(node, m);
  const double len = normal_sum.norm();
  const Vec3 axis = len > 0 ? Vec3(normal_sum / len) : Vec3::UnitZ();
  double cos_spread = len > 0 ? 1.0 : -1.0;
  if (len > 0)
    for (int k = node.begin; k < node.end; ++k) cos_spread = std::min(cos_spread, element_normal(order_[k]).dot(axis));
  set_cone(node, axis, cos_spread);
}

void MomentTree::finish_inner(Node& node, const Node& a, const Node& b) const {
  for (int k = 0; k < 3; ++k) {
    node.lo[k] = std::min(a.lo[k], b.lo[k]);
    node.hi[k] = std::max(a.hi[k], b.hi[k]);
  }
  PlaneMoments m = moments_of(a);
  add_moments(b, &m);
  set_moments(node, m);
  node.component = a.component == b.component ? a.component : -1;
  // A cone holding both children's cones (conservative).
  const Vec3 axis_a(a.axis[0], a.axis[1], a.axis[2]), axis_b(b.axis[0], b.axis[1], b.axis[2]);
  const Vec3 sum = a.weight * axis_a + b.weight * axis_b;
  const double len = sum.norm();
  if (!(len > 0) || a.cone_cos <= -1 || b.cone_cos <= -1) {
    set_cone(node, Vec3::UnitZ(), -1);
    return;
  }
  const Vec3 axis = sum / len;
  const double spread = std::max(cone_angle(axis_a.dot(axis)) + cone_angle(a.cone_cos),
                                 cone_angle(axis_b.dot(axis)) + cone_angle(b.cone_cos));
  set_cone(node, axis, spread >= M_PI ? -1.0 : std::cos(spread));
}

void MomentTree::add_cut(const Vec3& a, const Vec3& b, const Vec3& c, const Query& q, double r2,
                         PlaneMoments* out) const {
  const Vec3 g = (a + b + c) / 3.0;
  if ((g - q.center).squaredNorm() <= r2) out->add_triangle(a - origin_, b - origin_, c - origin_);
}

void MomentTree::add_element(int e, const Query& q, double r2, PlaneMoments* out) const {
  if (q.component >= 0 && element_component(e) != q.component) return;
  if (element_normal(e).dot(q.facing) < q.min_facing) return;
  if (elements_ == Elements::Faces) {
    add_cut(mesh_.position(mesh_.face_vertex(e, 0)), mesh_.position(mesh_.face_vertex(e, 1)),
            mesh_.position(mesh_.face_vertex(e, 2)), q, r2, out);
  } else if ((mesh_.position(e) - q.center).squaredNorm() <= r2) {
    out->add_point(mesh_.position(e) - origin_, element_weight(e));
  }
}

PlaneMoments MomentTree::sphere(const Query& q) const {
  PlaneMoments sum;
  if (nodes_.empty()) return sum;
  const double r2 = q.radius * q.radius, grain2 = q.grain * q.grain;
  const double facing_norm = q.facing.norm();
  const bool test_facing = facing_norm > 0 && q.min_facing > -1;
  const Vec3 facing = test_facing ? Vec3(q.facing / facing_norm) : Vec3::Zero();
  Query leaf_query = q;
  leaf_query.facing = facing;
  if (!test_facing) leaf_query.min_facing = -2;  // every normal passes
  const double cx = q.center.x(), cy = q.center.y(), cz = q.center.z();

  std::array<int, 128> stack;  // depth is ~log2(n / leaf) + a few: far below 128
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (q.component >= 0 && node.component >= 0 && node.component != q.component) continue;
    // Nearest and farthest points of the box.
    double near2 = 0, far2 = 0, diag2 = 0;
    const double c[3] = {cx, cy, cz};
    for (int k = 0; k < 3; ++k) {
      const double lo = node.lo[k], hi = node.hi[k];
      const double below = lo - c[k], above = c[k] - hi;
      const double gap = std::max({below, above, 0.0});
      near2 += gap * gap;
      const double reach = std::max(c[k] - lo, hi - c[k]);
      far2 += reach * reach;
      diag2 += (hi - lo) * (hi - lo);
    }
    if (near2 > r2) continue;
    bool all_facing = true;
    if (test_facing) {
      // The cone's normals make angles alpha -+ spread with `facing` (cos alpha = d).
      const double d = node.axis[0] * facing.x() + node.axis[1] * facing.y() + node.axis[2] * facing.z();
      const double sin_alpha = std::sqrt(std::max(0.0, 1 - d * d));
      const double cc = node.cone_cos, cs = node.cone_sin;
      const double best = d >= cc ? 1.0 : d * cc + sin_alpha * cs;    // cos(max(0, alpha - spread))
      if (best < q.min_facing) continue;                              // every normal faces away
      const double worst = d < -cc ? -1.0 : d * cc - sin_alpha * cs;  // cos(min(pi, alpha + spread))
      all_facing = worst >= q.min_facing;
    }
    const bool one_component = q.component < 0 || node.component == q.component;
    if (one_component && all_facing) {
      if (far2 <= r2) {
        add_moments(node, &sum);  // wholly inside: take the node's sums
        continue;
      }
      if (diag2 <= grain2) {
        // Small enough to count like a face: whole, if its centroid is inside.
        const Vec3 centroid = Vec3(node.first[0], node.first[1], node.first[2]) / node.weight + origin_;
        if ((centroid - q.center).squaredNorm() <= r2) add_moments(node, &sum);
        continue;
      }
    }
    if (node.left < 0) {
      for (int k = node.begin; k < node.end; ++k) add_element(order_[k], leaf_query, r2, &sum);
      continue;
    }
    stack[top++] = node.left;
    stack[top++] = node.right;
  }
  return sum.shifted(q.center - origin_);
}

std::size_t MomentTree::memory_bytes() const {
  return nodes_.capacity() * sizeof(Node) + order_.capacity() * sizeof(int);
}

}  // namespace relief_snake

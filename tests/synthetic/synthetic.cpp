// Synthetic scans with exact ground truth (see synthetic.hpp).
#include "synthetic.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <unordered_map>
#include <unordered_set>

#include <nlohmann/json.hpp>

#include "relief_snake/error.hpp"

namespace relief_snake {
namespace synthetic {
namespace {

using Vec2 = Eigen::Vector2d;

// --- deterministic randomness: a hash of (seed, stream, index), independent of order -----
std::uint64_t splitmix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}
std::uint64_t hash3(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  return splitmix(splitmix(seed * 0x2545f4914f6cdd1dULL + stream) ^ index);
}
double uniform01(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  return static_cast<double>(hash3(seed, stream, index) >> 11) * (1.0 / 9007199254740992.0);
}
double gaussian(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  // Box-Muller with our own uniforms: std::normal_distribution differs between libraries.
  const double u1 = (static_cast<double>(hash3(seed, stream, 2 * index) >> 11) + 1.0) * (1.0 / 9007199254740992.0);
  const double u2 = uniform01(seed, stream, 2 * index + 1);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}
enum Stream : std::uint64_t { kJitterU = 1, kJitterV = 2, kDiagonal = 3, kNoise = 4, kDots = 5, kPickMove = 6,
                               kRandomDraw = 1000 };

// std::hypot is careful about overflow and slow; our coordinates are small.
inline double len2d(double x, double y) { return std::sqrt(x * x + y * y); }

double clamp01(double x) { return x < 0 ? 0 : (x > 1 ? 1 : x); }
double smoothstep(double x) {
  x = clamp01(x);
  return x * x * (3 - 2 * x);
}

// The edge profile at distance d inside the boundary: the step's rise (0 .. 1), the drop's top
// (1, or falling to 0.3 within 1.5 h) and the edge groove's depth (in length units).
double step_rise(const ScanSpec& spec, double d) {
  return spec.step == Step::Sharp ? 1.0 : smoothstep(d / (spec.blend_width * spec.h));
}
double drop_top(const ScanSpec& spec, double d) { return spec.drop ? 1.0 - 0.7 * smoothstep(d / (1.5 * spec.h)) : 1.0; }
double edge_groove_depth(const ScanSpec& spec, double d) {
  const double off = (d - spec.edge_groove_distance * spec.h) / (spec.groove_width * spec.h);
  return spec.edge_groove * spec.h * std::exp(-off * off);
}

// --- 2D signed distances (negative inside) -----------------------------------------------
double sd_circle(double x, double y, double cx, double cy, double r) { return len2d(x - cx, y - cy) - r; }
double sd_capsule(double x, double y, double ax, double ay, double bx, double by, double r) {
  const double px = x - ax, py = y - ay, dx = bx - ax, dy = by - ay;
  const double t = clamp01((px * dx + py * dy) / (dx * dx + dy * dy));
  return len2d(px - t * dx, py - t * dy) - r;
}
double sd_box(double x, double y, double cx, double cy, double hx, double hy) {
  const double dx = std::abs(x - cx) - hx, dy = std::abs(y - cy) - hy;
  return len2d(std::max(dx, 0.0), std::max(dy, 0.0)) + std::min(std::max(dx, dy), 0.0);
}

double sd_duck(double x, double y) {
  double d = sd_capsule(x, y, -12, -6, 12, -6, 7);             // body: top edge at y = 1
  d = std::min(d, sd_circle(x, y, 5, 9, 5));                    // head
  d = std::min(d, sd_capsule(x, y, 4, -1, 5, 6, 2.5));          // neck
  d = std::min(d, sd_capsule(x, y, 9, 9, 17, 7.5, 1.6));        // beak over the pocket above the body
  d = std::min(d, sd_capsule(x, y, -12, -2, -17, 4, 1.8));      // tail
  return d;
}
constexpr double kSlotsHalfU = 24, kSlotsHalfV = 9;

// Box given by its corners.
double sd_span(double x, double y, double x0, double x1, double y0, double y1) {
  return sd_box(x, y, 0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (x1 - x0), 0.5 * (y1 - y0));
}
// Block letters of half sizes X, Y and stroke width w, centred on the origin.
double sd_letter(double x, double y, char letter, double X, double Y, double w) {
  const double left = sd_span(x, y, -X, -X + w, -Y, Y), right = sd_span(x, y, X - w, X, -Y, Y);
  const double top = sd_span(x, y, -X, X, Y - w, Y), bottom = sd_span(x, y, -X, X, -Y, -Y + w);
  switch (letter) {
    case 'L': return std::min(left, bottom);
    case 'T': return std::min(top, sd_span(x, y, -0.5 * w, 0.5 * w, -Y, Y));
    case 'E': return std::min({left, top, bottom, sd_span(x, y, -X, 0.6 * X, -0.5 * w, 0.5 * w)});
    case 'H': return std::min({left, right, sd_span(x, y, -X, X, -0.5 * w, 0.5 * w)});
    case 'U': return std::min({left, right, bottom});
    default: return left;
  }
}
constexpr double kOpenA[3] = {34, 4, 14};   // disk clipped by the right edge (needs width/2 < 48)
constexpr double kOpenB[3] = {22, -8, 7};

// --- level-set tracing (marching triangles on a uniform grid, blocks far from the curve skipped)
struct Curve2 {
  std::vector<Vec2> points;
  bool closed = true;
  double length() const {
    double l = 0;
    for (std::size_t i = 1; i < points.size(); ++i) l += (points[i] - points[i - 1]).norm();
    if (closed && points.size() > 1) l += (points.front() - points.back()).norm();
    return l;
  }
};

// Traces f = 0 over [u0, u0 + W] x [v0, v0 + H]; f must be 1-Lipschitz (so a block whose
// centre value exceeds its half diagonal holds no crossing). The region f < 0 is on the
// left of every curve.
template <class Fn>
std::vector<Curve2> trace_level(const Fn& f, double u0, double v0, double W, double H, double cell) {
  const std::int64_t nu = std::max<std::int64_t>(2, static_cast<std::int64_t>(std::ceil(W / cell)));
  const std::int64_t nv = std::max<std::int64_t>(2, static_cast<std::int64_t>(std::ceil(H / cell)));
  const double cu = W / nu, cv = H / nv;
  const int B = 16;
  auto node = [&](std::int64_t i, std::int64_t j) { return j * (nu + 1) + i; };
  std::unordered_map<std::int64_t, std::int64_t> next;  // exit crossing -> entry crossing
  std::unordered_map<std::int64_t, Vec2> point;
  std::vector<double> val((B + 1) * (B + 1));
  for (std::int64_t bj = 0; bj * B < nv; ++bj) {
    for (std::int64_t bi = 0; bi * B < nu; ++bi) {
      const std::int64_t i0 = bi * B, j0 = bj * B;
      const std::int64_t i1 = std::min(nu, i0 + B), j1 = std::min(nv, j0 + B);
      const double bu0 = u0 + i0 * cu, bv0 = v0 + j0 * cv, bu1 = u0 + i1 * cu, bv1 = v0 + j1 * cv;
      const double half_diag = 0.5 * std::hypot(bu1 - bu0, bv1 - bv0);
      if (std::abs(f(0.5 * (bu0 + bu1), 0.5 * (bv0 + bv1))) > half_diag * 1.001 + 1e-12) continue;
      const int w = static_cast<int>(i1 - i0) + 1;
      for (std::int64_t j = j0; j <= j1; ++j)
        for (std::int64_t i = i0; i <= i1; ++i)
          val[(j - j0) * w + (i - i0)] = f(u0 + i * cu, v0 + j * cv);
      auto value = [&](std::int64_t i, std::int64_t j) { return val[(j - j0) * w + (i - i0)]; };
      // Edge between two grid nodes: key and crossing point, computed from the canonical
      // (lower-left) end so neighbouring triangles and blocks agree exactly.
      auto crossing = [&](std::int64_t ia, std::int64_t ja, std::int64_t ib, std::int64_t jb) {
        if (ia > ib || ja > jb) {
          std::swap(ia, ib);
          std::swap(ja, jb);
        }
        const int type = (ja == jb) ? 0 : (ia == ib ? 1 : 2);
        const std::int64_t key = 3 * node(ia, ja) + type;
        if (!point.count(key)) {
          const double a = value(ia, ja), b = value(ib, jb);
          const double t = a / (a - b);
          point[key] = Vec2(u0 + (ia + t * (ib - ia)) * cu, v0 + (ja + t * (jb - ja)) * cv);
        }
        return key;
      };
      for (std::int64_t j = j0; j < j1; ++j) {
        for (std::int64_t i = i0; i < i1; ++i) {
          const std::int64_t tris[2][3][2] = {{{i, j}, {i + 1, j}, {i + 1, j + 1}},
                                              {{i, j}, {i + 1, j + 1}, {i, j + 1}}};
          for (const auto& tri : tris) {
            bool in[3];
            for (int k = 0; k < 3; ++k) in[k] = value(tri[k][0], tri[k][1]) < 0;
            if (in[0] == in[1] && in[1] == in[2]) continue;
            std::int64_t exit_key = -1, entry_key = -1;
            for (int k = 0; k < 3; ++k) {
              const int l = (k + 1) % 3;
              if (in[k] == in[l]) continue;
              const std::int64_t key = crossing(tri[k][0], tri[k][1], tri[l][0], tri[l][1]);
              (in[k] ? exit_key : entry_key) = key;
            }
            next[exit_key] = entry_key;
          }
        }
      }
    }
  }
  // Chain the segments: open chains start at a crossing nobody enters; the rest are loops.
  std::unordered_set<std::int64_t> entered;
  for (const auto& kv : next) entered.insert(kv.second);
  std::vector<std::int64_t> starts;
  for (const auto& kv : next)
    if (!entered.count(kv.first)) starts.push_back(kv.first);
  std::sort(starts.begin(), starts.end());
  std::vector<std::int64_t> loop_starts;
  for (const auto& kv : next) loop_starts.push_back(kv.first);
  std::sort(loop_starts.begin(), loop_starts.end());
  std::unordered_set<std::int64_t> visited;
  std::vector<Curve2> curves;
  auto follow = [&](std::int64_t key, bool closed) {
    Curve2 c;
    c.closed = closed;
    while (true) {
      visited.insert(key);
      const Vec2& p = point.at(key);
      if (c.points.empty() || (p - c.points.back()).norm() > 1e-12 * (1 + cell)) c.points.push_back(p);
      auto it = next.find(key);
      if (it == next.end()) break;
      key = it->second;
      if (visited.count(key)) break;
    }
    if (closed && c.points.size() > 1 && (c.points.front() - c.points.back()).norm() <= 1e-12 * (1 + cell))
      c.points.pop_back();
    if (c.points.size() >= 2) curves.push_back(std::move(c));
  };
  for (std::int64_t s : starts) follow(s, false);
  for (std::int64_t s : loop_starts)
    if (!visited.count(s)) follow(s, true);
  return curves;
}

// Point at arc length t along a curve (wraps around for closed curves).
struct ArcLength {
  const Curve2& curve;
  std::vector<double> cumulative;
  explicit ArcLength(const Curve2& c) : curve(c) {
    cumulative.push_back(0);
    const std::size_t n = c.points.size();
    const std::size_t segments = c.closed ? n : n - 1;
    for (std::size_t i = 0; i < segments; ++i)
      cumulative.push_back(cumulative.back() + (c.points[(i + 1) % n] - c.points[i]).norm());
  }
  double length() const { return cumulative.back(); }
  Vec2 at(double t) const {
    const std::size_t n = curve.points.size();
    if (curve.closed) t = std::fmod(std::fmod(t, length()) + length(), length());
    t = std::min(std::max(t, 0.0), length());
    std::size_t k = std::upper_bound(cumulative.begin(), cumulative.end(), t) - cumulative.begin();
    k = std::min(std::max<std::size_t>(k, 1), cumulative.size() - 1) - 1;
    const double seg = cumulative[k + 1] - cumulative[k];
    const double s = seg > 0 ? (t - cumulative[k]) / seg : 0;
    return (1 - s) * curve.points[k] + s * curve.points[(k + 1) % n];
  }
};

// Dots texture: the centre of lattice cell (i, j)'s dot (jittered by up to a quarter period).
Vec2 dot_center(const ScanSpec& sp, std::int64_t i, std::int64_t j) {
  const double S = sp.texture_period * sp.h;
  const std::uint64_t key = static_cast<std::uint64_t>(i + (1 << 20)) * 2097152ULL + static_cast<std::uint64_t>(j + (1 << 20));
  return Vec2((i + 0.5 + 0.5 * (uniform01(sp.seed, kDots, 2 * key) - 0.5)) * S,
              (j + 0.5 + 0.5 * (uniform01(sp.seed, kDots, 2 * key + 1) - 0.5)) * S);
}
// Texture offset along the normal at (u, v), absolute units.
double texture_at(const ScanSpec& sp, double u, double v) {
  const double A = sp.texture_amplitude * sp.h, P = sp.texture_period * sp.h;
  if (sp.texture == Texture::Striations)
    return A * std::sin(2 * M_PI * (u * std::cos(sp.texture_angle) + v * std::sin(sp.texture_angle)) / P);
  if (sp.texture == Texture::Dots) {
    const std::int64_t ci = static_cast<std::int64_t>(std::floor(u / P)), cj = static_cast<std::int64_t>(std::floor(v / P));
    const double r = sp.dot_radius * sp.h;
    double best = 0;
    for (std::int64_t j = cj - 1; j <= cj + 1; ++j)
      for (std::int64_t i = ci - 1; i <= ci + 1; ++i) {
        const Vec2 c = dot_center(sp, i, j);
        const double dist = len2d(u - c.x(), v - c.y());
        if (dist < r) best = std::max(best, smoothstep(1 - dist / r));
      }
    return A * best;
  }
  return 0;
}

}  // namespace

double edge_step_height(const ScanSpec& spec) {
  // The highest point of the profile up to where the step has risen and the profile then stops
  // rising (a drop falls from there, an edge groove dips), in thousandths of h, at most 3 h in.
  const auto profile = [&](double d) {
    double height = spec.h * step_rise(spec, d) * drop_top(spec, d);
    if (spec.edge_groove > 0) height -= edge_groove_depth(spec, d);
    return height;
  };
  const int risen = spec.step == Step::Sharp ? 1 : std::max(1, static_cast<int>(std::ceil(1e3 * spec.blend_width)));
  double rim = -std::numeric_limits<double>::infinity(), last = rim;
  for (int k = 1; k <= 3000; ++k) {
    const double height = profile(1e-3 * k * spec.h);
    if (k > risen && height <= last) break;
    rim = std::max(rim, height);
    last = height;
  }
  return rim;
}

// --- enums -------------------------------------------------------------------------------
Shape parse_shape(const std::string& n) {
  if (n == "duck") return Shape::Duck;
  if (n == "disk") return Shape::Disk;
  if (n == "rectangle") return Shape::Rectangle;
  if (n == "slots") return Shape::Slots;
  if (n == "open") return Shape::Open;
  if (n == "gear") return Shape::Gear;
  if (n == "c") return Shape::CShape;
  if (n == "ellipse") return Shape::Ellipse;
  if (n == "rounded-box") return Shape::RoundedBox;
  if (n == "letter") return Shape::Letter;
  if (n == "band") return Shape::Band;
  if (n == "ring") return Shape::Ring;
  if (n == "holed-letter") return Shape::HoledLetter;
  throw Error("unknown shape '" + n + "': use duck, disk, rectangle, slots, open, gear, c, ellipse, rounded-box, letter, "
              "band, ring or holed-letter");
}
Background parse_background(const std::string& n) {
  if (n == "plane") return Background::Plane;
  if (n == "cylinder") return Background::Cylinder;
  if (n == "sphere") return Background::Sphere;
  if (n == "saddle") return Background::Saddle;
  if (n == "vase") return Background::Vase;
  if (n == "wavy") return Background::Wavy;
  throw Error("unknown background '" + n + "': use plane, cylinder, sphere, saddle, vase or wavy");
}
Step parse_step(const std::string& n) {
  if (n == "sharp") return Step::Sharp;
  if (n == "blended") return Step::Blended;
  throw Error("unknown step '" + n + "': use sharp or blended");
}
Start parse_start(const std::string& n) {
  if (n == "near") return Start::Near;
  if (n == "far") return Start::Far;
  if (n == "zigzag") return Start::Zigzag;
  throw Error("unknown start '" + n + "': use near, far or zigzag");
}
const char* to_string(Shape s) {
  switch (s) {
    case Shape::Duck: return "duck";
    case Shape::Disk: return "disk";
    case Shape::Rectangle: return "rectangle";
    case Shape::Slots: return "slots";
    case Shape::Open: return "open";
    case Shape::Gear: return "gear";
    case Shape::CShape: return "c";
    case Shape::Ellipse: return "ellipse";
    case Shape::RoundedBox: return "rounded-box";
    case Shape::Letter: return "letter";
    case Shape::Band: return "band";
    case Shape::Ring: return "ring";
    case Shape::HoledLetter: return "holed-letter";
  }
  return "?";
}
const char* to_string(Background b) {
  switch (b) {
    case Background::Plane: return "plane";
    case Background::Cylinder: return "cylinder";
    case Background::Sphere: return "sphere";
    case Background::Saddle: return "saddle";
    case Background::Vase: return "vase";
    case Background::Wavy: return "wavy";
  }
  return "?";
}
const char* to_string(Step s) { return s == Step::Sharp ? "sharp" : "blended"; }
Texture parse_texture(const std::string& n) {
  if (n == "none") return Texture::None;
  if (n == "striations") return Texture::Striations;
  if (n == "dots") return Texture::Dots;
  throw Error("unknown texture '" + n + "': use none, striations or dots");
}
const char* to_string(Texture t) {
  switch (t) {
    case Texture::None: return "none";
    case Texture::Striations: return "striations";
    case Texture::Dots: return "dots";
  }
  return "?";
}
const char* to_string(Start s) {
  switch (s) {
    case Start::Near: return "near";
    case Start::Far: return "far";
    case Start::Zigzag: return "zigzag";
  }
  return "?";
}

// --- geometry of a scan ------------------------------------------------------------------
double Scan::signed_distance(double u, double v) const {
  if (spec.shape_rotation != 0 || spec.shape_center_u != 0 || spec.shape_center_v != 0) {
    // Into the shape's own frame (a rigid motion keeps distances).
    const double c = std::cos(spec.shape_rotation), s = std::sin(spec.shape_rotation);
    const double x = u - spec.shape_center_u, y = v - spec.shape_center_v;
    u = c * x + s * y;
    v = -s * x + c * y;
  }
  switch (spec.shape) {
    case Shape::Duck: return sd_duck(u, v);
    case Shape::Disk: return sd_circle(u, v, 0, 0, 12);
    case Shape::Rectangle: return sd_box(u, v, 0, 0, 16, 10);
    case Shape::Slots: {
      double d = sd_box(u, v, 0, 0, kSlotsHalfU, kSlotsHalfV);
      // Each slot box reaches 2 above the top edge so its mouth is open; subtracting
      // (max(d, -slot)) keeps the function 1-Lipschitz.
      const double depth = spec.slot_depth * spec.h, extra = 2;
      for (std::size_t k = 0; k + 1 < slots.size(); k += 2)
        d = std::max(d, -sd_box(u, v, slots[k], kSlotsHalfV - depth + 0.5 * (depth + extra), 0.5 * slots[k + 1],
                                0.5 * (depth + extra)));
      return d;
    }
    case Shape::Open:
      return std::min(sd_circle(u, v, kOpenA[0], kOpenA[1], kOpenA[2]), sd_circle(u, v, kOpenB[0], kOpenB[1], kOpenB[2]));
    case Shape::Gear: {
      const double R = spec.gear_radius, depth = spec.gear_slot_depth, extra = 2;
      double d = sd_circle(u, v, 0, 0, R);
      for (std::size_t k = 0; k + 1 < slots.size(); k += 2) {
        const double c = std::cos(slots[k]), s = std::sin(slots[k]);
        const double radial = c * u + s * v, across = -s * u + c * v;
        d = std::max(d, -sd_box(radial, across, R - depth + 0.5 * (depth + extra), 0, 0.5 * (depth + extra),
                                0.5 * slots[k + 1]));
      }
      return d;
    }
    case Shape::CShape: {
      const double ring = std::abs(len2d(u, v) - spec.c_radius) - spec.c_half_thickness;
      const double c = std::cos(spec.c_gap_angle), s = std::sin(spec.c_gap_angle);
      const double radial = c * u + s * v, across = -s * u + c * v;
      return std::max(ring, -sd_box(radial, across, spec.c_radius, 0, spec.c_half_thickness + 2, 0.5 * spec.c_gap_width));
    }
    case Shape::Ellipse: {
      // min(a, b) (|(u/a, v/b)| - 1): zero on the ellipse, 1-Lipschitz, a lower bound of the distance.
      const double a = spec.ellipse_a, b = spec.ellipse_b;
      return std::min(a, b) * (len2d(u / a, v / b) - 1);
    }
    case Shape::RoundedBox: {
      const double r = spec.box_corner;
      return sd_box(u, v, 0, 0, spec.box_half_u - r, spec.box_half_v - r) - r;
    }
    case Shape::Letter: return sd_letter(u, v, spec.letter, spec.letter_half_u, spec.letter_half_v, spec.stroke_width);
    case Shape::Ring:
    case Shape::HoledLetter: return holed_shape_distance(spec, u, v);
    case Shape::Band: {
      double d = 1e300;
      for (std::size_t k = 0; k + 3 < band.size(); k += 2)
        d = std::min(d, sd_capsule(u, v, band[k], band[k + 1], band[k + 2], band[k + 3], spec.band_half_width));
      return d;
    }
  }
  return 1;
}

Vec3 Scan::surface(double u, double v, double height) const {
  const double R = spec.radius;
  switch (spec.background) {
    case Background::Plane: return Vec3(u, v, height);
    case Background::Cylinder: {
      const double a = u / R;
      return Vec3((R + height) * std::sin(a), v, (R + height) * std::cos(a) - R);
    }
    case Background::Sphere: {
      const double a = u / R, b = v / R;
      const Vec3 n(std::cos(b) * std::sin(a), std::sin(b), std::cos(b) * std::cos(a));
      return (R + height) * n - Vec3(0, 0, R);
    }
    case Background::Saddle: return Vec3(u, v, (u * u - v * v) / (2 * R)) + height * background_normal(u, v);
    case Background::Vase: {
      const double a = u / R;
      const double rho = R * (1 + spec.vase_amplitude * std::sin(2 * M_PI * v / spec.vase_period + spec.vase_phase));
      return Vec3(rho * std::sin(a), v, rho * std::cos(a) - R) + height * background_normal(u, v);
    }
    case Background::Wavy: {
      const double z = spec.wavy_amplitude * std::sin(2 * M_PI * u / spec.wavy_period_u + spec.wavy_phase) *
                       std::cos(2 * M_PI * v / spec.wavy_period_v);
      return Vec3(u, v, z) + height * background_normal(u, v);
    }
  }
  return Vec3(u, v, height);
}

Vec3 Scan::background_normal(double u, double v) const {
  const double R = spec.radius;
  switch (spec.background) {
    case Background::Plane: return Vec3(0, 0, 1);
    case Background::Cylinder: return Vec3(std::sin(u / R), 0, std::cos(u / R));
    case Background::Sphere: {
      const double a = u / R, b = v / R;
      return Vec3(std::cos(b) * std::sin(a), std::sin(b), std::cos(b) * std::cos(a));
    }
    case Background::Saddle: return Vec3(-u / R, v / R, 1).normalized();
    case Background::Vase: {
      // d(rho)/dv; the normal is (sin a, -rho', cos a) / |.| (d/du x d/dv, facing +z at u = 0).
      const double k = 2 * M_PI / spec.vase_period;
      const double drho = R * spec.vase_amplitude * k * std::cos(k * v + spec.vase_phase);
      const double a = u / R;
      return Vec3(std::sin(a), -drho, std::cos(a)).normalized();
    }
    case Background::Wavy: {
      const double ku = 2 * M_PI / spec.wavy_period_u, kv = 2 * M_PI / spec.wavy_period_v, A = spec.wavy_amplitude;
      const double fu = A * ku * std::cos(ku * u + spec.wavy_phase) * std::cos(kv * v);
      const double fv = -A * kv * std::sin(ku * u + spec.wavy_phase) * std::sin(kv * v);
      return Vec3(-fu, -fv, 1).normalized();
    }
  }
  return Vec3(0, 0, 1);
}

namespace {
// Inverse of generate()'s graded warp x - g L / (2 pi) sin(2 pi x / L) (Newton; its slope is >= 1 - g).
double unwarp(double y, double L, double g) {
  double x = y;
  for (int it = 0; it < 30; ++it) {
    const double f = x - g * L / (2 * M_PI) * std::sin(2 * M_PI * x / L) - y;
    x -= f / (1 - g * std::cos(2 * M_PI * x / L));
    if (std::abs(f) < 1e-12 * L) break;
  }
  return x;
}
}  // namespace

double Scan::grid_column(double u) const {
  const double x = u + 0.5 * spec.width;
  return (spec.grade_u > 0 ? unwarp(x, spec.width, spec.grade_u) : x) / spacing_u;
}
double Scan::grid_row(double v) const {
  const double y = v + 0.5 * spec.height;
  return (spec.grade_v > 0 ? unwarp(y, spec.height, spec.grade_v) : y) / spacing_v;
}

int Scan::nearest_vertex(double u, double v) const {
  // Clamped into the grid: a point off the domain (a zigzag ring's far corner) gets the nearest
  // border vertex instead of no vertex at all.
  const int i0 = std::clamp(static_cast<int>(std::lround(grid_column(u))), 0, grid_u - 1);
  const int j0 = std::clamp(static_cast<int>(std::lround(grid_row(v))), 0, grid_v - 1);
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (int j = std::max(0, j0 - 2); j <= std::min(grid_v - 1, j0 + 2); ++j)
    for (int i = std::max(0, i0 - 2); i <= std::min(grid_u - 1, i0 + 2); ++i) {
      const int k = j * grid_u + i;
      const double d = std::hypot(UV[2 * k] - u, UV[2 * k + 1] - v);
      if (d < best_d) best_d = d, best = k;
    }
  return best;
}

std::vector<std::int64_t> Scan::relief_vertices() const {
  std::vector<std::int64_t> out;
  for (std::size_t i = 0; i < relief.size(); ++i)
    if (relief[i]) out.push_back(static_cast<std::int64_t>(i));
  return out;
}

double Scan::relief_fraction() const {
  if (relief.empty()) return 0;
  std::size_t n = 0;
  for (auto r : relief) n += r;
  return static_cast<double>(n) / relief.size();
}

// --- generation --------------------------------------------------------------------------
Scan generate(const ScanSpec& spec) {
  if (spec.triangles < 8 || spec.triangles > 50000000)
    throw Error("synthetic scan: triangles must be between 8 and 50M (e.g. 10000 .. 2000000)");
  if (!(spec.h > 0)) throw Error("synthetic scan: the step height h must be > 0");
  if (!(spec.width > 0) || !(spec.height > 0)) throw Error("synthetic scan: width and height must be > 0");
  if (!(spec.jitter >= 0 && spec.jitter < 0.35)) throw Error("synthetic scan: jitter must be in [0, 0.35)");
  if (!(spec.noise >= 0) || !(spec.detail >= 0) || !(spec.blend_width > 0))
    throw Error("synthetic scan: noise and detail must be >= 0 and blend_width > 0");
  if (spec.background != Background::Plane) {
    if (!(spec.radius > 0)) throw Error("synthetic scan: the background radius must be > 0");
    const double a = 0.5 * spec.width / spec.radius, b = 0.5 * spec.height / spec.radius;
    if ((spec.background == Background::Cylinder && a >= M_PI * 0.9) ||
        (spec.background == Background::Sphere && (a >= M_PI * 0.9 || b >= M_PI / 2 * 0.9)))
      throw Error("synthetic scan: the domain wraps too far around the background; use a larger radius");
    if (spec.background == Background::Vase && (a >= M_PI * 0.9 || !(std::abs(spec.vase_amplitude) < 0.5) ||
                                                !(spec.vase_period > 0)))
      throw Error("synthetic scan: the vase needs a larger radius, |amplitude| < 0.5 and a period > 0");
    if (spec.background == Background::Wavy && !(spec.wavy_period_u > 0 && spec.wavy_period_v > 0))
      throw Error("synthetic scan: the wavy background needs periods > 0");
  }
  if (spec.texture != Texture::None &&
      !(spec.texture_period > 0 && spec.dot_radius > 0 && std::abs(spec.texture_amplitude) <= 1))
    throw Error("synthetic scan: the texture needs a period > 0, a dot radius > 0 and |amplitude| <= 1");
  if (!(spec.grade_u >= 0 && spec.grade_u < 0.9 && spec.grade_v >= 0 && spec.grade_v < 0.9))
    throw Error("synthetic scan: grade_u and grade_v must be in [0, 0.9)");
  if (spec.shape == Shape::Open && 0.5 * spec.width >= kOpenA[0] + kOpenA[2])
    throw Error("synthetic scan: the open shape needs width < 96 to be clipped by the domain edge");

  Scan s;
  s.spec = spec;
  s.h = spec.h;
  const double W = spec.width, H = spec.height;
  const std::int64_t cells_u = std::max<std::int64_t>(
      2, std::llround(std::sqrt(0.5 * static_cast<double>(spec.triangles) * W / H)));
  const std::int64_t cells_v =
      std::max<std::int64_t>(2, std::llround(0.5 * static_cast<double>(spec.triangles) / cells_u));
  s.grid_u = static_cast<int>(cells_u + 1);
  s.grid_v = static_cast<int>(cells_v + 1);
  s.spacing_u = W / cells_u;
  s.spacing_v = H / cells_v;
  const std::size_t nv = static_cast<std::size_t>(s.grid_u) * s.grid_v;

  // Jittered grid; boundary vertices slide only along their edge so the domain stays a rectangle.
  s.UV.resize(2 * nv);
  for (int j = 0; j < s.grid_v; ++j)
    for (int i = 0; i < s.grid_u; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * s.grid_u + i;
      // Uniform in a disk of radius jitter: a square of half-side 0.3 could flip triangles,
      // the disk keeps every triangle's area above 0.07 spacing^2 at jitter 0.3.
      const double r = spec.jitter * std::sqrt(uniform01(spec.seed, kJitterU, k));
      const double angle = 2 * M_PI * uniform01(spec.seed, kJitterV, k);
      double du = r * std::cos(angle) * s.spacing_u, dv = r * std::sin(angle) * s.spacing_v;
      if (i == 0 || i + 1 == s.grid_u) du = 0;
      if (j == 0 || j + 1 == s.grid_v) dv = 0;
      s.UV[2 * k] = -0.5 * W + i * s.spacing_u + du;
      s.UV[2 * k + 1] = -0.5 * H + j * s.spacing_v + dv;
    }
  if (spec.grade_u > 0 || spec.grade_v > 0) {
    // Graded triangulation: a monotone warp of each axis that keeps the domain's edges, so the
    // spacing varies by (1 +- grade) and no triangle flips.
    auto warp = [](double x, double L, double g) { return x - g * L / (2 * M_PI) * std::sin(2 * M_PI * x / L); };
    for (std::size_t k = 0; k < nv; ++k) {
      if (spec.grade_u > 0) s.UV[2 * k] = warp(s.UV[2 * k] + 0.5 * W, W, spec.grade_u) - 0.5 * W;
      if (spec.grade_v > 0) s.UV[2 * k + 1] = warp(s.UV[2 * k + 1] + 0.5 * H, H, spec.grade_v) - 0.5 * H;
    }
  }
  if (spec.shape == Shape::Band) {
    // Centreline: starts outside the domain edge, enters along the edge's inward normal turned by
    // band_angle, bends with band_curvature.
    const double margin = 2 * spec.band_half_width + 4;
    Vec2 p, n;
    switch (spec.band_edge) {
      case 0: p = Vec2(-0.5 * W - margin, spec.band_offset), n = Vec2(1, 0); break;
      case 1: p = Vec2(0.5 * W + margin, spec.band_offset), n = Vec2(-1, 0); break;
      case 2: p = Vec2(spec.band_offset, -0.5 * H - margin), n = Vec2(0, 1); break;
      default: p = Vec2(spec.band_offset, 0.5 * H + margin), n = Vec2(0, -1); break;
    }
    double angle = std::atan2(n.y(), n.x()) + spec.band_angle;
    const int pieces = 32;
    const double length = spec.band_length + margin, step = length / pieces;
    s.band.push_back(p.x()), s.band.push_back(p.y());
    for (int k = 0; k < pieces; ++k) {
      angle += 0.5 * spec.band_curvature * step;
      p += step * Vec2(std::cos(angle), std::sin(angle));
      angle += 0.5 * spec.band_curvature * step;
      s.band.push_back(p.x()), s.band.push_back(p.y());
    }
  }

  // Random diagonals; also the unique edges (horizontal, vertical, one diagonal per quad).
  s.F.resize(static_cast<std::size_t>(6) * cells_u * cells_v);
  std::vector<std::uint8_t> diagonal(static_cast<std::size_t>(cells_u) * cells_v);
  for (std::int64_t j = 0; j < cells_v; ++j)
    for (std::int64_t i = 0; i < cells_u; ++i) {
      const std::size_t q = static_cast<std::size_t>(j * cells_u + i);
      const std::int64_t v00 = j * s.grid_u + i, v10 = v00 + 1, v01 = v00 + s.grid_u, v11 = v01 + 1;
      const bool d = (hash3(spec.seed, kDiagonal, q) >> 63) != 0;
      diagonal[q] = d;
      std::int64_t* f = &s.F[6 * q];
      if (d) {  // v00-v11
        f[0] = v00, f[1] = v10, f[2] = v11, f[3] = v00, f[4] = v11, f[5] = v01;
      } else {  // v10-v01
        f[0] = v00, f[1] = v10, f[2] = v01, f[3] = v10, f[4] = v11, f[5] = v01;
      }
    }
  auto for_each_edge = [&](auto&& visit) {
    for (int j = 0; j < s.grid_v; ++j)
      for (int i = 0; i < s.grid_u; ++i) {
        const std::int64_t k = static_cast<std::int64_t>(j) * s.grid_u + i;
        if (i + 1 < s.grid_u) visit(k, k + 1);
        if (j + 1 < s.grid_v) visit(k, k + s.grid_u);
        if (i + 1 < s.grid_u && j + 1 < s.grid_v)
          diagonal[static_cast<std::size_t>(j) * cells_u + i] ? visit(k, k + s.grid_u + 1) : visit(k + 1, k + s.grid_u);
      }
  };
  double uv_sum = 0;
  std::size_t n_edges = 0;
  for_each_edge([&](std::int64_t a, std::int64_t b) {
    uv_sum += len2d(s.UV[2 * a] - s.UV[2 * b], s.UV[2 * a + 1] - s.UV[2 * b + 1]);
    ++n_edges;
  });
  s.nominal_edge = uv_sum / n_edges;

  if (spec.shape == Shape::Slots) {
    // Slot mouths in nominal average edges; equal walls between and beside them.
    double total = 0;
    for (double w : spec.slot_widths) {
      if (!(w > 0)) throw Error("synthetic scan: slot widths must be > 0 (in average edges)");
      total += w * s.nominal_edge;
    }
    const double wall = (2 * kSlotsHalfU - total) / (spec.slot_widths.size() + 1);
    if (wall < 1.5 * spec.h)
      throw Error("synthetic scan: the slots do not fit in the 48-wide rectangle; use fewer or narrower slots or more triangles");
    if (spec.slot_depth * spec.h > 2 * kSlotsHalfV - 2 * spec.h)
      throw Error("synthetic scan: slot_depth * h must be below 16; use a smaller slot depth");
    double u = -kSlotsHalfU;
    for (double w : spec.slot_widths) {
      const double width = w * s.nominal_edge;
      u += wall;
      s.slots.push_back(u + 0.5 * width);
      s.slots.push_back(width);
      u += width;
    }
  }

  if (spec.shape == Shape::Gear) {
    // Radial slots, evenly spaced, mouths in nominal average edges.
    const std::size_t n = spec.slot_widths.size();
    for (std::size_t k = 0; k < n; ++k) {
      const double width = spec.slot_widths[k] * s.nominal_edge;
      if (!(width > 0)) throw Error("synthetic scan: slot widths must be > 0 (in average edges)");
      if (2 * M_PI * spec.gear_radius / n - width < 1.5 * spec.h)
        throw Error("synthetic scan: the gear's slots do not fit; use fewer or narrower slots");
      s.slots.push_back(2 * M_PI * static_cast<double>(k) / n);
      s.slots.push_back(width);
    }
    if (!(spec.gear_slot_depth > 0 && spec.gear_slot_depth < spec.gear_radius - 2 * spec.h))
      throw Error("synthetic scan: the gear's slot depth must be in (0, radius - 2 h)");
  }

  // Heights along the normal, flags, noise.
  s.V.resize(3 * nv);
  s.relief.resize(nv);
  s.relief_height.resize(nv);
  s.texture_height.assign(nv, 0.0);
  s.noise_height.assign(nv, 0.0);
  const double h = spec.h;
  for (std::size_t k = 0; k < nv; ++k) {
    const double u = s.UV[2 * k], v = s.UV[2 * k + 1];
    const double sd = s.signed_distance(u, v);
    s.relief[k] = sd < 0;
    double height = 0, rise = 0;
    if (sd < 0) {
      const double d = -sd;
      rise = step_rise(spec, d);
      height = h * rise * drop_top(spec, d);
      if (spec.detail > 0) {
        const double wave = 4 * h;
        height += spec.detail * h * smoothstep((d - spec.bump_inset * h) / h) * std::sin(2 * M_PI * u / wave) *
                  std::sin(2 * M_PI * v / wave);
      }
      if (spec.dome > 0) height += spec.dome * h * smoothstep(d / (spec.dome_width * h));
      if (spec.grooves > 0) {
        // Parallel straight grooves across the relief, faded out within 1 h of its edge.
        const double across = u * std::cos(spec.groove_angle) + v * std::sin(spec.groove_angle);
        const double off = std::remainder(across, spec.groove_spacing * h) / (spec.groove_width * h);
        height -= spec.grooves * h * std::exp(-off * off) * smoothstep((d - 0.5 * h) / (0.5 * h));
      }
      if (spec.edge_groove > 0) height -= edge_groove_depth(spec, d);
    }
    s.relief_height[k] = height;
    if (spec.texture != Texture::None) {
      // The background's texture, fading out as the step rises.
      const double t = texture_at(spec, u, v) * (sd < 0 ? 1 - rise : 1.0);
      s.texture_height[k] = t;
      if (t != 0) height += t;
    }
    if (spec.noise > 0) {
      const double e = spec.noise * h * gaussian(spec.seed, kNoise, k);
      s.noise_height[k] = e;
      height += e;
    }
    const Vec3 p = s.surface(u, v, height);
    s.V[3 * k] = p.x(), s.V[3 * k + 1] = p.y(), s.V[3 * k + 2] = p.z();
  }

  double sum = 0;
  for_each_edge([&](std::int64_t a, std::int64_t b) {
    sum += std::sqrt((s.V[3 * a] - s.V[3 * b]) * (s.V[3 * a] - s.V[3 * b]) +
                     (s.V[3 * a + 1] - s.V[3 * b + 1]) * (s.V[3 * a + 1] - s.V[3 * b + 1]) +
                     (s.V[3 * a + 2] - s.V[3 * b + 2]) * (s.V[3 * a + 2] - s.V[3 * b + 2]));
  });
  s.average_edge = sum / n_edges;

  // The true boundary: sd = 0, dense, on the surface the scan has there: the background's texture
  // (whole at the foot, where the step has not yet risen), not the smooth base under it. (On the base,
  // a contour exactly at the foot of a step on a texture of 0.2 h at 10 edges per h scored 1 to 1.4
  // edges off, and the one-edge IoU floor, grown in 3D from it, was stricter on textured scans.)
  // The noise, per vertex, is left out.
  const double cell = std::min(s.nominal_edge, h) / 8;
  auto sd = [&s](double u, double v) { return s.signed_distance(u, v); };
  for (const Curve2& c : trace_level(sd, -0.5 * W, -0.5 * H, W, H, cell)) {
    Polyline p;
    p.closed = c.closed;
    p.points.reserve(c.points.size());
    for (const Vec2& q : c.points) p.points.push_back(s.surface(q.x(), q.y(), texture_at(spec, q.x(), q.y())));
    if (!c.closed) s.open = true;
    s.boundary.push_back(std::move(p));
  }
  if (s.boundary.empty()) throw Error("synthetic scan: the silhouette lies outside the domain; use a larger width/height");
  return s;
}

// --- picks -------------------------------------------------------------------------------
Picks Scan::picks(const PickSpec& ps) const {
  if (ps.count < (open ? 2 : 3)) throw Error("synthetic picks: count must be >= 3 (closed) or >= 2 (open)");
  if (!(ps.distance > 0)) throw Error("synthetic picks: distance must be > 0 (in units of h)");
  const double W = spec.width, H = spec.height;
  auto sd = [this](double u, double v) { return signed_distance(u, v); };

  // Far distance: the gap between the relief's bounding box and the domain edges it does not
  // touch, less a margin.
  double far = ps.far_distance * h;
  if (!(ps.far_distance > 0)) {
    double lo_u = 1e300, hi_u = -1e300, lo_v = 1e300, hi_v = -1e300;
    // bounding box in (u, v): re-trace coarsely (the 3D boundary is not in the parameter plane)
    for (const Curve2& c : trace_level(sd, -0.5 * W, -0.5 * H, W, H, nominal_edge / 2))
      for (const Vec2& q : c.points) {
        lo_u = std::min(lo_u, q.x()), hi_u = std::max(hi_u, q.x());
        lo_v = std::min(lo_v, q.y()), hi_v = std::max(hi_v, q.y());
      }
    double gap = 1e300;
    const double touch = nominal_edge;
    for (double g : {lo_u + 0.5 * W, 0.5 * W - hi_u, lo_v + 0.5 * H, 0.5 * H - hi_v})
      if (g > touch) gap = std::min(gap, g);
    far = gap - std::max(3 * nominal_edge, 0.05 * std::min(W, H));
  }
  const double near = ps.distance * h;
  if (ps.start != Start::Near && !(far > near))
    throw Error("synthetic picks: the far ring does not fit beyond the near one; use a smaller distance or a larger domain");

  const double level = ps.start == Start::Near ? near : far;
  auto f = [&](double u, double v) { return sd(u, v) - level; };
  const std::vector<Curve2> curves =
      trace_level(f, -0.5 * W, -0.5 * H, W, H, std::min(nominal_edge / 2, level / 4));
  const Curve2* ring = nullptr;
  for (const Curve2& c : curves)
    if (c.closed == !open && (!ring || c.length() > ring->length())) ring = &c;
  if (!ring)
    throw Error("synthetic picks: the ring at distance " + std::to_string(level) +
                " does not fit in the domain; use a smaller distance");
  const ArcLength arc(*ring);
  const double L = arc.length();

  auto gradient = [&](const Vec2& p) {
    const double e = 1e-4 * (1 + nominal_edge);
    Vec2 g((sd(p.x() + e, p.y()) - sd(p.x() - e, p.y())) / (2 * e), (sd(p.x(), p.y() + e) - sd(p.x(), p.y() - e)) / (2 * e));
    return g;
  };
  auto to_near = [&](Vec2 p) {  // down the distance gradient to the near level set
    for (int it = 0; it < 8; ++it) {
      const Vec2 g = gradient(p);
      const double gg = g.squaredNorm();
      if (gg < 1e-12) break;
      p -= (sd(p.x(), p.y()) - near) * g / gg;
    }
    return p;
  };

  struct Pick {
    double t;      // arc length on the ring
    Vec2 target;   // where it should be
    int vertex;
  };
  auto snap = [&](const Vec2& p, bool on_boundary) {
    if (!on_boundary) return nearest_vertex(p.x(), p.y());
    // Ends of an open ring lie on the domain edge: take the nearest mesh-boundary vertex.
    const int i0 = static_cast<int>(std::lround(grid_column(p.x())));
    const int j0 = static_cast<int>(std::lround(grid_row(p.y())));
    int best = -1;
    double best_d = 1e300;
    for (int j = std::max(0, j0 - 2); j <= std::min(grid_v - 1, j0 + 2); ++j)
      for (int i = std::max(0, i0 - 2); i <= std::min(grid_u - 1, i0 + 2); ++i) {
        if (i != 0 && j != 0 && i != grid_u - 1 && j != grid_v - 1) continue;
        const int k = j * grid_u + i;
        const double d = std::hypot(UV[2 * k] - p.x(), UV[2 * k + 1] - p.y());
        if (d < best_d) best_d = d, best = k;
      }
    return best;
  };
  std::vector<Pick> picks;
  const int n = ps.count;
  for (int k = 0; k < n; ++k) {
    const double t = open ? L * k / (n - 1) : L * k / n;
    Vec2 p = arc.at(t);
    if (ps.start == Start::Zigzag && k % 2 == 1) p = to_near(p);
    const bool end = open && (k == 0 || k == n - 1);
    picks.push_back({t, p, snap(p, end)});
  }
  // Insert picks (on the ring, halfway along the arc) where a straight chord between two
  // consecutive picks would come closer to the relief than half the near distance.
  auto clearance = [&](int a, int b) {
    const Vec2 pa(UV[2 * a], UV[2 * a + 1]), pb(UV[2 * b], UV[2 * b + 1]);
    const int steps = std::max(2, static_cast<int>(std::ceil((pb - pa).norm() / (0.25 * nominal_edge))));
    double m = 1e300;
    for (int i = 0; i <= steps; ++i) {
      const Vec2 q = pa + (pb - pa) * (static_cast<double>(i) / steps);
      m = std::min(m, sd(q.x(), q.y()));
    }
    return m;
  };
  for (std::size_t guard = 0;; ++guard) {
    if (guard > 64 * static_cast<std::size_t>(n)) throw Error("synthetic picks: could not place a clear ring; use a larger distance");
    bool inserted = false;
    const std::size_t m = picks.size();
    for (std::size_t i = 0; i < (open ? m - 1 : m); ++i) {
      const Pick& a = picks[i];
      const Pick& b = picks[(i + 1) % m];
      if (clearance(a.vertex, b.vertex) >= 0.5 * near) continue;
      double tb = b.t;
      if (tb <= a.t) tb += L;
      if (tb - a.t < 0.5 * nominal_edge)
        throw Error("synthetic picks: the ring comes too close to the relief; use a larger distance");
      const double t = 0.5 * (a.t + tb);
      const Vec2 p = arc.at(t);
      picks.insert(picks.begin() + i + 1, Pick{std::fmod(t, L), p, snap(p, false)});
      inserted = true;
      break;
    }
    if (!inserted) break;
  }

  Picks out;
  out.closed = !open;
  out.near_distance = near;
  out.far_distance = far;
  for (const Pick& p : picks)
    if (out.vertices.empty() || out.vertices.back() != p.vertex) out.vertices.push_back(p.vertex);
  if (!open && out.vertices.size() > 1 && out.vertices.front() == out.vertices.back()) out.vertices.pop_back();
  out.relief_side = ReliefSide::Left;  // traced with the relief (sd < level) on the left
  if (ps.reverse) {
    std::reverse(out.vertices.begin(), out.vertices.end());
    out.relief_side = ReliefSide::Right;
  }
  return out;
}

std::int64_t texture_feature_vertex(const Scan& scan, double u, double v) {
  const ScanSpec& sp = scan.spec;
  const double P = sp.texture_period * sp.h;
  if (sp.texture == Texture::Dots) {
    const std::int64_t ci = static_cast<std::int64_t>(std::floor(u / P)), cj = static_cast<std::int64_t>(std::floor(v / P));
    Vec2 best(u, v);
    double best_d = 1e300;
    for (std::int64_t j = cj - 1; j <= cj + 1; ++j)
      for (std::int64_t i = ci - 1; i <= ci + 1; ++i) {
        const Vec2 c = dot_center(sp, i, j);
        const double d = len2d(u - c.x(), v - c.y());
        if (d < best_d) best_d = d, best = c;
      }
    return scan.nearest_vertex(best.x(), best.y());
  }
  if (sp.texture == Texture::Striations) {
    // Crests where the phase is a quarter period; move across the ridges to the nearest one.
    const Vec2 dir(std::cos(sp.texture_angle), std::sin(sp.texture_angle));
    const double s = u * dir.x() + v * dir.y();
    const double crest = P * (std::round(s / P - 0.25) + 0.25);
    return scan.nearest_vertex(u + (crest - s) * dir.x(), v + (crest - s) * dir.y());
  }
  return -1;
}

// --- scoring -----------------------------------------------------------------------------
namespace {
double point_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0 ? clamp01((p - a).dot(ab) / l2) : 0;
  return (p - (a + t * ab)).norm();
}
constexpr int kBits = 21;
std::int64_t pack(std::int64_t x, std::int64_t y, std::int64_t z) { return (x << (2 * kBits)) | (y << kBits) | z; }
}  // namespace

PolylineDistance::PolylineDistance(const std::vector<Polyline>& polylines, double cell) {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  double total = 0;
  for (const Polyline& p : polylines) {
    const std::size_t n = p.points.size();
    if (n == 1) segments_.push_back({p.points[0], p.points[0]});
    const std::size_t m = n < 2 ? 0 : (p.closed ? n : n - 1);
    for (std::size_t i = 0; i < m; ++i) {
      segments_.push_back({p.points[i], p.points[(i + 1) % n]});
      total += (p.points[(i + 1) % n] - p.points[i]).norm();
    }
    for (const Vec3& x : p.points) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  }
  if (segments_.empty()) return;
  const double diag = (hi - lo).norm();
  cell_ = cell > 0 ? cell : std::max(2 * total / segments_.size(), diag / 200);
  // Keep packed coordinates within kBits per axis.
  cell_ = std::max({cell_, diag / ((1 << (kBits - 2)) - 4), 1e-12});
  origin_ = lo - Vec3::Constant(cell_);
  std::vector<std::pair<std::int64_t, int>> entries;
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    const Vec3 a = (segments_[s].first.cwiseMin(segments_[s].second) - origin_) / cell_;
    const Vec3 b = (segments_[s].first.cwiseMax(segments_[s].second) - origin_) / cell_;
    for (auto x = static_cast<std::int64_t>(a.x()); x <= static_cast<std::int64_t>(b.x()); ++x)
      for (auto y = static_cast<std::int64_t>(a.y()); y <= static_cast<std::int64_t>(b.y()); ++y)
        for (auto z = static_cast<std::int64_t>(a.z()); z <= static_cast<std::int64_t>(b.z()); ++z)
          entries.push_back({pack(x, y, z), static_cast<int>(s)});
  }
  std::sort(entries.begin(), entries.end());
  keys_.reserve(entries.size());
  entries_.reserve(entries.size());
  for (const auto& e : entries) keys_.push_back(e.first), entries_.push_back(e.second);
  max_ring_ = 6;
}

double PolylineDistance::operator()(const Vec3& p) const {
  if (segments_.empty()) return std::numeric_limits<double>::infinity();
  const Vec3 c = (p - origin_) / cell_;
  const std::int64_t limit = (1LL << kBits) - 1;
  const std::int64_t cx = static_cast<std::int64_t>(std::floor(c.x()));
  const std::int64_t cy = static_cast<std::int64_t>(std::floor(c.y()));
  const std::int64_t cz = static_cast<std::int64_t>(std::floor(c.z()));
  double best = std::numeric_limits<double>::infinity();
  auto visit = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    if (x < 0 || y < 0 || z < 0 || x > limit || y > limit || z > limit) return;
    const std::int64_t key = pack(x, y, z);
    auto range = std::equal_range(keys_.begin(), keys_.end(), key);
    for (auto it = range.first; it != range.second; ++it) {
      const auto& s = segments_[entries_[it - keys_.begin()]];
      best = std::min(best, point_segment(p, s.first, s.second));
    }
  };
  for (int r = 0; r <= max_ring_; ++r) {
    // the shell of cells at Chebyshev distance r from p's cell
    for (std::int64_t x = cx - r; x <= cx + r; ++x)
      for (std::int64_t y = cy - r; y <= cy + r; ++y) {
        const bool edge_xy = (x == cx - r || x == cx + r || y == cy - r || y == cy + r);
        if (edge_xy) {
          for (std::int64_t z = cz - r; z <= cz + r; ++z) visit(x, y, z);
        } else {
          visit(x, y, cz - r);
          if (r > 0) visit(x, y, cz + r);
        }
      }
    // anything not yet visited lies at least r cells away
    if (best <= r * cell_) return best;
  }
  // Far from the polylines: brute force.
  for (const auto& s : segments_) best = std::min(best, point_segment(p, s.first, s.second));
  return best;
}

bool PolylineDistance::within(const Vec3& p, double r) const {
  if (segments_.empty()) return false;
  const Vec3 c = (p - origin_) / cell_;
  const std::int64_t limit = (1LL << kBits) - 1;
  const std::int64_t reach = static_cast<std::int64_t>(std::ceil(r / cell_));
  const std::int64_t cx = static_cast<std::int64_t>(std::floor(c.x()));
  const std::int64_t cy = static_cast<std::int64_t>(std::floor(c.y()));
  const std::int64_t cz = static_cast<std::int64_t>(std::floor(c.z()));
  for (std::int64_t x = std::max<std::int64_t>(0, cx - reach); x <= std::min(limit, cx + reach); ++x)
    for (std::int64_t y = std::max<std::int64_t>(0, cy - reach); y <= std::min(limit, cy + reach); ++y)
      for (std::int64_t z = std::max<std::int64_t>(0, cz - reach); z <= std::min(limit, cz + reach); ++z) {
        auto range = std::equal_range(keys_.begin(), keys_.end(), pack(x, y, z));
        for (auto it = range.first; it != range.second; ++it) {
          const auto& s = segments_[entries_[it - keys_.begin()]];
          if (point_segment(p, s.first, s.second) <= r) return true;
        }
      }
  return false;
}

std::vector<Vec3> resample(const Polyline& polyline, double step) {
  std::vector<Vec3> out;
  const auto& pts = polyline.points;
  const std::size_t n = pts.size();
  if (n == 0) return out;
  out.push_back(pts[0]);
  const std::size_t m = n < 2 ? 0 : (polyline.closed ? n : n - 1);
  for (std::size_t i = 0; i < m; ++i) {
    const Vec3& a = pts[i];
    const Vec3& b = pts[(i + 1) % n];
    const int k = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int j = 1; j <= k; ++j) {
      if (polyline.closed && i + 1 == m && j == k) break;  // back at the start
      out.push_back(a + (b - a) * (static_cast<double>(j) / k));
    }
  }
  return out;
}

Score score(const Polyline& contour, const std::vector<std::int64_t>& relief_vertices,
            const std::vector<Polyline>& truth_boundary, const std::vector<std::int64_t>& truth_relief,
            double average_edge) {
  if (contour.points.empty()) throw Error("score: the contour is empty; pass the result's polyline");
  if (!(average_edge > 0)) throw Error("score: average_edge must be > 0");
  Score s;
  std::vector<std::int64_t> a = relief_vertices, b = truth_relief;
  std::sort(a.begin(), a.end());
  a.erase(std::unique(a.begin(), a.end()), a.end());
  std::sort(b.begin(), b.end());
  b.erase(std::unique(b.begin(), b.end()), b.end());
  std::vector<std::int64_t> common;
  std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(common));
  s.result_vertices = a.size();
  s.truth_vertices = b.size();
  s.common_vertices = common.size();
  const std::size_t uni = a.size() + b.size() - common.size();
  s.iou = uni == 0 ? 1.0 : static_cast<double>(common.size()) / uni;

  const double step = average_edge / 4;
  auto stats = [&](const std::vector<Vec3>& points, const PolylineDistance& to, double* mean, double* p95, double* mx) {
    std::vector<double> d;
    d.reserve(points.size());
    for (const Vec3& p : points) d.push_back(to(p) / average_edge);
    if (d.empty()) return;
    double sum = 0;
    for (double x : d) sum += x;
    *mean = sum / d.size();
    *mx = *std::max_element(d.begin(), d.end());
    const std::size_t k = static_cast<std::size_t>(std::ceil(0.95 * d.size())) - 1;
    std::nth_element(d.begin(), d.begin() + k, d.end());
    *p95 = d[k];
  };
  const PolylineDistance to_truth(truth_boundary);
  stats(resample(contour, step), to_truth, &s.mean_to_truth, &s.p95_to_truth, &s.max_to_truth);
  const PolylineDistance to_contour({contour});
  std::vector<Vec3> truth_points;
  for (const Polyline& p : truth_boundary) {
    const auto r = resample(p, step);
    truth_points.insert(truth_points.end(), r.begin(), r.end());
  }
  stats(truth_points, to_contour, &s.mean_from_truth, &s.p95_from_truth, &s.max_from_truth);
  return s;
}

// --- files -------------------------------------------------------------------------------
void write_ply(const Scan& scan, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw Error("cannot write " + path + ": check that the folder exists and is writable");
  const std::uint16_t probe = 1;
  unsigned char first;
  std::memcpy(&first, &probe, 1);
  if (first != 1) throw Error("write_ply: big-endian hosts are not supported; write OBJ instead");
  out << "ply\nformat binary_little_endian 1.0\ncomment relief-snake synthetic scan\n"
      << "element vertex " << scan.n_vertices() << "\nproperty float x\nproperty float y\nproperty float z\n"
      << "element face " << scan.n_faces() << "\nproperty list uchar int vertex_indices\nend_header\n";
  std::vector<float> v(scan.V.begin(), scan.V.end());
  out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(float)));
  std::vector<char> faces(scan.n_faces() * 13);
  for (std::size_t f = 0; f < scan.n_faces(); ++f) {
    char* p = &faces[13 * f];
    p[0] = 3;
    for (int k = 0; k < 3; ++k) {
      const std::int32_t idx = static_cast<std::int32_t>(scan.F[3 * f + k]);
      std::memcpy(p + 1 + 4 * k, &idx, 4);
    }
  }
  out.write(faces.data(), static_cast<std::streamsize>(faces.size()));
  if (!out) throw Error("failed writing " + path + ": check free disk space");
}

void write_obj(const Scan& scan, const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file) throw Error("cannot write " + path + ": check that the folder exists and is writable");
  std::fprintf(file, "# relief-snake synthetic scan\n");
  for (std::size_t v = 0; v < scan.n_vertices(); ++v)
    std::fprintf(file, "v %.17g %.17g %.17g\n", scan.V[3 * v], scan.V[3 * v + 1], scan.V[3 * v + 2]);
  for (std::size_t f = 0; f < scan.n_faces(); ++f)
    std::fprintf(file, "f %lld %lld %lld\n", static_cast<long long>(scan.F[3 * f] + 1),
                 static_cast<long long>(scan.F[3 * f + 1] + 1), static_cast<long long>(scan.F[3 * f + 2] + 1));
  const bool ok = std::ferror(file) == 0;
  std::fclose(file);
  if (!ok) throw Error("failed writing " + path + ": check free disk space");
}

void write_truth_json(const Scan& scan, const Picks& picks, const std::string& path) {
  const nlohmann::json j = truth_json(scan, picks);
  std::ofstream out(path);
  if (!out) throw Error("cannot write " + path + ": check that the folder exists and is writable");
  out << j.dump() << "\n";
  if (!out) throw Error("failed writing " + path + ": check free disk space");
}

void write_json(const nlohmann::json& j, const std::string& path) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw Error("cannot write " + tmp + ": check that the folder exists and is writable");
    out << j.dump() << "\n";
    if (!out) throw Error("failed writing " + tmp + ": check free disk space");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw Error("cannot rename " + tmp + " to " + path);
}

nlohmann::json truth_json(const Scan& scan, const Picks& picks) {
  nlohmann::json j;
  const ScanSpec& sp = scan.spec;
  j["h"] = scan.h;
  j["average_edge"] = scan.average_edge;
  j["nominal_edge"] = scan.nominal_edge;
  j["triangles"] = scan.n_faces();
  j["vertices"] = scan.n_vertices();
  j["relief_vertices"] = scan.relief_vertices();
  nlohmann::json boundary = nlohmann::json::array(), closed = nlohmann::json::array();
  for (const Polyline& p : scan.boundary) {
    nlohmann::json line = nlohmann::json::array();
    for (const Vec3& x : p.points) line.push_back({x.x(), x.y(), x.z()});
    boundary.push_back(std::move(line));
    closed.push_back(p.closed);
  }
  j["boundary"] = std::move(boundary);
  j["boundary_closed"] = std::move(closed);
  j["picks"] = picks.vertices;
  j["picks_closed"] = picks.closed;
  j["open"] = scan.open;
  j["relief_side"] = picks.relief_side == ReliefSide::Left ? "left" : "right";
  j["near_distance"] = picks.near_distance;
  j["far_distance"] = picks.far_distance;
  if (sp.shape == Shape::Slots) {
    // Per slot: where it is and the mesh vertices inside it (the background the snake
    // uncovers if it enters the slot; they are not relief vertices).
    nlohmann::json slots = nlohmann::json::array();
    const double depth = sp.slot_depth * sp.h;
    for (std::size_t k = 0; k + 1 < scan.slots.size(); k += 2) {
      const double center = scan.slots[k], width = scan.slots[k + 1];
      std::vector<std::int64_t> inside;
      for (std::size_t v = 0; v < scan.n_vertices(); ++v) {
        const double u = scan.UV[2 * v], w = scan.UV[2 * v + 1];
        if (std::abs(u - center) < 0.5 * width && w > kSlotsHalfV - depth && w < kSlotsHalfV)
          inside.push_back(static_cast<std::int64_t>(v));
      }
      slots.push_back({{"center_u", center},
                       {"width", width},
                       {"width_edges", k / 2 < sp.slot_widths.size() ? sp.slot_widths[k / 2] : 0.0},
                       {"depth", depth},
                       {"vertices", inside}});
    }
    j["slots"] = std::move(slots);
  }
  j["spec"] = {{"shape", to_string(sp.shape)},      {"background", to_string(sp.background)},
               {"triangles", sp.triangles},         {"h", sp.h},
               {"width", sp.width},                 {"height", sp.height},
               {"radius", sp.radius},               {"step", to_string(sp.step)},
               {"blend_width", sp.blend_width},     {"detail", sp.detail},
               {"drop", sp.drop},                   {"noise", sp.noise},
               {"jitter", sp.jitter},               {"slot_widths", sp.slot_widths},
               {"slot_depth", sp.slot_depth},       {"seed", sp.seed}};
  return j;
}

}  // namespace synthetic
}  // namespace relief_snake

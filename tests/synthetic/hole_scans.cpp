// Shapes with holes and the band round a surface of revolution (issue 13), see hole_scans.hpp.
#include "hole_scans.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <unordered_set>

#include "relief_snake/error.hpp"

namespace relief_snake {
namespace synthetic {

namespace {

double box(double x, double y, double x0, double x1, double y0, double y1) {
  const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1), hx = 0.5 * (x1 - x0), hy = 0.5 * (y1 - y0);
  const double dx = std::abs(x - cx) - hx, dy = std::abs(y - cy) - hy;
  return std::hypot(std::max(dx, 0.0), std::max(dy, 0.0)) + std::min(std::max(dx, dy), 0.0);
}

std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}
double uniform(std::uint64_t seed, std::uint64_t stream, std::uint64_t k) {
  return (mix(mix(seed * 0x100000001b3ull + stream) ^ k) >> 11) * (1.0 / 9007199254740992.0);
}
double gauss(std::uint64_t seed, std::uint64_t stream, std::uint64_t k) {
  const double u1 = std::max(uniform(seed, stream, 2 * k), 1e-300), u2 = uniform(seed, stream, 2 * k + 1);
  return std::sqrt(-2 * std::log(u1)) * std::cos(2 * M_PI * u2);
}
double smooth(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

// The tube's geometry.
struct Tube {
  TubeSpec spec;
  double circumference() const { return 2 * M_PI * spec.radius; }
  double lo(double u) const { return -spec.half_width + spec.wave * std::sin(spec.waves * u / spec.radius + spec.phase); }
  double hi(double u) const {
    return spec.half_width + spec.wave * std::sin(spec.waves * u / spec.radius + spec.phase + 1);
  }
  // Negative inside the band; the distance across each edge (its slope taken out).
  double sd(double u, double v) const {
    const double k = spec.waves / spec.radius;
    const double slope_lo = spec.wave * k * std::cos(k * u + spec.phase);
    const double slope_hi = spec.wave * k * std::cos(k * u + spec.phase + 1);
    return std::max((lo(u) - v) / std::sqrt(1 + slope_lo * slope_lo), (v - hi(u)) / std::sqrt(1 + slope_hi * slope_hi));
  }
  double rho(double v) const {
    return spec.radius * (1 + spec.vase_amplitude * std::sin(2 * M_PI * v / spec.vase_period));
  }
  Vec3 normal(double u, double v) const {
    const double k = 2 * M_PI / spec.vase_period;
    const double drho = spec.radius * spec.vase_amplitude * k * std::cos(k * v);
    const double a = u / spec.radius;
    return Vec3(std::sin(a), -drho, std::cos(a)).normalized();
  }
  Vec3 surface(double u, double v, double height) const {
    const double a = u / spec.radius, r = rho(v);
    return Vec3(r * std::sin(a), v, r * std::cos(a)) + height * normal(u, v);
  }
};

}  // namespace

double holed_shape_distance(const ScanSpec& spec, double u, double v) {
  if (spec.shape == Shape::Ring) return std::abs(std::hypot(u, v) - spec.c_radius) - spec.c_half_thickness;
  const double X = spec.letter_half_u, Y = spec.letter_half_v, w = spec.stroke_width;
  const double left = box(u, v, -X, -X + w, -Y, Y), right = box(u, v, X - w, X, -Y, Y);
  const double top = box(u, v, -X, X, Y - w, Y), bottom = box(u, v, -X, X, -Y, -Y + w);
  switch (spec.letter) {
    case 'O': return std::min({left, right, top, bottom});
    // Strokes overlap by half a stroke where they join: boxes that only touch along an edge
    // leave a crack of height 0 there (sd = 0), a groove after blending.
    case 'D':  // the O with its right corners cut in
      return std::min({left, box(u, v, -X, X - 0.5 * w, Y - w, Y), box(u, v, -X, X - 0.5 * w, -Y, -Y + w),
                       box(u, v, X - w, X, -Y + 0.5 * w, Y - 0.5 * w)});
    case 'A': return std::min({left, right, top, box(u, v, -X, X, -0.5 * w, 0.5 * w)});
    case 'B': {
      const double bar = box(u, v, -X, X - 0.5 * w, -0.5 * w, 0.5 * w);  // a notch at the right middle
      return std::min({left, top, bottom, bar, box(u, v, X - w, X, 0.2 * w, Y), box(u, v, X - w, X, -Y, -0.2 * w)});
    }
    default: throw Error("synthetic scan: holed-letter needs letter O, D, A or B");
  }
}

std::vector<Polyline> hole_boundaries(const Scan& scan) {
  std::size_t outer = scan.boundary.size();
  double longest = -1;
  for (std::size_t k = 0; k < scan.boundary.size(); ++k) {
    const Polyline& p = scan.boundary[k];
    if (!p.closed) continue;
    double length = 0;
    for (std::size_t i = 0; i < p.points.size(); ++i) length += (p.points[(i + 1) % p.points.size()] - p.points[i]).norm();
    if (length > longest) longest = length, outer = k;
  }
  std::vector<Polyline> holes;
  for (std::size_t k = 0; k < scan.boundary.size(); ++k)
    if (k != outer && scan.boundary[k].closed) holes.push_back(scan.boundary[k]);
  return holes;
}

Scan generate_tube(const TubeSpec& ts) {
  if (!(ts.radius > 0) || !(ts.length > 0)) throw Error("synthetic tube: radius and length must be > 0");
  if (!(std::abs(ts.vase_amplitude) < 0.5) || !(ts.vase_period > 0))
    throw Error("synthetic tube: the vase needs |amplitude| < 0.5 and a period > 0");
  if (!(ts.h != 0) || !(ts.half_width > 0) || ts.half_width + std::abs(ts.wave) + 6 * std::abs(ts.h) > 0.5 * ts.length)
    throw Error("synthetic tube: the band (half width + wave + 6 |h|) must fit in half the length");
  if (ts.triangles < 1000 || ts.triangles > 20000000) throw Error("synthetic tube: triangles must be 1000 .. 20M");
  if (!(ts.jitter >= 0 && ts.jitter < 0.35)) throw Error("synthetic tube: jitter must be in [0, 0.35)");
  const Tube tube{ts};
  const double C = tube.circumference(), L = ts.length, depth = std::abs(ts.h), sign = ts.h > 0 ? 1.0 : -1.0;
  const std::int64_t cells_u = std::max<std::int64_t>(8, std::llround(std::sqrt(0.5 * ts.triangles * C / L)));
  const std::int64_t cells_v = std::max<std::int64_t>(2, std::llround(0.5 * ts.triangles / cells_u));
  Scan s;
  s.spec.background = ts.vase_amplitude != 0 ? Background::Vase : Background::Cylinder;
  s.spec.radius = ts.radius;
  s.spec.h = depth;
  s.spec.triangles = ts.triangles;
  s.spec.seed = ts.seed;
  s.spec.step = ts.step;
  s.h = depth;
  s.grid_u = static_cast<int>(cells_u);  // periodic: column cells_u is column 0
  s.grid_v = static_cast<int>(cells_v + 1);
  s.spacing_u = C / cells_u;
  s.spacing_v = L / cells_v;
  const std::size_t nv = static_cast<std::size_t>(s.grid_u) * s.grid_v;
  s.UV.resize(2 * nv);
  s.V.resize(3 * nv);
  s.relief.resize(nv);
  s.relief_height.resize(nv);
  s.texture_height.assign(nv, 0.0);
  s.noise_height.assign(nv, 0.0);
  for (int j = 0; j < s.grid_v; ++j)
    for (int i = 0; i < s.grid_u; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * s.grid_u + i;
      const double r = ts.jitter * std::sqrt(uniform(ts.seed, 1, k)), angle = 2 * M_PI * uniform(ts.seed, 2, k);
      double du = r * std::cos(angle) * s.spacing_u, dv = r * std::sin(angle) * s.spacing_v;
      if (j == 0 || j + 1 == s.grid_v) dv = 0;
      const double u = i * s.spacing_u + du, v = -0.5 * L + j * s.spacing_v + dv;
      s.UV[2 * k] = u, s.UV[2 * k + 1] = v;
      const double sd = tube.sd(u, v);
      s.relief[k] = sd < 0;
      double height = 0;
      if (sd < 0) height = sign * depth * (ts.step == Step::Sharp ? 1.0 : smooth(-sd / (ts.blend_width * depth)));
      s.relief_height[k] = height;
      if (ts.noise > 0) {
        s.noise_height[k] = ts.noise * depth * gauss(ts.seed, 3, k);
        height += s.noise_height[k];
      }
      const Vec3 p = tube.surface(u, v, height);
      s.V[3 * k] = p.x(), s.V[3 * k + 1] = p.y(), s.V[3 * k + 2] = p.z();
    }
  auto index = [&](std::int64_t i, std::int64_t j) { return j * s.grid_u + (i % s.grid_u); };
  for (std::int64_t j = 0; j < cells_v; ++j)
    for (std::int64_t i = 0; i < cells_u; ++i) {
      const std::int64_t a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1), d = index(i, j + 1);
      if ((i + j) % 2 == 0) s.F.insert(s.F.end(), {a, b, c, a, c, d});
      else s.F.insert(s.F.end(), {a, b, d, b, c, d});
    }
  std::unordered_set<std::uint64_t> seen;
  double sum = 0;
  for (std::size_t f = 0; f < s.n_faces(); ++f)
    for (int e = 0; e < 3; ++e) {
      const std::int64_t a = s.F[3 * f + e], b = s.F[3 * f + (e + 1) % 3];
      const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint64_t>(std::max(a, b));
      if (seen.insert(key).second) sum += (s.vertex(a) - s.vertex(b)).norm();
    }
  s.average_edge = sum / static_cast<double>(seen.size());
  s.nominal_edge = s.average_edge;
  // The two band edges, dense, each right round (relief on the left seen from outside: the lower
  // edge runs with increasing u, the upper one against it). A frieze's at the foot of its wall
  // (height 0); a groove's at the foot of its wall too, on the floor (height -|h|), where a contour
  // approaching the wall from the floor settles.
  const double foot = ts.h > 0 ? 0.0 : -depth;
  const int samples = static_cast<int>(std::ceil(C / (s.average_edge / 8)));
  Polyline lower, upper;
  for (int k = 0; k < samples; ++k) {
    const double u = C * k / samples;
    lower.points.push_back(tube.surface(u, tube.lo(u), foot));
    const double ub = C * (samples - k) / samples;
    upper.points.push_back(tube.surface(ub, tube.hi(ub), foot));
  }
  s.boundary = {lower, upper};
  return s;
}

TubePicks tube_picks(const Scan& scan, const TubeSpec& spec, int count, double distance) {
  if (count < 3) throw Error("synthetic tube picks: count must be >= 3");
  const Tube tube{spec};
  const double C = tube.circumference(), depth = std::abs(spec.h);
  // A frieze: on the background beside it; engraved: on the groove's floor, near each wall.
  const double offset = spec.h > 0 ? spec.half_width + std::abs(spec.wave) + distance * depth
                                   : spec.half_width - std::abs(spec.wave) - distance * depth;
  if (!(offset > 0)) throw Error("synthetic tube picks: the groove is too narrow for rings on its floor");
  const double v_first = -offset, v_second = offset;
  auto nearest = [&](double u, double v) {
    const int i0 = static_cast<int>(std::lround(u / scan.spacing_u));
    const int j0 = static_cast<int>(std::lround((v + 0.5 * spec.length) / scan.spacing_v));
    std::int64_t best = -1;
    double best_d = 1e300;
    for (int j = std::max(0, j0 - 2); j <= std::min(scan.grid_v - 1, j0 + 2); ++j)
      for (int di = -2; di <= 2; ++di) {
        const int i = ((i0 + di) % scan.grid_u + scan.grid_u) % scan.grid_u;
        const std::int64_t k = static_cast<std::int64_t>(j) * scan.grid_u + i;
        double du = std::abs(scan.UV[2 * k] - u);
        du = std::min(du, C - du);
        const double d = std::hypot(du, scan.UV[2 * k + 1] - v);
        if (d < best_d) best_d = d, best = k;
      }
    return best;
  };
  TubePicks picks;
  for (int k = 0; k < count; ++k) {
    const double u = C * k / count;
    picks.first.push_back(nearest(u, v_first));
    picks.second.push_back(nearest(u, v_second));
  }
  return picks;
}

ContourMatch match_contour(const std::vector<Vec3>& contour, const Polyline& truth, double average_edge) {
  ContourMatch m;
  if (contour.empty() || truth.points.empty()) return m;
  const PolylineDistance to_truth({truth});
  Polyline result;
  result.points = contour;
  result.closed = true;
  const PolylineDistance to_result({result});
  const std::vector<Vec3> a = resample(result, average_edge / 4), b = resample(truth, average_edge / 4);
  for (const Vec3& p : a) {
    const double d = to_truth(p) / average_edge;
    m.mean_to_truth += d, m.max_to_truth = std::max(m.max_to_truth, d);
  }
  for (const Vec3& p : b) {
    const double d = to_result(p) / average_edge;
    m.mean_from_truth += d, m.max_from_truth = std::max(m.max_from_truth, d);
  }
  m.mean_to_truth /= static_cast<double>(a.size());
  m.mean_from_truth /= static_cast<double>(b.size());
  return m;
}

std::size_t nearest_polyline(const std::vector<Vec3>& contour, const std::vector<Polyline>& candidates) {
  std::size_t best = 0;
  double best_d = 1e300;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const PolylineDistance d({candidates[k]});
    double sum = 0;
    for (const Vec3& p : contour) sum += d(p);
    if (sum < best_d) best_d = sum, best = k;
  }
  return best;
}

void add_hole_truth(const Scan& scan, nlohmann::json* truth) {
  nlohmann::json holes = nlohmann::json::array();
  for (const Polyline& p : hole_boundaries(scan)) {
    nlohmann::json line = nlohmann::json::array();
    for (const Vec3& q : p.points) line.push_back({q.x(), q.y(), q.z()});
    holes.push_back(std::move(line));
  }
  (*truth)["holes"] = std::move(holes);
}

int tube_command(const std::vector<std::string>& args) {
  TubeSpec spec;
  int count = 12;
  double distance = 3;
  std::string out;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw Error(a + " needs a value (see make-scan --help)");
      return args[++i];
    };
    try {
      if (a == "--radius") spec.radius = std::stod(value());
      else if (a == "--length") spec.length = std::stod(value());
      else if (a == "--vase") spec.vase_amplitude = std::stod(value());
      else if (a == "--half-width") spec.half_width = std::stod(value());
      else if (a == "--wave") spec.wave = std::stod(value());
      else if (a == "--waves") spec.waves = std::stoi(value());
      else if (a == "--phase") spec.phase = std::stod(value());
      else if (a == "--h") spec.h = std::stod(value());
      else if (a == "--step") spec.step = parse_step(value());
      else if (a == "--blend-width") spec.blend_width = std::stod(value());
      else if (a == "--noise") spec.noise = std::stod(value());
      else if (a == "--jitter") spec.jitter = std::stod(value());
      else if (a == "--triangles") spec.triangles = std::stoull(value());
      else if (a == "--seed") spec.seed = std::stoull(value());
      else if (a == "--picks") count = std::stoi(value());
      else if (a == "--distance") distance = std::stod(value());
      else if (a == "--out") out = value();
      else throw Error("unknown tube option " + a + " (see make-scan --help)");
    } catch (const std::logic_error&) {
      throw Error("bad value for " + a + ": give a number (see make-scan --help)");
    }
  }
  if (out.empty()) throw Error("tube needs --out PREFIX (writes PREFIX.ply and PREFIX.truth.json)");
  const Scan scan = generate_tube(spec);
  const TubePicks picks = tube_picks(scan, spec, count, distance);
  Picks first;
  first.vertices = picks.first;
  nlohmann::json truth = truth_json(scan, first);
  truth["band_picks"] = picks.second;
  truth["engraved"] = spec.h < 0;
  const std::string mesh_path = out + ".ply", truth_path = out + ".truth.json";
  write_ply(scan, mesh_path);
  write_json(truth, truth_path);
  std::cout << nlohmann::json{{"mesh", mesh_path},
                              {"truth", truth_path},
                              {"triangles", scan.n_faces()},
                              {"vertices", scan.n_vertices()},
                              {"average_edge", scan.average_edge},
                              {"h", scan.h}}
                   .dump()
            << std::endl;
  return 0;
}

}  // namespace synthetic
}  // namespace relief_snake

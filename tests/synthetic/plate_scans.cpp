// Plates with several reliefs and their truth (plate_scans.hpp).
#include "plate_scans.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "relief_snake/error.hpp"

namespace relief_snake {
namespace synthetic {
namespace {

double smooth01(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

// Standard normal from the raw output of mt19937_64 (fixed by the C++ standard, unlike
// std::normal_distribution).
struct Normal {
  std::mt19937_64 engine;
  explicit Normal(std::uint64_t seed) : engine(seed * 0x9e3779b97f4a7c15ULL + 17) {}
  double uniform() { return (static_cast<double>(engine() >> 11) + 0.5) * (1.0 / 9007199254740992.0); }
  double operator()() { return std::sqrt(-2 * std::log(uniform())) * std::cos(2 * M_PI * uniform()); }
};

const char* shape_name(PlateShape s) {
  switch (s) {
    case PlateShape::Disk: return "disk";
    case PlateShape::Ellipse: return "ellipse";
    case PlateShape::Box: return "box";
  }
  return "?";
}

}  // namespace

double PlateRelief::signed_distance(double u, double v) const {
  const double du = u - center_u, dv = v - center_v;
  const double c = std::cos(rotation), s = std::sin(rotation);
  const double x = c * du + s * dv, y = -s * du + c * dv;
  switch (shape) {
    case PlateShape::Disk: return std::sqrt(du * du + dv * dv) - size_u;
    case PlateShape::Ellipse: {
      const double k = std::sqrt((x / size_u) * (x / size_u) + (y / size_v) * (y / size_v));
      return (k - 1) * std::min(size_u, size_v);
    }
    case PlateShape::Box: {
      const double r = std::min(corner, std::min(size_u, size_v));
      const double qx = std::fabs(x) - size_u + r, qy = std::fabs(y) - size_v + r;
      const double ox = std::max(qx, 0.0), oy = std::max(qy, 0.0);
      return std::sqrt(ox * ox + oy * oy) + std::min(std::max(qx, qy), 0.0) - r;
    }
  }
  return 1;
}

std::vector<PlateRelief> random_plate_layout(std::uint64_t seed, double width, double height) {
  std::mt19937_64 rng(seed * 0x2545f4914f6cdd1dULL + 99);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * (static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0)); };
  auto fits = [&](const std::vector<PlateRelief>& placed, const PlateRelief& r, double reach) {
    const double margin = 4;
    if (std::fabs(r.center_u) + reach > 0.5 * width - margin || std::fabs(r.center_v) + reach > 0.5 * height - margin)
      return false;
    for (const PlateRelief& p : placed) {
      const double pr = std::max(p.size_u, p.size_v) * (p.shape == PlateShape::Box ? std::sqrt(2.0) : 1.0) +
                        (p.touches >= 0 ? 2 * p.size_u : 0);
      const double gap = std::max(6.0, 3 * std::max(p.h, r.h));
      if (std::hypot(r.center_u - p.center_u, r.center_v - p.center_v) < pr + reach + gap) return false;
    }
    return true;
  };
  std::vector<PlateRelief> out;
  // The touching pair: a box, and a box of another height sharing its right side.
  for (int attempt = 0; attempt < 200 && out.empty(); ++attempt) {
    PlateRelief a, b;
    a.shape = b.shape = PlateShape::Box;
    a.size_u = uniform(4, 7), a.size_v = uniform(4, 7);
    b.size_u = uniform(4, 7), b.size_v = a.size_v;
    a.h = uniform(0.6, 1.2);
    b.h = a.h * uniform(1.6, 2.2);
    if (rng() & 1) std::swap(a.h, b.h);
    a.center_u = uniform(-0.5 * width + 10, 0.5 * width - 10 - 2 * b.size_u);
    a.center_v = uniform(-0.5 * height + 10, 0.5 * height - 10);
    b.center_u = a.center_u + a.size_u + b.size_u, b.center_v = a.center_v;
    const double reach = std::hypot(a.size_u + 2 * b.size_u, a.size_v);
    PlateRelief probe = a;
    probe.center_u = a.center_u + b.size_u;
    if (!fits(out, probe, reach)) continue;
    a.touches = 1, b.touches = 0;
    out.push_back(a);
    out.push_back(b);
  }
  const int others = 1 + static_cast<int>(rng() % 3);
  for (int k = 0, attempt = 0; k < others && attempt < 500; ++attempt) {
    PlateRelief r;
    const int kind = static_cast<int>(rng() % 3);
    r.shape = kind == 0 ? PlateShape::Disk : kind == 1 ? PlateShape::Ellipse : PlateShape::Box;
    r.size_u = uniform(4, 9);
    r.size_v = r.shape == PlateShape::Disk ? r.size_u : uniform(4, 9);
    r.rotation = r.shape == PlateShape::Disk ? 0 : uniform(0, M_PI);
    r.corner = r.shape == PlateShape::Box ? uniform(0, 3) : 0;
    r.h = uniform(0.6, 2.0);
    r.center_u = uniform(-0.5 * width, 0.5 * width), r.center_v = uniform(-0.5 * height, 0.5 * height);
    const double reach = std::max(r.size_u, r.size_v) * (r.shape == PlateShape::Box ? std::sqrt(2.0) : 1.0);
    if (!fits(out, r, reach)) continue;
    out.push_back(r);
    ++k;
  }
  for (int attempt = 0; attempt < 500; ++attempt) {
    PlateRelief small;
    small.size_u = small.size_v = 1.5;
    small.h = 1;
    small.center_u = uniform(-0.5 * width, 0.5 * width), small.center_v = uniform(-0.5 * height, 0.5 * height);
    if (!fits(out, small, small.size_u)) continue;
    out.push_back(small);
    break;
  }
  return out;
}

PlateScan generate_plate(const PlateSpec& spec) {
  if (!(spec.noise >= 0) || !(spec.blend_width > 0)) throw Error("plate: noise must be >= 0 and blend_width > 0");
  for (const PlateRelief& r : spec.reliefs)
    if (!(r.h > 0) || !(r.size_u > 0) || !(r.size_v > 0)) throw Error("plate: every relief needs h > 0 and sizes > 0");
  ScanSpec base;
  base.shape = Shape::Disk;
  base.background = spec.background;
  base.radius = spec.radius;
  base.triangles = spec.triangles;
  base.width = spec.width, base.height = spec.height;
  base.jitter = spec.jitter;
  base.seed = spec.seed;
  PlateScan plate;
  plate.spec = spec;
  plate.scan = generate(base);
  Scan& s = plate.scan;
  const std::size_t nv = s.n_vertices();
  Normal normal(spec.seed);
  plate.truth.assign(spec.reliefs.size(), {});
  for (std::size_t k = 0; k < nv; ++k) {
    const double u = s.UV[2 * k], v = s.UV[2 * k + 1];
    double height = 0;
    for (std::size_t r = 0; r < spec.reliefs.size(); ++r) {
      const PlateRelief& relief = spec.reliefs[r];
      double sd = relief.signed_distance(u, v);
      if (sd < 0) plate.truth[r].push_back(static_cast<std::int64_t>(k));
      // The lower of two touching reliefs runs on under the taller one: a step of the difference
      // of their heights separates them (not a groove down to the background).
      if (relief.touches >= 0 && relief.h < spec.reliefs[relief.touches].h)
        sd = std::min(sd, spec.reliefs[relief.touches].signed_distance(u, v));
      if (sd >= 0) continue;
      const double rise = spec.step == Step::Sharp ? 1.0 : smooth01(-sd / (spec.blend_width * relief.h));
      height = std::max(height, relief.h * rise);
    }
    s.relief_height[k] = height;
    s.relief[k] = height > 0;
    s.texture_height[k] = 0;
    s.noise_height[k] = spec.noise > 0 ? spec.noise * normal() : 0;
    const Vec3 p = s.surface(u, v, height + s.noise_height[k]);
    s.V[3 * k] = p.x(), s.V[3 * k + 1] = p.y(), s.V[3 * k + 2] = p.z();
  }
  // The average edge of the plate's own geometry (the reliefs' walls lengthen some edges).
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t f = 0; f < s.n_faces(); ++f)
    for (int c = 0; c < 3; ++c) {
      const std::int64_t a = s.F[3 * f + c], b = s.F[3 * f + (c + 1) % 3];
      sum += (s.vertex(a) - s.vertex(b)).norm();
      ++count;
    }
  s.average_edge = count ? sum / count : 0;  // interior edges counted twice, boundary ones once: close enough
  const Mesh mesh = to_mesh(s);
  for (const auto& t : plate.truth) {
    double a = 0;
    for (const std::int64_t i : t) a += mesh.vertex_area(mesh.input_to_mesh(static_cast<std::size_t>(i)));
    plate.truth_area.push_back(a);
  }
  s.average_edge = mesh.average_edge_length();
  return plate;
}

nlohmann::json plate_truth_json(const PlateScan& plate) {
  nlohmann::json reliefs = nlohmann::json::array();
  for (std::size_t r = 0; r < plate.spec.reliefs.size(); ++r) {
    const PlateRelief& p = plate.spec.reliefs[r];
    reliefs.push_back({{"shape", shape_name(p.shape)},
                       {"center", {p.center_u, p.center_v}},
                       {"size", {p.size_u, p.size_v}},
                       {"rotation", p.rotation},
                       {"corner", p.corner},
                       {"h", p.h},
                       {"touches", p.touches},
                       {"area", plate.truth_area[r]},
                       {"vertices", plate.truth[r]}});
  }
  const PlateSpec& s = plate.spec;
  return {{"format", "relief-snake-plate-truth/1"},
          {"average_edge", plate.scan.average_edge},
          {"triangles", plate.scan.n_faces()},
          {"vertices", plate.scan.n_vertices()},
          {"spec",
           {{"background", to_string(s.background)}, {"radius", s.radius}, {"triangles", s.triangles},
            {"width", s.width}, {"height", s.height}, {"step", to_string(s.step)}, {"blend_width", s.blend_width},
            {"noise", s.noise}, {"jitter", s.jitter}, {"seed", s.seed}}},
          {"reliefs", reliefs}};
}

const char* kPlateUsage =
    "  make-scan --plate SEED --out PREFIX [--background plane|cylinder|sphere|saddle] [--radius R (120)]\n"
    "            [--noise S (0, absolute sigma)] [--triangles N (100000)] [--step sharp|blended (blended)] [--empty]\n"
    "                                          a plate with several reliefs (some touching): PREFIX.ply and\n"
    "                                          PREFIX.truth.json with the truth per relief; --empty: no reliefs\n";

int run_plate_command(const std::vector<std::string>& args) {
  PlateSpec spec;
  std::string out;
  bool empty = false, have_seed = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw Error(a + " needs a value (see make-scan --help)");
      return args[++i];
    };
    try {
      if (a == "--plate") spec.seed = std::stoull(value()), have_seed = true;
      else if (a == "--out") out = value();
      else if (a == "--background") spec.background = parse_background(value());
      else if (a == "--radius") spec.radius = std::stod(value());
      else if (a == "--noise") spec.noise = std::stod(value());
      else if (a == "--triangles") spec.triangles = std::stoull(value());
      else if (a == "--step") spec.step = parse_step(value());
      else if (a == "--empty") empty = true;
      else throw Error("unknown option '" + a + "' for make-scan --plate (see make-scan --help)");
    } catch (const std::logic_error&) {
      throw Error("bad value for " + a + ": give a number");
    }
  }
  if (!have_seed || out.empty()) throw Error("make-scan --plate needs a seed and --out PREFIX");
  if (!empty) spec.reliefs = random_plate_layout(spec.seed, spec.width, spec.height);
  const PlateScan plate = generate_plate(spec);
  write_ply(plate.scan, out + ".ply");
  write_json(plate_truth_json(plate), out + ".truth.json");
  return 0;
}

double index_iou(const std::vector<std::int64_t>& a, const std::vector<std::int64_t>& b) {
  if (a.empty() && b.empty()) return 1;
  std::vector<std::int64_t> common;
  std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(common));
  return static_cast<double>(common.size()) / static_cast<double>(a.size() + b.size() - common.size());
}

}  // namespace synthetic
}  // namespace relief_snake

// The random scan family (make-scan --random SEED): every axis of a synthetic scan drawn from a
// seeded distribution, so defaults are chosen on scans nobody tuned for. The distributions are
// listed in bench/README.md ("Random suite"); draw_random() is the single source of truth.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "relief_snake/error.hpp"
#include "synthetic.hpp"

namespace relief_snake {
namespace synthetic {
namespace {

using Vec2 = Eigen::Vector2d;

std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// Sequential uniform draws for one (seed, attempt): draw k is a hash of (seed, attempt, k).
class Draws {
 public:
  Draws(std::uint64_t seed, int attempt) : key_(mix(mix(seed) ^ (0x5151ULL + static_cast<std::uint64_t>(attempt)))) {}
  double uniform() { return static_cast<double>(mix(key_ ^ mix(++count_)) >> 11) * (1.0 / 9007199254740992.0); }
  double range(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double log_range(double lo, double hi) { return std::exp(range(std::log(lo), std::log(hi))); }
  bool chance(double p) { return uniform() < p; }
  int integer(int lo, int hi) { return std::min(hi, lo + static_cast<int>(uniform() * (hi - lo + 1))); }
  /// Index drawn with the given weights.
  int pick(std::initializer_list<double> weights) {
    double total = 0;
    for (double w : weights) total += w;
    double x = uniform() * total;
    int i = 0;
    for (double w : weights) {
      if (x < w) return i;
      x -= w;
      ++i;
    }
    return i - 1;
  }

 private:
  std::uint64_t key_;
  std::uint64_t count_ = 0;
};

constexpr double kWidth = 80, kHeight = 56;  // the family's parameter domain (mm)
constexpr double kMaxH = 3.5;                // the largest step: keeps the pick rings inside the domain

/// The nominal (u, v) edge generate() will produce for a triangle count (before jitter and grading).
double nominal_edge_for(double triangles) {
  const double cu = std::max(2.0, std::round(std::sqrt(0.5 * triangles * kWidth / kHeight)));
  const double cv = std::max(2.0, std::round(0.5 * triangles / cu));
  const double su = kWidth / cu, sv = kHeight / cv;
  return (su + sv + std::hypot(su, sv)) / 3;
}

bool point_in_polygon(const std::vector<Vec2>& poly, const Vec2& q) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[j];
    if ((a.y() > q.y()) != (b.y() > q.y()) && q.x() < (b.x() - a.x()) * (q.y() - a.y()) / (b.y() - a.y()) + a.x())
      in = !in;
  }
  return in;
}

bool segments_cross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  auto side = [](const Vec2& p, const Vec2& q, const Vec2& r) {
    return (q.x() - p.x()) * (r.y() - p.y()) - (q.y() - p.y()) * (r.x() - p.x());
  };
  const double d1 = side(c, d, a), d2 = side(c, d, b), d3 = side(a, b, c), d4 = side(a, b, d);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

/// A closed polygon two of whose non-adjacent sides cross.
bool polygon_crosses_itself(const std::vector<Vec2>& poly) {
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;
      if (segments_cross(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n])) return true;
    }
  return false;
}

}  // namespace

RandomDraw draw_random(std::uint64_t seed, int attempt) {
  Draws r(seed, attempt);
  RandomDraw out;
  ScanSpec& sp = out.spec;
  PickSpec& ps = out.picks;
  nlohmann::json& axes = out.axes;
  sp.seed = mix(seed * 131 + static_cast<std::uint64_t>(attempt)) % 1000000007ULL;
  sp.width = kWidth;
  sp.height = kHeight;

  // Resolution: h in average edges log-uniform 1 .. 13; triangles log-uniform 15k .. 250k, raised
  // where needed so the step stays below kMaxH.
  const double h_edges = r.log_range(1, 13);
  double t_lo = 15000;
  while (t_lo < 250000 && h_edges * nominal_edge_for(t_lo) > kMaxH) t_lo *= 1.05;
  t_lo = std::min(t_lo, 250000.0);
  const double triangles = r.log_range(t_lo, 250000);
  sp.triangles = static_cast<std::size_t>(std::llround(triangles));
  const double edge = nominal_edge_for(triangles);
  sp.h = h_edges * edge;
  const double h = sp.h;
  axes["h_edges"] = h_edges;
  axes["triangles"] = sp.triangles;

  // Shape.
  const char* shape_names[] = {"duck", "gear", "c", "ellipse", "rounded-box", "letter", "band", "open"};
  int shape = r.pick({2, 1.5, 1.5, 0.75, 0.75, 1.5, 1.5, 0.5});
  // Concavities narrower than about 2 h (the h-ball does not fit: no planar floor) or 6 edges (the
  // paper: the snake does not enter mouths of 4-6 edges) cannot be entered by design; draw none.
  const double mouth = std::max(2 * h, 6 * edge);
  if (shape == 0 && h > 1.75) shape = 3;  // the duck's pocket under the beak is 3.5 wide
  axes["min_mouth"] = mouth;
  axes["shape"] = shape_names[shape];
  const bool closed_shape = shape != 6 && shape != 7;
  if (closed_shape) {
    sp.shape_rotation = r.range(0, 2 * M_PI);
    sp.shape_center_u = r.range(-3, 3);
    sp.shape_center_v = r.range(-2, 2);
  }
  switch (shape) {
    case 0: sp.shape = Shape::Duck; break;
    case 1: {
      sp.shape = Shape::Gear;
      sp.gear_radius = r.range(11, 16);
      const int n = r.integer(3, 6);
      sp.slot_widths.clear();
      for (int k = 0; k < n; ++k) sp.slot_widths.push_back(mouth / edge * r.range(1, 2));
      sp.gear_slot_depth = std::min({r.range(1.5, 5) * h, 0.6 * sp.gear_radius, sp.gear_radius - 2 * h - 0.5});
      axes["slots"] = n;
      axes["slot_min_edges"] = *std::min_element(sp.slot_widths.begin(), sp.slot_widths.end());
      break;
    }
    case 2: {
      sp.shape = Shape::CShape;
      sp.c_radius = r.range(10, 15);
      sp.c_half_thickness = std::min(std::max(1.5 * h, 2.5) + r.range(0, 3), 0.45 * sp.c_radius);
      sp.c_gap_width = mouth * r.range(1, 2.5);
      const double gap_edges = sp.c_gap_width / edge;
      sp.c_gap_angle = r.range(0, 2 * M_PI);
      axes["gap_edges"] = gap_edges;
      break;
    }
    case 3:
      sp.shape = Shape::Ellipse;
      sp.ellipse_a = r.range(9, 18);
      sp.ellipse_b = r.range(6, sp.ellipse_a);
      break;
    case 4:
      sp.shape = Shape::RoundedBox;
      sp.box_half_u = r.range(8, 18);
      sp.box_half_v = r.range(6, 13);
      sp.box_corner = r.chance(0.5) ? 0.0 : r.range(0.5, 4);
      break;
    case 5: {
      sp.shape = Shape::Letter;
      const char letters[] = {'L', 'T', 'E', 'H', 'U'};
      sp.letter = letters[r.integer(0, 4)];
      sp.letter_half_u = r.range(10, 15);
      sp.letter_half_v = r.range(13, 19);
      sp.stroke_width = std::min(std::max(2.5 * h, 4.0) + r.range(0, 4), 0.45 * sp.letter_half_u);
      axes["letter"] = std::string(1, sp.letter);
      break;
    }
    case 6: {
      sp.shape = Shape::Band;
      sp.band_edge = r.integer(0, 3);
      const double along = sp.band_edge < 2 ? kHeight : kWidth;
      sp.band_offset = r.range(-0.3, 0.3) * along;
      sp.band_angle = r.range(-0.6, 0.6);
      sp.band_half_width = std::max(2 * h, 3.0) + r.range(0, 4);
      const double across = sp.band_edge < 2 ? kWidth : kHeight;
      sp.band_length = r.range(0.35, 0.6) * across;
      sp.band_curvature = r.range(-1, 1) / 25;
      break;
    }
    default: sp.shape = Shape::Open; break;
  }

  // Background.
  const char* bg_names[] = {"plane", "cylinder", "sphere", "saddle", "vase", "wavy"};
  const int bg = r.pick({1, 1, 1, 1, 1, 1});
  axes["background"] = bg_names[bg];
  switch (bg) {
    case 0: sp.background = Background::Plane; break;
    case 1: sp.background = Background::Cylinder, sp.radius = r.range(22, 80); break;
    case 2: sp.background = Background::Sphere, sp.radius = r.range(30, 90); break;
    case 3: sp.background = Background::Saddle, sp.radius = r.range(30, 90); break;
    case 4:
      sp.background = Background::Vase, sp.radius = r.range(25, 60);
      sp.vase_amplitude = r.range(0.05, 0.2);
      sp.vase_period = r.range(40, 100);
      sp.vase_phase = r.range(0, 2 * M_PI);
      break;
    default:
      sp.background = Background::Wavy;
      sp.wavy_amplitude = r.range(0.5, 2.5);
      sp.wavy_period_u = r.range(25, 70);
      sp.wavy_period_v = r.range(25, 70);
      sp.wavy_phase = r.range(0, 2 * M_PI);
      break;
  }
  if (bg != 0) axes["radius"] = sp.radius;

  // Texture on the background: striations or stamped dots, amplitude up to 0.3 h.
  const int texture = r.pick({3, 1, 1});
  axes["texture"] = texture == 0 ? "none" : texture == 1 ? "striations" : "dots";
  if (texture != 0) {
    sp.texture = texture == 1 ? Texture::Striations : Texture::Dots;
    sp.texture_amplitude = r.range(0.05, 0.3);
    if (texture == 1) {
      sp.texture_period = std::max(r.range(1.2, 4), 6 / h_edges);  // resolved by >= 6 edges
      sp.texture_angle = r.range(0, M_PI);
    } else {
      sp.texture_period = std::max(r.range(2, 5), 8 / h_edges);
      sp.dot_radius = r.range(0.3, 0.45) * sp.texture_period;
      if (r.chance(0.5)) sp.texture_amplitude = -sp.texture_amplitude;  // stamped in
    }
    axes["texture_amplitude"] = std::abs(sp.texture_amplitude);
    out.picks_on_texture = r.chance(0.5);
  }
  axes["picks_on_texture"] = out.picks_on_texture;

  // Step profile: sharp, one triangle wide, or blended over 0.2 .. 1 h.
  const int step = r.pick({1, 1, 1});
  axes["step"] = step == 0 ? "sharp" : step == 1 ? "one-triangle" : "blended";
  if (step == 0) {
    sp.step = Step::Sharp;
  } else {
    sp.step = Step::Blended;
    sp.blend_width = step == 1 ? 1 / h_edges : r.range(0.2, 1.0);
  }
  axes["blend_width"] = step == 0 ? 0.0 : sp.blend_width;

  // Triangulation: jittered, sometimes graded.
  sp.jitter = r.range(0, 0.34);
  if (r.chance(0.4)) sp.grade_u = r.range(0, 0.35), sp.grade_v = r.range(0, 0.35);
  axes["jitter"] = sp.jitter;
  axes["graded"] = sp.grade_u > 0 || sp.grade_v > 0;

  // Noise: up to 0.05 h, on 60% of the scans.
  sp.noise = r.chance(0.6) ? r.range(0, 0.05) : 0.0;
  axes["noise"] = sp.noise;

  // Interior detail.
  const char* detail_names[] = {"none", "dome", "grooves", "edge-groove", "bumps", "drop"};
  const int detail = r.pick({2, 1, 1, 1, 1, 0.6});
  axes["detail"] = detail_names[detail];
  const double groove_width = std::max(r.range(0.2, 0.5), 1.2 / h_edges);
  bool near_edge = false;
  switch (detail) {
    case 1: sp.dome = r.range(0.3, 1.0), sp.dome_width = r.range(3, 8); break;
    case 2:
      sp.grooves = r.range(0.3, 0.8), sp.groove_width = groove_width;
      sp.groove_spacing = r.range(3, 6), sp.groove_angle = r.range(0, M_PI);
      near_edge = true;  // they fade in from 0.5 h inside the edge
      break;
    case 3:
      sp.edge_groove = r.range(0.3, 0.8), sp.groove_width = groove_width;
      sp.edge_groove_distance = r.range(1, 2);
      near_edge = true;
      break;
    case 4:
      sp.detail = r.range(0.1, 0.4), sp.bump_inset = r.range(1, 3);
      near_edge = sp.bump_inset <= 2;
      break;
    case 5: sp.drop = true, near_edge = true; break;
    default: break;
  }
  axes["detail_near_edge"] = near_edge;

  // Starts.
  const int start = r.pick({1.2, 0.9, 0.9});
  ps.start = start == 0 ? Start::Near : start == 1 ? Start::Far : Start::Zigzag;
  axes["start"] = to_string(ps.start);
  ps.distance = r.range(1.5, 3.5);
  ps.count = r.integer(5, 12);
  ps.reverse = r.chance(0.5);
  axes["pick_distance"] = ps.distance;

  // The h the user types.
  out.typed_factor = r.log_range(0.5, 2.0);
  axes["typed_factor"] = out.typed_factor;
  axes["open"] = !closed_shape;
  return out;
}

RandomScan generate_random(std::uint64_t seed) {
  std::string last_error = "no attempt";
  for (int attempt = 0; attempt < 50; ++attempt) {
    RandomDraw draw = draw_random(seed, attempt);
    const ScanSpec& sp = draw.spec;
    if (sp.shape == Shape::Letter) {
      // The letters' mouths must be enterable too (see draw_random).
      const double mouth = draw.axes["min_mouth"].get<double>();
      const double e_mouth = 0.5 * (2 * sp.letter_half_v - 3 * sp.stroke_width);
      const double u_mouth = 2 * sp.letter_half_u - 2 * sp.stroke_width;
      if ((sp.letter == 'E' && e_mouth < mouth) || ((sp.letter == 'U' || sp.letter == 'H') && u_mouth < mouth)) {
        last_error = "the letter's mouth is too narrow";
        continue;
      }
    }
    try {
      Scan scan = generate(draw.spec);
      const bool open_shape = draw.spec.shape == Shape::Band || draw.spec.shape == Shape::Open;
      // One boundary curve, open exactly for the open shapes, and a relief big enough to matter.
      if (scan.boundary.size() != 1 || scan.open != open_shape) {
        last_error = "the silhouette left the domain";
        continue;
      }
      const double fraction = scan.relief_fraction();
      if (fraction < 0.03 || fraction > 0.6) {
        last_error = "relief fraction out of range";
        continue;
      }
      Picks picks = scan.picks(draw.picks);
      if (draw.picks_on_texture) {
        // Move about half the picks (never an open contour's ends) onto the nearest texture feature
        // when that keeps them clear of the relief.
        for (std::size_t i = 0; i < picks.vertices.size(); ++i) {
          if (!picks.closed && (i == 0 || i + 1 == picks.vertices.size())) continue;
          if (((mix(seed * 7919 + i) >> 20) & 1) == 0) continue;
          const std::int64_t old = picks.vertices[i];
          const double u = scan.UV[2 * old], v = scan.UV[2 * old + 1];
          const std::int64_t moved = texture_feature_vertex(scan, u, v);
          if (moved < 0) continue;
          const double sd_old = scan.signed_distance(u, v);
          const double sd_new = scan.signed_distance(scan.UV[2 * moved], scan.UV[2 * moved + 1]);
          if (sd_new >= std::max(0.75 * sd_old, 1.0 * scan.h)) picks.vertices[i] = moved;
        }
        std::vector<std::int64_t> kept;
        for (std::int64_t p : picks.vertices)
          if (kept.empty() || kept.back() != p) kept.push_back(p);
        if (picks.closed && kept.size() > 1 && kept.front() == kept.back()) kept.pop_back();
        picks.vertices = kept;
      }
      // A vertex picked twice (two picks snapped or moved onto the same one): kept once, where first.
      {
        std::vector<std::int64_t> distinct;
        for (std::int64_t p : picks.vertices)
          if (std::find(distinct.begin(), distinct.end(), p) == distinct.end()) distinct.push_back(p);
        picks.vertices = distinct;
      }
      bool valid = picks.vertices.size() >= (picks.closed ? 3u : 2u);
      for (std::int64_t p : picks.vertices) valid = valid && p >= 0;
      if (!valid) {
        last_error = "a pick did not land on a vertex";
        continue;
      }
      // Picks a user would make round a closed relief: a pick polygon (in the parameter plane) that does
      // not cross itself and holds the whole relief. (A zigzag on a coarse mesh could cross itself, and a
      // near ring round a C near the domain's edge could be the one inside its hole; the engine rightly
      // refuses such picks, which measures nothing about the segmentation.)
      if (picks.closed) {
        std::vector<Vec2> poly;
        for (std::int64_t p : picks.vertices) poly.emplace_back(scan.UV[2 * p], scan.UV[2 * p + 1]);
        if (polygon_crosses_itself(poly)) {
          last_error = "the pick polygon crosses itself";
          continue;
        }
        std::size_t relief = 0, inside = 0;
        for (std::size_t k = 0; k < scan.relief.size(); ++k) {
          if (!scan.relief[k]) continue;
          ++relief;
          inside += point_in_polygon(poly, Vec2(scan.UV[2 * k], scan.UV[2 * k + 1])) ? 1 : 0;
        }
        if (inside < relief) {
          last_error = "the picks do not go round the relief";
          continue;
        }
      }
      RandomScan out;
      out.draw = std::move(draw);
      out.scan = std::move(scan);
      out.picks = std::move(picks);
      out.attempts = attempt + 1;
      return out;
    } catch (const Error& e) {
      last_error = e.what();
    }
  }
  throw Error("random scan " + std::to_string(seed) + ": no draw fitted in 50 attempts (last: " + last_error + ")");
}

IouFloor one_edge_floor(const Scan& scan) {
  const std::size_t nv = scan.n_vertices();
  std::vector<double> area(nv, 0.0);
  for (std::size_t f = 0; f < scan.n_faces(); ++f) {
    const std::int64_t a = scan.F[3 * f], b = scan.F[3 * f + 1], c = scan.F[3 * f + 2];
    const double third = (scan.vertex(b) - scan.vertex(a)).cross(scan.vertex(c) - scan.vertex(a)).norm() / 6;
    area[a] += third, area[b] += third, area[c] += third;
  }
  const PolylineDistance to_boundary(scan.boundary);
  double truth_n = 0, truth_a = 0, grown_n = 0, grown_a = 0;
  for (std::size_t v = 0; v < nv; ++v) {
    const bool in = scan.relief[v] != 0;
    const bool grown = in || to_boundary.within(scan.vertex(v), scan.average_edge);
    truth_n += in, truth_a += in ? area[v] : 0;
    grown_n += grown, grown_a += grown ? area[v] : 0;
  }
  IouFloor floor;
  floor.vertices = grown_n > 0 ? truth_n / grown_n : 1;
  floor.area = grown_a > 0 ? truth_a / grown_a : 1;
  return floor;
}

nlohmann::json random_truth_json(const RandomScan& random, const std::string& background_file) {
  const Scan& scan = random.scan;
  nlohmann::json j = truth_json(scan, random.picks);
  const IouFloor floor = one_edge_floor(scan);
  j["closed"] = random.picks.closed;
  j["true_step_height"] = scan.h;
  j["edge_step_height"] = edge_step_height(random.draw.spec);
  j["typed_step_height"] = scan.h * random.draw.typed_factor;
  j["typed_factor"] = random.draw.typed_factor;
  j["h_over_average_edge"] = scan.h / scan.average_edge;
  j["axes"] = random.draw.axes;
  j["attempts"] = random.attempts;
  j["iou_floor"] = {{"vertices", floor.vertices}, {"area", floor.area},
                    {"definition", "IoU of the true relief against itself grown by every vertex within one "
                                   "average edge (3D) of the true boundary"}};
  j["background_file"] = background_file;
  j["background_columns"] = {"base_x", "base_y", "base_z", "normal_x", "normal_y", "normal_z",
                             "relief_height", "texture_height", "noise_height"};
  j["background_note"] = "vertex = base + (relief_height + texture_height + noise_height) * normal, up to float32 "
                         "rounding of the PLY; base is the smooth background (texture excluded)";
  const ScanSpec& sp = scan.spec;
  j["random_spec"] = {{"shape_rotation", sp.shape_rotation}, {"shape_center", {sp.shape_center_u, sp.shape_center_v}},
                      {"gear_radius", sp.gear_radius},       {"gear_slot_depth", sp.gear_slot_depth},
                      {"slots", scan.slots},                 {"c", {sp.c_radius, sp.c_half_thickness, sp.c_gap_width, sp.c_gap_angle}},
                      {"ellipse", {sp.ellipse_a, sp.ellipse_b}},
                      {"box", {sp.box_half_u, sp.box_half_v, sp.box_corner}},
                      {"letter", std::string(1, sp.letter)},
                      {"letter_size", {sp.letter_half_u, sp.letter_half_v, sp.stroke_width}},
                      {"band", {sp.band_edge, sp.band_offset, sp.band_angle, sp.band_length, sp.band_curvature, sp.band_half_width}},
                      {"vase", {sp.vase_amplitude, sp.vase_period, sp.vase_phase}},
                      {"wavy", {sp.wavy_amplitude, sp.wavy_period_u, sp.wavy_period_v, sp.wavy_phase}},
                      {"texture", to_string(sp.texture)},
                      {"texture_params", {sp.texture_amplitude, sp.texture_period, sp.texture_angle, sp.dot_radius}},
                      {"dome", {sp.dome, sp.dome_width}},
                      {"grooves", {sp.grooves, sp.groove_spacing, sp.groove_width, sp.groove_angle}},
                      {"edge_groove", {sp.edge_groove, sp.edge_groove_distance}},
                      {"bump_inset", sp.bump_inset},
                      {"grade", {sp.grade_u, sp.grade_v}},
                      {"pick_spec", {{"start", to_string(random.draw.picks.start)},
                                     {"count", random.draw.picks.count},
                                     {"distance", random.draw.picks.distance},
                                     {"reverse", random.draw.picks.reverse}}}};
  return j;
}

void write_background_npy(const Scan& scan, const std::string& path) {
  const std::size_t nv = scan.n_vertices();
  std::vector<float> data(9 * nv);
  for (std::size_t v = 0; v < nv; ++v) {
    const double u = scan.UV[2 * v], w = scan.UV[2 * v + 1];
    const Vec3 base = scan.surface(u, w, 0), n = scan.background_normal(u, w);
    const double row[9] = {base.x(), base.y(), base.z(), n.x(), n.y(), n.z(),
                           scan.relief_height[v], scan.texture_height[v], scan.noise_height[v]};
    for (int k = 0; k < 9; ++k) data[9 * v + k] = static_cast<float>(row[k]);
  }
  // NPY format 1.0: magic, version, little-endian header length, a Python dict literal padded with
  // spaces to a multiple of 64 bytes and ended by a newline.
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + std::to_string(nv) + ", 9), }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw Error("cannot write " + tmp + ": check that the folder exists and is writable");
    const unsigned char magic[8] = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0};
    out.write(reinterpret_cast<const char*>(magic), 8);
    const std::uint16_t len = static_cast<std::uint16_t>(header.size());
    const unsigned char len_bytes[2] = {static_cast<unsigned char>(len & 0xff), static_cast<unsigned char>(len >> 8)};
    out.write(reinterpret_cast<const char*>(len_bytes), 2);
    out << header;
    out.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size() * sizeof(float)));
    if (!out) throw Error("failed writing " + tmp + ": check free disk space");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw Error("cannot rename " + tmp + " to " + path);
}

}  // namespace synthetic
}  // namespace relief_snake

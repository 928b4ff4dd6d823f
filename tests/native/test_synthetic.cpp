// Tests of the synthetic scan generator: mesh validity, ground truth, picks, scoring.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <random>

#include <nlohmann/json.hpp>

#include "relief_snake/error.hpp"
#include "synthetic.hpp"

using namespace relief_snake;
using namespace relief_snake::synthetic;

namespace {

ScanSpec make_spec(Shape shape, Background bg = Background::Plane, std::size_t triangles = 40000) {
  ScanSpec s;
  s.shape = shape;
  s.background = bg;
  s.triangles = triangles;
  return s;
}

Eigen::Vector2d uv(const Scan& s, std::int64_t v) { return {s.UV[2 * v], s.UV[2 * v + 1]}; }
double sd_at(const Scan& s, std::int64_t v) { return s.signed_distance(s.UV[2 * v], s.UV[2 * v + 1]); }

int find(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

bool on_mesh_boundary(const Scan& s, std::int64_t v) {
  const int i = static_cast<int>(v % s.grid_u), j = static_cast<int>(v / s.grid_u);
  return i == 0 || j == 0 || i == s.grid_u - 1 || j == s.grid_v - 1;
}

// Winding number of a closed polygon (in uv) around point p.
int winding(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& p) {
  double total = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector2d a = poly[i] - p, b = poly[(i + 1) % poly.size()] - p;
    total += std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
  }
  return static_cast<int>(std::lround(total / (2 * M_PI)));
}

}  // namespace

TEST(Synthetic, TriangleCountWithinTenPercentOfTarget) {
  for (std::size_t target : {10000u, 55555u, 300000u}) {
    const Scan s = generate(make_spec(Shape::Duck, Background::Plane, target));
    EXPECT_NEAR(static_cast<double>(s.n_faces()), static_cast<double>(target), 0.1 * target) << target;
    EXPECT_EQ(s.n_vertices(), static_cast<std::size_t>(s.grid_u) * s.grid_v);
    EXPECT_EQ(s.relief.size(), s.n_vertices());
    EXPECT_EQ(s.UV.size(), 2 * s.n_vertices());
  }
}

TEST(Synthetic, NoDegenerateTrianglesAndCounterClockwise) {
  for (Background bg : {Background::Plane, Background::Cylinder, Background::Sphere, Background::Saddle}) {
    ScanSpec spec = make_spec(Shape::Duck, bg, 20000);
    spec.noise = 0.05;
    const Scan s = generate(spec);
    const double min_uv_area = 0.06 * s.spacing_u * s.spacing_v;  // 0.073 is the bound at jitter 0.3
    for (std::size_t f = 0; f < s.n_faces(); ++f) {
      const std::int64_t a = s.F[3 * f], b = s.F[3 * f + 1], c = s.F[3 * f + 2];
      ASSERT_TRUE(a != b && b != c && a != c);
      const Eigen::Vector2d e1 = uv(s, b) - uv(s, a), e2 = uv(s, c) - uv(s, a);
      const double uv_area = 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
      ASSERT_GT(uv_area, min_uv_area) << "face " << f;  // positive: counter-clockwise in (u, v)
      const Vec3 n = (s.vertex(b) - s.vertex(a)).cross(s.vertex(c) - s.vertex(a));
      ASSERT_GT(0.5 * n.norm(), 1e-3 * s.nominal_edge * s.nominal_edge) << "face " << f;
      // oriented like the background normal (+normal side sees it counter-clockwise)
      const Eigen::Vector2d m = (uv(s, a) + uv(s, b) + uv(s, c)) / 3;
      ASSERT_GT(n.dot(s.background_normal(m.x(), m.y())), 0) << "face " << f;
    }
  }
}

TEST(Synthetic, MeshIsOneManifoldComponentWithRectangularBoundary) {
  const Scan s = generate(make_spec(Shape::Slots, Background::Saddle, 30000));
  const int nv = static_cast<int>(s.n_vertices());
  std::vector<int> parent(nv);
  std::iota(parent.begin(), parent.end(), 0);
  std::map<std::pair<std::int64_t, std::int64_t>, int> edge_faces;
  std::vector<char> used(nv, 0);
  for (std::size_t f = 0; f < s.n_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const std::int64_t a = s.F[3 * f + k], b = s.F[3 * f + (k + 1) % 3];
      used[a] = 1;
      parent[find(parent, static_cast<int>(a))] = find(parent, static_cast<int>(b));
      ++edge_faces[{std::min(a, b), std::max(a, b)}];
    }
  for (int v = 0; v < nv; ++v) ASSERT_TRUE(used[v]) << "unreferenced vertex " << v;
  const int root = find(parent, 0);
  for (int v = 0; v < nv; ++v) ASSERT_EQ(find(parent, v), root) << "vertex " << v << " in another component";
  std::size_t boundary_edges = 0;
  double sum = 0;
  for (const auto& e : edge_faces) {
    ASSERT_LE(e.second, 2);
    if (e.second == 1) ++boundary_edges;
    sum += (s.vertex(e.first.first) - s.vertex(e.first.second)).norm();
  }
  EXPECT_EQ(boundary_edges, static_cast<std::size_t>(2 * (s.grid_u - 1 + s.grid_v - 1)));
  EXPECT_NEAR(s.average_edge, sum / edge_faces.size(), 1e-9 * s.average_edge);
  // Euler characteristic of a disk
  EXPECT_EQ(static_cast<long>(nv) - static_cast<long>(edge_faces.size()) + static_cast<long>(s.n_faces()), 1);
}

TEST(Synthetic, ReliefFractionMatchesSilhouetteArea) {
  const double domain = 80.0 * 56.0;
  EXPECT_NEAR(generate(make_spec(Shape::Disk)).relief_fraction(), M_PI * 144 / domain, 0.005);
  EXPECT_NEAR(generate(make_spec(Shape::Rectangle)).relief_fraction(), 32.0 * 20 / domain, 0.005);
  const double duck = generate(make_spec(Shape::Duck)).relief_fraction();
  EXPECT_GT(duck, 0.08);
  EXPECT_LT(duck, 0.25);
  const double open = generate(make_spec(Shape::Open)).relief_fraction();
  EXPECT_GT(open, 0.05);
  EXPECT_LT(open, 0.3);
}

TEST(Synthetic, StepProfilesAlongTheNormal) {
  ScanSpec spec = make_spec(Shape::Disk);
  spec.h = 0.8;
  Scan s = generate(spec);
  for (std::size_t v = 0; v < s.n_vertices(); ++v)
    ASSERT_NEAR(s.V[3 * v + 2], s.relief[v] ? 0.8 : 0.0, 1e-12) << v;

  spec.step = Step::Blended;
  spec.blend_width = 0.5;
  s = generate(spec);
  for (std::size_t v = 0; v < s.n_vertices(); ++v) {
    const double z = s.V[3 * v + 2], d = -sd_at(s, v);
    if (d <= 0) {
      ASSERT_EQ(z, 0.0);
    } else if (d >= 0.4) {
      ASSERT_NEAR(z, 0.8, 1e-12);
    } else {
      ASSERT_TRUE(z > 0 && z < 0.8) << z;
    }
  }

  spec.step = Step::Sharp;
  spec.drop = true;
  s = generate(spec);
  for (std::size_t v = 0; v < s.n_vertices(); ++v) {
    const double z = s.V[3 * v + 2], d = -sd_at(s, v);
    if (d > 1.5 * 0.8) {
      ASSERT_NEAR(z, 0.3 * 0.8, 1e-12);
    }
    if (d > 0 && d < 0.02) {
      ASSERT_GT(z, 0.79);
    }
  }

  spec.drop = false;
  spec.detail = 0.2;
  s = generate(spec);
  double lo = 1e9, hi = -1e9;
  for (std::size_t v = 0; v < s.n_vertices(); ++v) {
    const double z = s.V[3 * v + 2], d = -sd_at(s, v);
    if (d > 0 && d < 2 * 0.8) {
      ASSERT_NEAR(z, 0.8, 1e-12);  // detail stays away from the boundary
    }
    if (d > 0) lo = std::min(lo, z), hi = std::max(hi, z);
  }
  EXPECT_GT(hi, 0.8 + 0.1 * 0.8);
  EXPECT_LT(lo, 0.8 - 0.1 * 0.8);
  EXPECT_LE(hi, 0.8 * 1.2 + 1e-12);
}

// The rim a step measured at the edge can find: h for a plain step; below h where a drop or an edge
// groove keeps the surface from reaching it; and the highest the generated vertices stand within
// the profile's first rise (a fine disk, so vertices sample the profile densely).
TEST(Synthetic, EdgeStepHeightIsTheRimTheVerticesReach) {
  ScanSpec spec = make_spec(Shape::Disk);
  spec.h = 0.8;
  spec.triangles = 200000;
  EXPECT_DOUBLE_EQ(edge_step_height(spec), 0.8);
  spec.step = Step::Blended;
  spec.blend_width = 0.5;
  EXPECT_NEAR(edge_step_height(spec), 0.8, 1e-9);
  spec.edge_groove = 0.5, spec.edge_groove_distance = 2, spec.groove_width = 0.3;  // clear of the rise
  EXPECT_NEAR(edge_step_height(spec), 0.8, 1e-3 * 0.8);
  struct Case { Step step; double blend; bool drop; double groove, at; double lo, hi; };
  const Case cases[] = {{Step::Blended, 1.0, true, 0, 0, 0.45, 0.6},    // a blended rise into the drop
                        {Step::Sharp, 0, true, 0, 0, 0.999, 1.0},       // sharp: the rim right at the edge
                        {Step::Blended, 1.0, false, 0.6, 1.2, 0.5, 0.9}};  // the groove starts before the rise ends
  for (const Case& c : cases) {
    spec.step = c.step, spec.blend_width = c.blend > 0 ? c.blend : 0.5, spec.drop = c.drop;
    spec.edge_groove = c.groove, spec.edge_groove_distance = c.at > 0 ? c.at : 1.5, spec.groove_width = 0.3;
    const double rim = edge_step_height(spec);
    EXPECT_GE(rim, c.lo * 0.8);
    EXPECT_LE(rim, c.hi * 0.8);
    const Scan s = generate(spec);
    double highest = 0;  // the vertices' highest point short of 2 h in, where the profile starts again
    for (std::size_t v = 0; v < s.n_vertices(); ++v) {
      const double d = -sd_at(s, v);
      if (d > 0 && d < (c.groove > 0 ? c.at : 2.0) * spec.h) highest = std::max(highest, s.V[3 * v + 2]);
    }
    EXPECT_LE(highest, rim + 1e-3 * spec.h);  // the profile is sampled every thousandth of h
    EXPECT_GT(highest, rim - 0.02 * spec.h) << "the vertices should come close to the rim";
  }
}

TEST(Synthetic, NoiseHasTheRequestedSigma) {
  ScanSpec spec = make_spec(Shape::Disk, Background::Plane, 100000);
  spec.noise = 0.1;
  spec.h = 2;
  const Scan s = generate(spec);
  double sum = 0, sum2 = 0;
  std::size_t n = 0;
  for (std::size_t v = 0; v < s.n_vertices(); ++v)
    if (!s.relief[v]) {
      sum += s.V[3 * v + 2];
      sum2 += s.V[3 * v + 2] * s.V[3 * v + 2];
      ++n;
    }
  const double mean = sum / n, sigma = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0, 0.01);
  EXPECT_NEAR(sigma, 0.2, 0.01);
}

TEST(Synthetic, VerticesLieOnTheBackgroundOffsetAlongItsNormal) {
  const double R = 40;
  for (Background bg : {Background::Cylinder, Background::Sphere, Background::Saddle}) {
    const Scan s = generate(make_spec(Shape::Duck, bg, 20000));
    for (std::size_t v = 0; v < s.n_vertices(); ++v) {
      const Vec3 p = s.vertex(v);
      const double height = s.relief[v] ? 1.0 : 0.0;
      if (bg == Background::Cylinder) {
        ASSERT_NEAR(std::hypot(p.x(), p.z() + R), R + height, 1e-9);
      } else if (bg == Background::Sphere) {
        ASSERT_NEAR((p + Vec3(0, 0, R)).norm(), R + height, 1e-9);
      } else {
        const Vec3 foot = p - height * s.background_normal(s.UV[2 * v], s.UV[2 * v + 1]);
        ASSERT_NEAR(foot.z(), (foot.x() * foot.x() - foot.y() * foot.y()) / (2 * R), 1e-9);
      }
    }
  }
}

TEST(Synthetic, BoundaryIsAtTheFootOfTheStepOnTheBackground) {
  const double R = 40;
  for (Background bg : {Background::Plane, Background::Cylinder, Background::Sphere, Background::Saddle}) {
    const Scan s = generate(make_spec(Shape::Duck, bg, 20000));
    ASSERT_EQ(s.boundary.size(), 1u);
    ASSERT_TRUE(s.boundary[0].closed);
    EXPECT_FALSE(s.open);
    double longest = 0;
    const auto& pts = s.boundary[0].points;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Vec3& p = pts[i];
      longest = std::max(longest, (pts[(i + 1) % pts.size()] - p).norm());
      double error = 0;  // distance from the background's implicit equation
      if (bg == Background::Plane) error = p.z();
      if (bg == Background::Cylinder) error = std::hypot(p.x(), p.z() + R) - R;
      if (bg == Background::Sphere) error = (p + Vec3(0, 0, R)).norm() - R;
      if (bg == Background::Saddle) error = p.z() - (p.x() * p.x() - p.y() * p.y()) / (2 * R);
      ASSERT_NEAR(error, 0, 1e-9);
    }
    EXPECT_LE(longest, s.average_edge / 4);  // dense
  }
}

TEST(Synthetic, BoundaryFollowsTheReliefTransitionsBothWays) {
  for (Shape shape : {Shape::Duck, Shape::Slots, Shape::Open}) {
    const Scan s = generate(make_spec(shape, Background::Plane, 30000));
    const PolylineDistance to_boundary(s.boundary);
    // every relief / non-relief mesh edge crosses the boundary: its midpoint is within half an edge
    std::size_t transitions = 0;
    for (std::size_t f = 0; f < s.n_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const std::int64_t a = s.F[3 * f + k], b = s.F[3 * f + (k + 1) % 3];
        if (s.relief[a] == s.relief[b]) continue;
        ++transitions;
        const Vec3 foot_a(s.UV[2 * a], s.UV[2 * a + 1], 0), foot_b(s.UV[2 * b], s.UV[2 * b + 1], 0);
        ASSERT_LT(to_boundary(0.5 * (foot_a + foot_b)), 0.5 * (foot_a - foot_b).norm() + 1e-9);
      }
    EXPECT_GT(transitions, 100u);
    // every boundary point has both a relief and a non-relief vertex within 1.5 edges
    const auto& pts = s.boundary[0].points;
    for (std::size_t i = 0; i < pts.size(); i += 7) {
      bool in = false, out = false;
      const int i0 = static_cast<int>((pts[i].x() + 40) / s.spacing_u), j0 = static_cast<int>((pts[i].y() + 28) / s.spacing_v);
      for (int j = std::max(0, j0 - 3); j <= std::min(s.grid_v - 1, j0 + 3); ++j)
        for (int ii = std::max(0, i0 - 3); ii <= std::min(s.grid_u - 1, i0 + 3); ++ii) {
          const int v = j * s.grid_u + ii;
          if (std::hypot(s.UV[2 * v] - pts[i].x(), s.UV[2 * v + 1] - pts[i].y()) > 1.5 * s.nominal_edge) continue;
          (s.relief[v] ? in : out) = true;
        }
      ASSERT_TRUE(in && out) << "boundary point " << i << " of " << to_string(shape);
    }
  }
}

TEST(Synthetic, ClosedBoundaryHasTheReliefOnItsLeft) {
  const Scan s = generate(make_spec(Shape::Disk));
  const auto& p = s.boundary[0].points;
  double area = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3& a = p[i];
    const Vec3& b = p[(i + 1) % p.size()];
    area += 0.5 * (a.x() * b.y() - a.y() * b.x());
  }
  EXPECT_NEAR(area, M_PI * 144, 0.01 * M_PI * 144);  // positive: counter-clockwise
}

TEST(Synthetic, SlotsHaveTheRequestedMouthWidths) {
  ScanSpec spec = make_spec(Shape::Slots, Background::Plane, 60000);
  spec.slot_widths = {2, 4, 6};
  spec.slot_depth = 4;
  const Scan s = generate(spec);
  ASSERT_EQ(s.slots.size(), 6u);
  for (std::size_t k = 0; k < 3; ++k) {
    const double centre = s.slots[2 * k], width = s.slots[2 * k + 1];
    EXPECT_NEAR(width, spec.slot_widths[k] * s.nominal_edge, 1e-12);
    // open just below the top edge and down to the depth, closed below it
    EXPECT_GT(s.signed_distance(centre, 9 - 0.1), 0);
    EXPECT_GT(s.signed_distance(centre, 9 - 3.9), 0);
    EXPECT_LT(s.signed_distance(centre, 9 - 4.1), 0);
    EXPECT_LT(s.signed_distance(centre + 0.5 * width + 0.1, 9 - 0.5), 0);
    EXPECT_LT(s.signed_distance(centre - 0.5 * width - 0.1, 9 - 0.5), 0);
  }
  spec.slot_widths = {60, 60};  // cannot fit
  EXPECT_THROW(generate(spec), Error);
}

TEST(Synthetic, ClosedPicksAreOutsideAndEncloseTheRelief) {
  for (Shape shape : {Shape::Duck, Shape::Disk, Shape::Rectangle, Shape::Slots}) {
    for (Background bg : {Background::Plane, Background::Sphere}) {
      const Scan s = generate(make_spec(shape, bg, 30000));
      const std::int64_t inside = s.relief_vertices()[s.relief_vertices().size() / 2];
      for (Start start : {Start::Near, Start::Far, Start::Zigzag}) {
        for (bool reverse : {false, true}) {
          PickSpec ps;
          ps.start = start;
          ps.count = 8;
          ps.reverse = reverse;
          const Picks p = s.picks(ps);
          SCOPED_TRACE(std::string(to_string(shape)) + " " + to_string(bg) + " " + to_string(start));
          ASSERT_TRUE(p.closed);
          ASSERT_GE(p.vertices.size(), 8u);
          EXPECT_EQ(p.relief_side, reverse ? ReliefSide::Right : ReliefSide::Left);
          std::vector<Eigen::Vector2d> poly;
          double lo = 1e9, hi = -1e9;
          for (std::int64_t v : p.vertices) {
            ASSERT_FALSE(s.relief[v]);
            const double d = sd_at(s, v);
            lo = std::min(lo, d), hi = std::max(hi, d);
            poly.push_back(uv(s, v));
          }
          // straight chords between consecutive picks stay clear of the relief
          for (std::size_t i = 0; i < poly.size(); ++i)
            for (int t = 0; t <= 50; ++t) {
              const Eigen::Vector2d q = poly[i] + (poly[(i + 1) % poly.size()] - poly[i]) * (t / 50.0);
              ASSERT_GT(s.signed_distance(q.x(), q.y()), 0.4 * p.near_distance);
            }
          EXPECT_EQ(winding(poly, uv(s, inside)), reverse ? -1 : 1);
          const double tol = s.nominal_edge;
          if (start == Start::Near) {
            EXPECT_GT(lo, p.near_distance - tol);
            EXPECT_LT(hi, p.near_distance + tol);
          } else if (start == Start::Far) {
            EXPECT_GT(lo, p.far_distance - tol);
            EXPECT_GT(p.far_distance, 3 * p.near_distance);
          } else {
            EXPECT_LT(lo, p.near_distance + tol);
            EXPECT_GT(hi, p.far_distance - tol);
          }
        }
      }
    }
  }
}

TEST(Synthetic, OpenPicksRunFromMeshBoundaryToMeshBoundary) {
  for (Background bg : {Background::Plane, Background::Saddle}) {
    const Scan s = generate(make_spec(Shape::Open, bg, 30000));
    EXPECT_TRUE(s.open);
    ASSERT_EQ(s.boundary.size(), 1u);
    EXPECT_FALSE(s.boundary[0].closed);
    // truth ends on the right edge of the domain (u = 40)
    const Vec3 first = s.boundary[0].points.front(), last = s.boundary[0].points.back();
    if (bg == Background::Plane) {
      EXPECT_NEAR(first.x(), 40, 1e-9);
      EXPECT_NEAR(last.x(), 40, 1e-9);
      EXPECT_GT(first.y(), last.y());  // relief on the left: from top to bottom around the blob's left side
    }
    for (bool reverse : {false, true}) {
      for (Start start : {Start::Near, Start::Far, Start::Zigzag}) {
        PickSpec ps;
        ps.start = start;
        ps.reverse = reverse;
        const Picks p = s.picks(ps);
        ASSERT_FALSE(p.closed);
        ASSERT_GE(p.vertices.size(), 2u);
        EXPECT_TRUE(on_mesh_boundary(s, p.vertices.front()));
        EXPECT_TRUE(on_mesh_boundary(s, p.vertices.back()));
        for (std::size_t i = 1; i + 1 < p.vertices.size(); ++i) EXPECT_FALSE(on_mesh_boundary(s, p.vertices[i]));
        for (std::int64_t v : p.vertices) ASSERT_GT(sd_at(s, v), 0.5 * p.near_distance);
        EXPECT_EQ(p.relief_side, reverse ? ReliefSide::Right : ReliefSide::Left);
        // the relief is on the stated side of every chord, seen from +normal (uv is right-handed)
        const std::vector<std::int64_t> relief = s.relief_vertices();
        for (std::size_t i = 0; i + 1 < p.vertices.size(); ++i) {
          const Eigen::Vector2d a = uv(s, p.vertices[i]), b = uv(s, p.vertices[i + 1]), m = 0.5 * (a + b);
          double best = 1e300;
          Eigen::Vector2d r = m;
          for (std::size_t k = 0; k < relief.size(); k += 3) {
            const double d = (uv(s, relief[k]) - m).squaredNorm();
            if (d < best) best = d, r = uv(s, relief[k]);
          }
          const double cross = (b - a).x() * (r - m).y() - (b - a).y() * (r - m).x();
          EXPECT_GT(reverse ? -cross : cross, 0) << "chord " << i;
        }
      }
    }
  }
}

TEST(Synthetic, PolylineDistanceMatchesBruteForce) {
  const Scan s = generate(make_spec(Shape::Duck, Background::Saddle, 20000));
  const PolylineDistance dist(s.boundary);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-60, 60), Z(-20, 20);
  for (int i = 0; i < 300; ++i) {
    Vec3 p(U(rng), U(rng) * 0.7, Z(rng));
    if (i < 150) p = s.boundary[0].points[(i * 37) % s.boundary[0].points.size()] + Vec3(U(rng), U(rng), U(rng)) * 0.01;
    double brute = 1e300;
    const auto& q = s.boundary[0].points;
    for (std::size_t k = 0; k < q.size(); ++k) {
      const Vec3 a = q[k], b = q[(k + 1) % q.size()];
      const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      brute = std::min(brute, (p - (a + t * (b - a))).norm());
    }
    ASSERT_NEAR(dist(p), brute, 1e-12) << i;
  }
}

TEST(Synthetic, ScoreOfTheTruthIsPerfect) {
  for (Shape shape : {Shape::Duck, Shape::Open}) {
    const Scan s = generate(make_spec(shape, Background::Sphere, 30000));
    const Score sc = score(s.boundary[0], s.relief_vertices(), s);
    EXPECT_DOUBLE_EQ(sc.iou, 1.0);
    EXPECT_LT(sc.max_to_truth, 1e-9);
    EXPECT_LT(sc.max_from_truth, 1e-9);
  }
}

TEST(Synthetic, ScoreOfAnOffsetContourIsTheOffset) {
  const Scan s = generate(make_spec(Shape::Disk, Background::Plane, 100000));
  const double delta = 2 * s.average_edge;
  // the disk's boundary pushed out radially by delta, and the vertices within it
  Polyline grown;
  grown.closed = true;
  for (const Vec3& p : s.boundary[0].points) {
    const Vec3 r(p.x(), p.y(), 0);
    grown.points.push_back(r * ((r.norm() + delta) / r.norm()));
  }
  std::vector<std::int64_t> inside;
  for (std::size_t v = 0; v < s.n_vertices(); ++v)
    if (std::hypot(s.UV[2 * v], s.UV[2 * v + 1]) < 12 + delta) inside.push_back(static_cast<std::int64_t>(v));
  const Score sc = score(grown, inside, s);
  EXPECT_NEAR(sc.mean_to_truth, 2, 0.02);
  EXPECT_NEAR(sc.p95_to_truth, 2, 0.02);
  EXPECT_NEAR(sc.mean_from_truth, 2, 0.02);
  EXPECT_NEAR(sc.max_from_truth, 2, 0.03);
  EXPECT_NEAR(sc.iou, 144.0 / ((12 + delta) * (12 + delta)), 0.01);
  EXPECT_EQ(sc.common_vertices, sc.truth_vertices);

  // a contour translated sideways: distances between 0 and delta, mean about 2/pi of it
  Polyline moved = s.boundary[0];
  for (Vec3& p : moved.points) p.x() += delta;
  const Score t = score(moved, s.relief_vertices(), s);
  EXPECT_GT(t.mean_to_truth, 0.55 * 2);
  EXPECT_LT(t.mean_to_truth, 0.75 * 2);
  EXPECT_NEAR(t.max_to_truth, 2, 0.05);
  EXPECT_LT(t.p95_to_truth, 2.0 + 1e-9);
  EXPECT_GT(t.p95_to_truth, 1.8);
  EXPECT_THROW(score(Polyline{}, {}, s), Error);
}

TEST(Synthetic, DeterministicForASeed) {
  ScanSpec spec = make_spec(Shape::Duck, Background::Saddle, 20000);
  spec.noise = 0.1;
  spec.detail = 0.2;
  const Scan a = generate(spec), b = generate(spec);
  EXPECT_EQ(a.V, b.V);
  EXPECT_EQ(a.F, b.F);
  EXPECT_EQ(a.relief, b.relief);
  ASSERT_EQ(a.boundary.size(), b.boundary.size());
  EXPECT_EQ(a.boundary[0].points, b.boundary[0].points);
  PickSpec ps;
  ps.start = Start::Zigzag;
  EXPECT_EQ(a.picks(ps).vertices, b.picks(ps).vertices);
  spec.seed = 2;
  const Scan c = generate(spec);
  EXPECT_NE(a.V, c.V);
  EXPECT_NE(a.F, c.F);  // different diagonals
}

TEST(Synthetic, BadParametersThrow) {
  ScanSpec spec;
  spec.h = 0;
  EXPECT_THROW(generate(spec), Error);
  spec = ScanSpec();
  spec.jitter = 0.5;
  EXPECT_THROW(generate(spec), Error);
  spec = ScanSpec();
  spec.background = Background::Sphere;
  spec.radius = 10;
  EXPECT_THROW(generate(spec), Error);
  EXPECT_THROW(parse_shape("cat"), Error);
  EXPECT_EQ(parse_background("saddle"), Background::Saddle);
  EXPECT_EQ(parse_start(to_string(Start::Zigzag)), Start::Zigzag);
  const Scan s = generate(make_spec(Shape::Duck, Background::Plane, 10000));
  PickSpec ps;
  ps.distance = 30;  // a ring 30 away from the duck leaves the 80 x 56 domain
  EXPECT_THROW(s.picks(ps), Error);
}

TEST(Synthetic, FilesRoundTrip) {
  const Scan s = generate(make_spec(Shape::Open, Background::Cylinder, 10000));
  PickSpec ps;
  ps.reverse = true;
  const Picks p = s.picks(ps);
  const std::string prefix = ::testing::TempDir() + "synthetic_roundtrip";
  write_ply(s, prefix + ".ply");
  write_truth_json(s, p, prefix + ".truth.json");
  std::ifstream ply(prefix + ".ply", std::ios::binary);
  std::string line, header;
  while (std::getline(ply, line) && line != "end_header") header += line + "\n";
  EXPECT_NE(header.find("binary_little_endian"), std::string::npos);
  EXPECT_NE(header.find("element vertex " + std::to_string(s.n_vertices())), std::string::npos);
  EXPECT_NE(header.find("element face " + std::to_string(s.n_faces())), std::string::npos);
  std::vector<float> xyz(3 * s.n_vertices());
  ply.read(reinterpret_cast<char*>(xyz.data()), static_cast<std::streamsize>(xyz.size() * sizeof(float)));
  ASSERT_TRUE(ply.good());
  EXPECT_NEAR(xyz[3 * 123 + 2], s.V[3 * 123 + 2], 1e-5);
  unsigned char count = 0;
  std::int32_t idx[3];
  ply.read(reinterpret_cast<char*>(&count), 1);
  ply.read(reinterpret_cast<char*>(idx), 12);
  EXPECT_EQ(count, 3);
  EXPECT_EQ(idx[2], s.F[2]);

  std::ifstream js(prefix + ".truth.json");
  const nlohmann::json j = nlohmann::json::parse(js);
  EXPECT_EQ(j["relief_vertices"].get<std::vector<std::int64_t>>(), s.relief_vertices());
  EXPECT_EQ(j["picks"].get<std::vector<std::int64_t>>(), p.vertices);
  EXPECT_EQ(j["open"].get<bool>(), true);
  EXPECT_EQ(j["relief_side"].get<std::string>(), "right");
  EXPECT_EQ(j["triangles"].get<std::size_t>(), s.n_faces());
  EXPECT_DOUBLE_EQ(j["average_edge"].get<double>(), s.average_edge);
  ASSERT_EQ(j["boundary"].size(), 1u);
  EXPECT_EQ(j["boundary"][0].size(), s.boundary[0].points.size());
  EXPECT_FALSE(j["boundary_closed"][0].get<bool>());
  const Mesh loaded = Mesh::load(prefix + ".ply");  // OpenMesh's reader agrees with our writer
  EXPECT_EQ(static_cast<std::size_t>(loaded.n_faces()), s.n_faces());
  EXPECT_EQ(loaded.input_vertex_count(), s.n_vertices());
  std::remove((prefix + ".ply").c_str());
  std::remove((prefix + ".truth.json").c_str());
}

TEST(Synthetic, EngineMeshAcceptsTheScanUnchanged) {
  ScanSpec spec = make_spec(Shape::Open, Background::Sphere, 20000);
  spec.noise = 0.05;
  const Scan s = generate(spec);
  const Mesh mesh = to_mesh(s);
  EXPECT_EQ(static_cast<std::size_t>(mesh.n_vertices()), s.n_vertices());
  EXPECT_EQ(static_cast<std::size_t>(mesh.n_faces()), s.n_faces());
  EXPECT_EQ(mesh.report().components, 1u);
  EXPECT_EQ(mesh.report().degenerate_faces, 0u);
  EXPECT_EQ(mesh.report().nonmanifold_faces, 0u);
  EXPECT_EQ(mesh.report().duplicate_vertices_merged, 0u);
  EXPECT_EQ(mesh.report().boundary_edges, static_cast<std::size_t>(2 * (s.grid_u - 1 + s.grid_v - 1)));
  for (std::size_t v = 0; v < s.n_vertices(); v += 97) EXPECT_EQ(mesh.input_to_mesh(v), static_cast<int>(v));
  EXPECT_NEAR(mesh.average_edge_length(), s.average_edge, 1e-6 * s.average_edge);
  // open picks: their ends are mesh-boundary vertices for the engine too
  const Picks p = s.picks();
  EXPECT_TRUE(mesh.is_boundary_vertex(mesh.input_to_mesh(p.vertices.front())));
  EXPECT_TRUE(mesh.is_boundary_vertex(mesh.input_to_mesh(p.vertices.back())));
}

// --- the random family (make-scan --random) ---------------------------------------------

TEST(SyntheticRandom, DeterministicForASeedAndDifferentAcrossSeeds) {
  const RandomScan a = generate_random(3), b = generate_random(3), c = generate_random(4);
  EXPECT_EQ(a.scan.V, b.scan.V);
  EXPECT_EQ(a.scan.F, b.scan.F);
  EXPECT_EQ(a.picks.vertices, b.picks.vertices);
  EXPECT_EQ(a.draw.axes, b.draw.axes);
  EXPECT_NE(a.draw.axes, c.draw.axes);
}

TEST(SyntheticRandom, DrawsStayInTheirRanges) {
  std::map<std::string, int> shapes, backgrounds, textures, details, starts;
  for (std::uint64_t seed = 0; seed < 300; ++seed) {
    const RandomDraw d = draw_random(seed);
    ASSERT_GE(d.spec.triangles, 15000u);
    ASSERT_LE(d.spec.triangles, 250000u);
    const double h_edges = d.axes["h_edges"].get<double>();
    ASSERT_GE(h_edges, 1.0);
    ASSERT_LE(h_edges, 13.0);
    ASSERT_GE(d.typed_factor, 0.5);
    ASSERT_LE(d.typed_factor, 2.0);
    ASSERT_LE(d.spec.noise, 0.05);
    ASSERT_LE(std::abs(d.spec.texture_amplitude), 0.3);
    if (d.spec.step == Step::Blended) {
      ASSERT_LE(d.spec.blend_width, 1.0);
    }
    ++shapes[d.axes["shape"].get<std::string>()];
    ++backgrounds[d.axes["background"].get<std::string>()];
    ++textures[d.axes["texture"].get<std::string>()];
    ++details[d.axes["detail"].get<std::string>()];
    ++starts[d.axes["start"].get<std::string>()];
  }
  // Every value of every axis is drawn.
  EXPECT_EQ(shapes.size(), 8u);
  EXPECT_EQ(backgrounds.size(), 6u);
  EXPECT_EQ(textures.size(), 3u);
  EXPECT_EQ(details.size(), 6u);
  EXPECT_EQ(starts.size(), 3u);
}

TEST(SyntheticRandom, ScansAreConsistentWithTheirTruth) {
  for (std::uint64_t seed = 0; seed < 12; ++seed) {
    const RandomScan r = generate_random(seed);
    const Scan& s = r.scan;
    SCOPED_TRACE("seed " + std::to_string(seed) + " " + r.draw.axes.dump());
    const bool open_shape = s.spec.shape == Shape::Band || s.spec.shape == Shape::Open;
    ASSERT_EQ(s.boundary.size(), 1u);
    EXPECT_EQ(s.open, open_shape);
    EXPECT_EQ(r.picks.closed, !open_shape);
    EXPECT_NEAR(static_cast<double>(s.n_faces()), static_cast<double>(s.spec.triangles), 0.02 * s.spec.triangles);
    // Relief flags are the silhouette; picks lie outside it, on the background.
    for (std::size_t v = 0; v < s.n_vertices(); v += 7) ASSERT_EQ(s.relief[v] != 0, sd_at(s, v) < 0);
    for (std::int64_t p : r.picks.vertices) {
      ASSERT_GE(p, 0);
      EXPECT_GT(sd_at(s, p), 0.5 * s.h) << "pick " << p;
    }
    // Each vertex is its base plus the three heights along the background normal.
    for (std::size_t v = 0; v < s.n_vertices(); v += 5) {
      const double u = s.UV[2 * v], w = s.UV[2 * v + 1];
      const Vec3 expected = s.surface(u, w, 0) +
                            (s.relief_height[v] + s.texture_height[v] + s.noise_height[v]) * s.background_normal(u, w);
      ASSERT_LT((s.vertex(v) - expected).norm(), 1e-9 * (1 + s.h)) << "vertex " << v;
      if (!s.relief[v]) {
        ASSERT_EQ(s.relief_height[v], 0.0);
      }
    }
    const IouFloor floor = one_edge_floor(s);
    EXPECT_GT(floor.area, 0.5);
    EXPECT_LT(floor.area, 1.0);
  }
}

// Picks a user would make: every vertex once, and round a closed relief a polygon that does not cross
// itself and holds all of it (in the parameter plane). Seeds 4061 (a pick moved onto a texture dot
// another pick had), 151 (a zigzag on a mesh one edge per h that crossed itself) and 58, 1105, 2120,
// 3187 (a ring that missed part of the relief, or ran inside a C's hole) broke this before 5 December
// 2026; the engine refused each (a repeated pick, a crossing order, a contour a few h long, nothing
// enclosed rising), which measured nothing about the segmentation.
TEST(SyntheticRandom, PicksAreDistinctAndGoRoundAClosedRelief) {
  using Vec2 = Eigen::Vector2d;
  auto crosses = [](const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
    auto side = [](const Vec2& p, const Vec2& q, const Vec2& r) {
      return (q.x() - p.x()) * (r.y() - p.y()) - (q.y() - p.y()) * (r.x() - p.x());
    };
    return side(c, d, a) * side(c, d, b) < 0 && side(a, b, c) * side(a, b, d) < 0;
  };
  std::vector<std::uint64_t> seeds = {58, 151, 1105, 2120, 3187, 4061};
  for (std::uint64_t s = 0; s < 20; ++s) seeds.push_back(s);
  for (const std::uint64_t seed : seeds) {
    const RandomScan r = generate_random(seed);
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::vector<std::int64_t> sorted = r.picks.vertices;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
    if (!r.picks.closed) continue;
    std::vector<Vec2> poly;
    for (std::int64_t p : r.picks.vertices) poly.emplace_back(r.scan.UV[2 * p], r.scan.UV[2 * p + 1]);
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = i + 2; j < n; ++j) {
        if (i == 0 && j == n - 1) continue;
        EXPECT_FALSE(crosses(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n]));
      }
    std::size_t outside = 0;
    for (std::size_t k = 0; k < r.scan.relief.size(); k += 3) {
      if (!r.scan.relief[k]) continue;
      const Vec2 q(r.scan.UV[2 * k], r.scan.UV[2 * k + 1]);
      bool in = false;
      for (std::size_t a = 0, b = n - 1; a < n; b = a++)
        if ((poly[a].y() > q.y()) != (poly[b].y() > q.y()) &&
            q.x() < (poly[b].x() - poly[a].x()) * (q.y() - poly[a].y()) / (poly[b].y() - poly[a].y()) + poly[a].x())
          in = !in;
      outside += in ? 0 : 1;
    }
    EXPECT_EQ(outside, 0u);
  }
}

TEST(SyntheticRandom, BackgroundNormalsAreUnitAndOrthogonalToTheSurface) {
  for (Background bg : {Background::Vase, Background::Wavy}) {
    ScanSpec spec = make_spec(Shape::Duck, bg, 20000);
    const Scan s = generate(spec);
    for (double u : {-30.0, -5.0, 12.0, 33.0})
      for (double v : {-20.0, 0.0, 17.0}) {
        const Vec3 n = s.background_normal(u, v);
        EXPECT_NEAR(n.norm(), 1.0, 1e-12);
        const double e = 1e-5;
        const Vec3 du = (s.surface(u + e, v) - s.surface(u - e, v)) / (2 * e);
        const Vec3 dv = (s.surface(u, v + e) - s.surface(u, v - e)) / (2 * e);
        EXPECT_NEAR(n.dot(du.normalized()), 0.0, 1e-6);
        EXPECT_NEAR(n.dot(dv.normalized()), 0.0, 1e-6);
        EXPECT_GT(n.dot(du.cross(dv)), 0);  // the +normal side sees (u, v) counter-clockwise
      }
  }
}

TEST(SyntheticRandom, TexturesStayWithinTheirAmplitudeOffTheRelief) {
  for (Texture t : {Texture::Striations, Texture::Dots}) {
    ScanSpec spec = make_spec(Shape::Disk, Background::Plane, 40000);
    spec.texture = t;
    spec.texture_amplitude = 0.25;
    spec.texture_period = 3;
    spec.dot_radius = 1.2;
    const Scan s = generate(spec);
    double lo = 0, hi = 0;
    for (std::size_t v = 0; v < s.n_vertices(); ++v) {
      if (s.relief[v]) continue;
      lo = std::min(lo, s.texture_height[v]), hi = std::max(hi, s.texture_height[v]);
      ASSERT_NEAR(s.vertex(v).z(), s.texture_height[v], 1e-12);
    }
    EXPECT_GE(lo, t == Texture::Dots ? 0.0 : -0.25 - 1e-12);
    EXPECT_LE(hi, 0.25 + 1e-12);
    EXPECT_GT(hi, 0.2);  // the texture is there
    // Sharp step: no texture on the relief's top.
    for (std::size_t v = 0; v < s.n_vertices(); ++v) {
      if (s.relief[v]) {
        ASSERT_EQ(s.texture_height[v], 0.0);
      }
    }
  }
}

TEST(SyntheticRandom, BoundaryLiesOnTheTexturedBackground) {
  // On a plane with striations, the surface off the relief is z = the texture; the true boundary (the
  // foot of the step) lies on it, not on the smooth base under it, so a contour exactly at the foot
  // scores 0 and the one-edge floor grows from where the scan's surface is.
  ScanSpec spec = make_spec(Shape::Disk, Background::Plane, 40000);
  spec.texture = Texture::Striations;
  spec.texture_amplitude = 0.25;
  spec.texture_period = 3;
  spec.texture_angle = 0.4;
  const Scan s = generate(spec);
  ASSERT_EQ(s.boundary.size(), 1u);
  const double A = spec.texture_amplitude * spec.h, P = spec.texture_period * spec.h;
  double highest = 0, nearest_sum = 0;
  for (const Vec3& p : s.boundary[0].points) {
    const double texture = A * std::sin(2 * M_PI * (p.x() * std::cos(spec.texture_angle) + p.y() * std::sin(spec.texture_angle)) / P);
    ASSERT_NEAR(p.z(), texture, 1e-9);
    highest = std::max(highest, std::fabs(p.z()));
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t v = 0; v < s.n_vertices(); ++v)
      if (!s.relief[v]) nearest = std::min(nearest, (s.vertex(v) - p).norm());
    nearest_sum += nearest;
  }
  EXPECT_GT(highest, 0.9 * A);  // the boundary does go up and down with the texture
  // The background's vertices lie within an edge of it (on the base it was up to A = 0.25 h away).
  EXPECT_LT(nearest_sum / s.boundary[0].points.size(), s.average_edge);
}

TEST(SyntheticRandom, OneEdgeFloorMatchesAnOffsetRegion) {
  // A plane disk of radius 12 with a negligible step (so the wall adds no area): growing it by one
  // edge e gives about (12 / (12 + e))^2.
  ScanSpec spec = make_spec(Shape::Disk, Background::Plane, 60000);
  spec.h = 0.02;
  const Scan s = generate(spec);
  const IouFloor floor = one_edge_floor(s);
  const double expected = std::pow(12 / (12 + s.average_edge), 2);
  EXPECT_NEAR(floor.area, expected, 0.1 * (1 - expected));
  EXPECT_NEAR(floor.vertices, expected, 0.1 * (1 - expected));
  // The same count by brute force over the boundary's segments.
  const auto& pts = s.boundary[0].points;
  std::size_t truth = 0, grown = 0;
  for (std::size_t v = 0; v < s.n_vertices(); ++v) {
    bool near = s.relief[v] != 0;
    if (!near && sd_at(s, v) > 2 * s.average_edge) continue;  // on the plane: far in (u, v) is far in 3D
    for (std::size_t i = 0; i < pts.size() && !near; ++i) {
      const Vec3 a = pts[i], b = pts[(i + 1) % pts.size()], p = s.vertex(v);
      const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      near = (p - (a + t * (b - a))).norm() <= s.average_edge;
    }
    truth += s.relief[v], grown += near;
  }
  ASSERT_GT(grown, truth);
  EXPECT_NEAR(floor.vertices, static_cast<double>(truth) / grown, 1e-12);
}

TEST(SyntheticRandom, NearestVertexOnAGradedTriangulation) {
  ScanSpec spec = make_spec(Shape::Disk, Background::Plane, 20000);
  spec.grade_u = 0.35;
  spec.grade_v = 0.3;
  const Scan s = generate(spec);
  for (std::size_t v = 0; v < s.n_vertices(); v += 37) {
    const double u = s.UV[2 * v] + 0.1 * s.spacing_u, w = s.UV[2 * v + 1] - 0.1 * s.spacing_v;
    std::size_t best = 0;
    double best_d = 1e300;
    for (std::size_t k = 0; k < s.n_vertices(); ++k) {
      const double d = std::hypot(s.UV[2 * k] - u, s.UV[2 * k + 1] - w);
      if (d < best_d) best_d = d, best = k;
    }
    ASSERT_EQ(s.nearest_vertex(u, w), static_cast<int>(best)) << "vertex " << v;
  }
}

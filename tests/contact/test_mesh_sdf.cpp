// Mesh obstacles' distance grids (mesh_sdf.h) and their reading (obstacle_sdf.h,
// mesh_surface in obstacle_shapes.h): every grid node within the exact band is the exact
// distance to the triangles, beyond it an upper bound, with the sign of an independent
// inside test (the generalised winding number);
// the interpolated distance of a cube mesh and of an icosphere is within the
// interpolation bound sqrt(3)/2 cell of the analytic box and sphere (plus the icosphere's
// facet depth) at random points, exact above a flat face, of the right sign away from the
// surface, and never below the SIMD stage's bounding-sphere bound; a float copy reads the
// same distances. Prints the start-up time for a 5k-triangle mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "sim/contact/mesh_sdf.h"
#include "sim/contact/obstacle_shapes.h"
#include "sim/mesh/surface_generators.h"
#include "sim/mesh/surface_mesh.h"

using namespace softtled;

namespace {

const double kInterp = std::sqrt(3.0) / 2;  // interpolation bound, in cells

// The mesh obstacle of grid g at the origin, unrotated, reading g's own doubles.
Obstacle<double> mesh_obstacle(const SdfGrid& g) {
  Obstacle<double> o;
  o.shape = kObstacleMesh;
  o.sdf = g.view<double>(g.value.data());
  return o;
}

// Brute force over every triangle.
double exact_unsigned(const SurfaceMesh& s, const double p[3]) {
  double best = INFINITY;
  for (int t = 0; t < s.ntri(); ++t) {
    double q[3];
    closest_point_on_triangle(p, &s.xyz[3 * s.tri[3 * t]], &s.xyz[3 * s.tri[3 * t + 1]], &s.xyz[3 * s.tri[3 * t + 2]], q);
    best = std::min(best, std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2])));
  }
  return best;
}

void node(const SdfGrid& g, int i, int j, int k, double p[3]) {
  p[0] = g.origin[0] + i * g.cell, p[1] = g.origin[1] + j * g.cell, p[2] = g.origin[2] + k * g.cell;
}

}  // namespace

TEST(MeshSdf, GridNodesAreExactDistancesWithTheWindingNumbersSign) {
  // A coarse torus (non-convex, 480 triangles) on a 24-cell grid: within the exact band
  // every node's |value| is the brute-force distance to the triangles (the bounded BVH
  // search misses nothing); beyond it the swept value is never below that distance nor
  // the band, and stays within a tenth of a cell of it. Its sign is the winding number's
  // (the three scan-line parities agree with it).
  const SurfaceMesh s = make_torus(7.5e-3, 2.5e-3, 24, 10);
  const SdfGrid g = build_mesh_sdf(s, 24);
  const double band = kSdfExactBandCells * g.cell;
  int wrong_sign = 0, inside = 0, beyond = 0;
  double worst_band = 0, worst_beyond = 0, below = INFINITY;
  for (int k = 0; k < g.n[2]; ++k)
    for (int j = 0; j < g.n[1]; ++j)
      for (int i = 0; i < g.n[0]; ++i) {
        double p[3];
        node(g, i, j, k, p);
        const double v = g.value[i + g.n[0] * (j + g.n[1] * std::size_t(k))];
        const double d = exact_unsigned(s, p);
        if (d < band) {
          worst_band = std::max(worst_band, std::fabs(std::fabs(v) - d));
        } else {
          ++beyond;
          worst_beyond = std::max(worst_beyond, std::fabs(v) - d);
          below = std::min({below, std::fabs(v) - d, std::fabs(v) - band});
        }
        if (d < 1e-3 * g.cell) continue;  // on the surface: either sign
        // generalized_winding_number (surface_mesh.h): independent of the grid's ray parity
        const bool in = generalized_winding_number(s, p) > 0.5;
        inside += in;
        wrong_sign += in != (v < 0);
      }
  std::printf("torus grid %d x %d x %d: within %.0f cells max | |value| - exact | = %.3g m; beyond (%d nodes) "
              "|value| - exact from %.3g m to %.3g cell; %d nodes inside, %d of wrong sign\n",
              g.n[0], g.n[1], g.n[2], kSdfExactBandCells, worst_band, beyond, below, worst_beyond / g.cell, inside,
              wrong_sign);
  EXPECT_LT(worst_band, 1e-15);
  EXPECT_GT(beyond, 1000);
  EXPECT_GE(below, -1e-15);
  EXPECT_LT(worst_beyond, 0.1 * g.cell);
  EXPECT_EQ(wrong_sign, 0);
  EXPECT_GT(inside, 100);
  EXPECT_EQ(g.n[0], 24 + 1 + 2 * kSdfPadCells) << "the longest side: resolution cells plus the padding";
}

TEST(MeshSdf, CubeMeshReadsAsTheAnalyticBox) {
  // A 2 m cube of 12 triangles (its faces lie on grid planes along x, where lines could
  // graze its diagonals), 20 cells across: at random points in and around the grid the
  // mesh obstacle's distance is the analytic box's within sqrt(3)/2 cell, with its sign
  // wherever the box's distance is larger than that, and exact with normal +y above the
  // top face (the distance is linear over those cells).
  const SurfaceMesh s = make_box(2, 2, 2, 1, 1, 1);
  const SdfGrid g = build_mesh_sdf(s, 20);
  const Obstacle<double> mesh = mesh_obstacle(g);
  Obstacle<double> box;
  box.shape = kObstacleBox;
  for (int k = 0; k < 3; ++k) box.e[k] = 1;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.6, 1.6);
  double worst = 0, worst_top = 0, worst_top_n = 0, mean = 0;
  int wrong_sign = 0, n_top = 0;
  const int N = 20000;
  for (int t = 0; t < N; ++t) {
    const double x[3] = {U(rng), U(rng), U(rng)};
    const SurfacePoint<double> a = box_surface(box, x), m = obstacle_surface(mesh, x);
    const double e = std::fabs(m.dist - a.dist);
    worst = std::max(worst, e);
    mean += e / N;
    if (std::fabs(a.dist) > kInterp * g.cell) wrong_sign += (a.dist < 0) != (m.dist < 0);
    if (x[1] > 1 && std::fabs(x[0]) < 1 - g.cell && std::fabs(x[2]) < 1 - g.cell && x[1] < 1 + 3 * g.cell) {
      ++n_top;
      worst_top = std::max(worst_top, e);
      worst_top_n = std::max({worst_top_n, std::fabs(m.n[0]), std::fabs(m.n[1] - 1), std::fabs(m.n[2])});
    }
  }
  std::printf("cube, cell %.3g m: max error %.3g m (%.3f cell), mean %.3g cell; above the top face (%d points) %.3g m, "
              "normal off +y by %.3g\n",
              g.cell, worst, worst / g.cell, mean / g.cell, n_top, worst_top, worst_top_n);
  EXPECT_LT(worst, kInterp * g.cell);
  EXPECT_EQ(wrong_sign, 0);
  EXPECT_GT(n_top, 100);
  EXPECT_LT(worst_top, 1e-14);
  EXPECT_LT(worst_top_n, 1e-14);
}

TEST(MeshSdf, IcosphereReadsAsTheAnalyticSphere) {
  // An icosphere of radius 1 (1280 triangles; its facets lie up to `depth` inside the
  // sphere), 32 cells across, turned and moved: at random points in the grid's box within
  // sqrt(3)/2 cell + depth of |x| - 1, of its sign beyond that, the normal within 8 degrees
  // of the radial direction near the surface (the facets' own normals are up to ~5 degrees
  // off it); beyond the box never below |x| - 1 less that bound (a far node stays free);
  // everywhere never below the bounding-sphere bound the SIMD stage filters with.
  const SurfaceMesh s = make_sphere(1, 3);
  double depth = 0;
  for (int t = 0; t < s.ntri(); ++t) {
    const double o[3] = {0, 0, 0};
    double q[3];
    closest_point_on_triangle(o, &s.xyz[3 * s.tri[3 * t]], &s.xyz[3 * s.tri[3 * t + 1]], &s.xyz[3 * s.tri[3 * t + 2]], q);
    depth = std::max(depth, 1 - std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]));
  }
  const SdfGrid g = build_mesh_sdf(s, 32);
  Obstacle<double> mesh = mesh_obstacle(g);
  // Turned and moved: the frame (c, R) must be applied both ways.
  const double c = std::cos(0.3), sn = std::sin(0.3);
  const double R[9] = {c, -sn, 0, sn, c, 0, 0, 0, 1};
  for (int k = 0; k < 9; ++k) mesh.R[k] = R[k];
  const double centre[3] = {0.5, -2, 3};
  for (int k = 0; k < 3; ++k) mesh.c[k] = centre[k];
  double cb[3], rb;
  obstacle_bound(mesh, cb, rb);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-2.5, 2.5);
  const double bound = kInterp * g.cell + depth;
  double worst = 0, worst_angle = 0, mean = 0, bound_gap = INFINITY, below_beyond = INFINITY;
  int wrong_sign = 0, n_in = 0, n_beyond = 0;
  const int N = 20000;
  for (int t = 0; t < N; ++t) {
    const double v[3] = {U(rng), U(rng), U(rng)};
    const double x[3] = {centre[0] + v[0], centre[1] + v[1], centre[2] + v[2]};
    const double r = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    const SurfacePoint<double> m = obstacle_surface(mesh, x);
    const double dx[3] = {x[0] - cb[0], x[1] - cb[1], x[2] - cb[2]};
    bound_gap = std::min(bound_gap, m.dist - (std::sqrt(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]) - rb));
    double q[3];  // in the grid's frame: R^T v
    for (int k = 0; k < 3; ++k) q[k] = R[k] * v[0] + R[3 + k] * v[1] + R[6 + k] * v[2];
    bool in_box = true;
    for (int k = 0; k < 3; ++k) in_box = in_box && q[k] >= g.origin[k] && q[k] <= g.origin[k] + (g.n[k] - 1) * g.cell;
    if (!in_box) {
      ++n_beyond;
      below_beyond = std::min(below_beyond, m.dist - (r - 1));
      continue;
    }
    ++n_in;
    const double e = std::fabs(m.dist - (r - 1));
    worst = std::max(worst, e);
    mean += e;
    if (std::fabs(r - 1) > bound) wrong_sign += (r < 1) != (m.dist < 0);
    if (std::fabs(r - 1) < 0.2)
      worst_angle = std::max(worst_angle, std::acos(std::min(1.0, (m.n[0] * v[0] + m.n[1] * v[1] + m.n[2] * v[2]) / r)));
  }
  mean /= n_in;
  std::printf("icosphere, cell %.3g, facet depth %.3g: in the grid (%d points) max error %.3g (%.3f cell), mean %.3g "
              "cell, normal within %.2f deg near the surface; beyond it (%d points) distance - (|x| - 1) >= %.3g; "
              "distance - sphere bound >= %.3g\n",
              g.cell, depth, n_in, worst, worst / g.cell, mean / g.cell, worst_angle * 180 / M_PI, n_beyond, below_beyond,
              bound_gap);
  EXPECT_GT(n_in, 1000);
  EXPECT_GT(n_beyond, 1000);
  EXPECT_LT(worst, bound);
  EXPECT_LT(mean, 0.1 * g.cell) << "away from the centre the interpolation error is far below the bound";
  EXPECT_EQ(wrong_sign, 0);
  EXPECT_LT(worst_angle, 8 * M_PI / 180);
  EXPECT_GT(below_beyond, -bound);
  EXPECT_GE(bound_gap, -1e-12);
}

TEST(MeshSdf, FloatCopyReadsTheSameDistances) {
  // A backend's float copy of the grid (the CPU solver in float): the same distances to
  // float rounding of coordinates of size 1.
  const SdfGrid g = build_mesh_sdf(make_sphere(1, 2), 16);
  const std::vector<float> vf(g.value.begin(), g.value.end());
  Obstacle<float> of;
  of.shape = kObstacleMesh;
  of.sdf = g.view<float>(vf.data());
  const Obstacle<double> od = mesh_obstacle(g);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-2, 2);
  double worst = 0;
  for (int t = 0; t < 2000; ++t) {
    const double x[3] = {U(rng), U(rng), U(rng)};
    const float xf[3] = {float(x[0]), float(x[1]), float(x[2])};
    worst = std::max(worst, std::fabs(double(obstacle_surface(of, xf).dist) - obstacle_surface(od, x).dist));
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(MeshSdf, StartUpTimeOfA5kTriangleMesh) {
  // The cost README "Obstacles" quotes: a 5120-triangle icosphere at the default and the
  // largest resolution (printed; timings vary with the machine). The grid's size is the
  // documented one.
  const SurfaceMesh s = make_sphere(0.01, 4);
  ASSERT_EQ(s.ntri(), 5120);
  for (int res : {kDefaultSdfResolution, kMaxSdfResolution}) {
    const SdfGrid g = build_mesh_sdf(s, res);
    std::printf("%d triangles, resolution %d: %d x %d x %d nodes, built in %.3f s\n", s.ntri(), res, g.n[0], g.n[1], g.n[2],
                g.build_seconds);
    for (int k = 0; k < 3; ++k) EXPECT_LE(g.n[k], res + 1 + 2 * kSdfPadCells);
    // A node inside the sphere, away from the surface: its distance is about 0.01 - r.
    const double p[3] = {0, 0, 0};
    const SurfacePoint<double> c = obstacle_surface(mesh_obstacle(g), p);
    EXPECT_NEAR(c.dist, -0.01, 1e-3 * 0.01 + kInterp * g.cell);
  }
}

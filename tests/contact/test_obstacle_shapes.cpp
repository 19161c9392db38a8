// Signed distance and outward normal of the rigid obstacles (obstacle_shapes.h) against
// analytic values: sphere, rotated box (outside a face, an edge and a corner; inside,
// nearest face), capsule (beside the axis, beyond each end); and the obstacle projection
// (node_contact.h): lands on the surface, sliding / static like a plane, a moving obstacle
// pushes by its own displacement, a free node's step untouched bit for bit.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/contact/node_contact.h"
#include "sim/contact/obstacle_shapes.h"
#include "sim/solver/solver.h"

using namespace softtled;

namespace {

constexpr double kPi = 3.14159265358979323846;

Obstacle<double> sphere(double cx, double cy, double cz, double r) {
  Obstacle<double> o;
  o.shape = kObstacleSphere;
  o.c[0] = cx, o.c[1] = cy, o.c[2] = cz;
  o.r = r;
  return o;
}

// A box of half sides (hx, hy, hz) at c, turned by `deg` about z.
Obstacle<double> box_z(const double c[3], double hx, double hy, double hz, double deg) {
  ObstacleSpec s;
  s.shape = kObstacleBox;
  for (int k = 0; k < 3; ++k) s.center[k] = c[k];
  s.half[0] = hx, s.half[1] = hy, s.half[2] = hz;
  const double a = deg * kPi / 180;
  const double R[9] = {std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1};
  for (int k = 0; k < 9; ++k) s.R[k] = R[k];
  return obstacle_from<double>(s, 0);
}

Obstacle<double> capsule(const double a[3], const double b[3], double r) {
  ObstacleSpec s;
  s.shape = kObstacleCapsule;
  for (int k = 0; k < 3; ++k) s.center[k] = a[k], s.b[k] = b[k];
  s.radius = r;
  return obstacle_from<double>(s, 0);
}

void expect_normal(const SurfacePoint<double>& sp, double nx, double ny, double nz, double tol = 1e-14) {
  EXPECT_NEAR(sp.n[0], nx, tol);
  EXPECT_NEAR(sp.n[1], ny, tol);
  EXPECT_NEAR(sp.n[2], nz, tol);
}

}  // namespace

TEST(ObstacleShapes, SphereDistanceAndNormal) {
  const Obstacle<double> o = sphere(1, 2, 3, 0.5);
  const double out[3] = {1 + 3, 2 + 4, 3};  // 5 from the centre along (0.6, 0.8, 0)
  SurfacePoint<double> sp = obstacle_surface(o, out);
  EXPECT_NEAR(sp.dist, 4.5, 1e-14);
  expect_normal(sp, 0.6, 0.8, 0);
  const double in[3] = {1, 2, 3 - 0.2};
  sp = obstacle_surface(o, in);
  EXPECT_NEAR(sp.dist, -0.3, 1e-14);
  expect_normal(sp, 0, 0, -1);
  const double centre[3] = {1, 2, 3};
  sp = obstacle_surface(o, centre);
  EXPECT_DOUBLE_EQ(sp.dist, -0.5);
  EXPECT_DOUBLE_EQ(sp.n[0] * sp.n[0] + sp.n[1] * sp.n[1] + sp.n[2] * sp.n[2], 1.0) << "a unit normal even at the centre";
}

TEST(ObstacleShapes, RotatedBoxFaceEdgeCornerAndInside) {
  // A 2 x 1 x 0.6 box at c turned 30 degrees about z: local axes ex = (cos, sin, 0),
  // ey = (-sin, cos, 0), ez = z.
  const double c[3] = {0.5, -1, 2}, a = 30 * kPi / 180;
  const Obstacle<double> o = box_z(c, 1.0, 0.5, 0.3, 30);
  const double ex[3] = {std::cos(a), std::sin(a), 0}, ey[3] = {-std::sin(a), std::cos(a), 0};
  auto at = [&](double qx, double qy, double qz, double x[3]) {
    for (int k = 0; k < 3; ++k) x[k] = c[k] + qx * ex[k] + qy * ey[k] + qz * (k == 2);
  };
  double x[3];
  // Outside the +y face, over its interior: distance along ey.
  at(0.3, 0.5 + 0.25, 0.1, x);
  SurfacePoint<double> sp = obstacle_surface(o, x);
  EXPECT_NEAR(sp.dist, 0.25, 1e-14);
  expect_normal(sp, ey[0], ey[1], ey[2]);
  // Outside the edge (+x, +y): from the edge, diagonal in the local xy plane.
  at(1.0 + 0.3, 0.5 + 0.4, 0.0, x);
  sp = obstacle_surface(o, x);
  EXPECT_NEAR(sp.dist, 0.5, 1e-14);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(sp.n[k], 0.6 * ex[k] + 0.8 * ey[k], 1e-14);
  // Outside the corner (+x, -y, -z): |(0.2, -0.2, -0.1)| = 0.3.
  at(1.2, -0.7, -0.4, x);
  sp = obstacle_surface(o, x);
  EXPECT_NEAR(sp.dist, 0.3, 1e-14);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(sp.n[k], (0.2 * ex[k] - 0.2 * ey[k]) / 0.3 + (k == 2 ? -0.1 / 0.3 : 0), 1e-13);
  // Inside, nearer the -z face (0.05) than any other (+x: 0.2, y: 0.3): distance -0.05, normal -z.
  at(0.8, 0.2, -0.25, x);
  sp = obstacle_surface(o, x);
  EXPECT_NEAR(sp.dist, -0.05, 1e-14);
  expect_normal(sp, 0, 0, -1);
  // Inside, nearest the +x face.
  at(0.9, 0.0, 0.0, x);
  sp = obstacle_surface(o, x);
  EXPECT_NEAR(sp.dist, -0.1, 1e-14);
  expect_normal(sp, ex[0], ex[1], ex[2]);
  // On the surface: distance 0.
  at(-1.0, 0.1, 0.1, x);
  sp = obstacle_surface(o, x);
  EXPECT_NEAR(sp.dist, 0.0, 1e-14);
  expect_normal(sp, -ex[0], -ex[1], -ex[2]);
}

TEST(ObstacleShapes, BoxRotationFromSceneAnglesTurnsTheAxes) {
  // The scene's rotation_deg [0, 0, 90] turns the box's x axis onto the world's y axis: a
  // 4 x 1 x 1 box then reaches 2 along y and 0.5 along x.
  ObstacleSpec s;
  s.shape = kObstacleBox;
  s.half[0] = 2, s.half[1] = 0.5, s.half[2] = 0.5;
  const double a = kPi / 2;
  const double R[9] = {std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1};
  for (int k = 0; k < 9; ++k) s.R[k] = R[k];
  const double above[3] = {0, 3, 0}, beside[3] = {1.5, 0, 0};
  EXPECT_NEAR(signed_distance(s, above), 1.0, 1e-12);
  EXPECT_NEAR(signed_distance(s, beside), 1.0, 1e-12);
}

TEST(ObstacleShapes, CapsuleSideAndEnds) {
  const double a[3] = {0, 0, 0}, b[3] = {2, 0, 0};
  const Obstacle<double> o = capsule(a, b, 0.5);
  const double side[3] = {1.2, 0, 1.5};  // beside the axis: 1.5 from it
  SurfacePoint<double> sp = obstacle_surface(o, side);
  EXPECT_NEAR(sp.dist, 1.0, 1e-14);
  expect_normal(sp, 0, 0, 1);
  const double past_b[3] = {2 + 0.6, 0.8, 0};  // beyond b: 1.0 from b
  sp = obstacle_surface(o, past_b);
  EXPECT_NEAR(sp.dist, 0.5, 1e-14);
  expect_normal(sp, 0.6, 0.8, 0);
  const double before_a[3] = {-0.3, 0, 0};  // inside the cap around a
  sp = obstacle_surface(o, before_a);
  EXPECT_NEAR(sp.dist, -0.2, 1e-14);
  expect_normal(sp, -1, 0, 0);
  const double in_axis[3] = {0.7, -0.1, 0};
  sp = obstacle_surface(o, in_axis);
  EXPECT_NEAR(sp.dist, -0.4, 1e-14);
  expect_normal(sp, 0, -1, 0);
}

TEST(ObstacleShapes, BoundingSphereHoldsTheShape) {
  const double c[3] = {1, 2, 3};
  const Obstacle<double> b = box_z(c, 1, 2, 2, 40);
  double cb[3], rb;
  obstacle_bound(b, cb, rb);
  EXPECT_DOUBLE_EQ(rb, 3.0);
  const double a[3] = {0, 0, 0}, e[3] = {0, 4, 0};
  obstacle_bound(capsule(a, e, 1), cb, rb);
  EXPECT_DOUBLE_EQ(rb, 3.0);
  EXPECT_DOUBLE_EQ(cb[1], 2.0);
}

TEST(ObstacleContact, SlidingLandsOnTheSphereAndKeepsTheTangentialStep) {
  const Obstacle<double> o = sphere(0, 0, 0, 1);
  const double x[3] = {0, 1 + 1e-4, 0};  // just above the top
  double du[3] = {3e-4, -4e-4, 0};
  EXPECT_EQ(project_to_obstacle(o, x, du, kSliding, 0.5), kSlide);
  EXPECT_NEAR(x[1] + du[1], 1.0, 1e-16) << "on the tangent plane at the top";
  EXPECT_DOUBLE_EQ(du[0], 3e-4);
  double ds[3] = {3e-4, -4e-4, 0};
  EXPECT_EQ(project_to_obstacle(o, x, ds, kStatic, 0.5), kStick);
  EXPECT_NEAR(ds[0], 3e-4 * 0.25, 1e-15) << "static: stops where its path meets the support (u_y / u^_y = 1/4)";
}

TEST(ObstacleContact, EqualsThePlaneRuleOnABoxFace) {
  // A box face and the plane through it: the same projected step in every mode.
  const double c[3] = {0, -1, 0};
  const Obstacle<double> o = box_z(c, 5, 1, 5, 20);
  const double a = 20 * kPi / 180;
  const Plane<double> pl{{c[0] - std::sin(a), c[1] + std::cos(a), 0}, {-std::sin(a), std::cos(a), 0}};  // c + ey
  for (int mode : {kSliding, kStatic, kCoulomb}) {
    const double x[3] = {-std::sin(a) * 1.0001, -1 + std::cos(a) * 1.0001, 0.2};
    double d1[3] = {2e-4, -3e-4, 1e-4}, d2[3] = {2e-4, -3e-4, 1e-4};
    const auto s1 = project_to_obstacle(o, x, d1, mode, 0.3);
    const auto s2 = project_to_plane(pl, x, d2, mode, 0.3);
    EXPECT_EQ(s1, s2);
    EXPECT_NE(s1, kFree);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(d1[k], d2[k], 1e-15) << "mode " << mode << " component " << k;
  }
}

TEST(ObstacleContact, MovingObstaclePushesByItsDisplacement) {
  // A wall-like sphere face moving +x by 1e-4 per step meets a node at rest 0 from it:
  // the node moves with it (sliding), its tangential step unchanged.
  Obstacle<double> o = sphere(-1, 0, 0, 1);
  o.d[0] = 1e-4;
  const double x[3] = {0, 0, 0};
  double du[3] = {0, 2e-5, 0};
  EXPECT_EQ(project_to_obstacle(o, x, du, kSliding, 0.0), kSlide);
  EXPECT_NEAR(du[0], 1e-4, 1e-18) << "pushed by the obstacle's own step";
  EXPECT_NEAR(du[1], 2e-5, 1e-18);
  // Static: the relative tangential step is removed; the node moves with the obstacle.
  double ds[3] = {0, 2e-5, 0};
  EXPECT_EQ(project_to_obstacle(o, x, ds, kStatic, 0.0), kStick);
  EXPECT_NEAR(ds[0], 1e-4, 1e-18);
  EXPECT_NEAR(ds[1], 0.0, 1e-18);
}

TEST(ObstacleContact, FreeNodeUntouchedBitForBit) {
  Obstacle<float> o;
  o.shape = kObstacleSphere;
  o.r = 1;
  o.d[0] = 0.1f, o.d[1] = 0.37f;
  const float x[3] = {3, 0, 0};
  float du[3] = {0.1f + 1e-7f, 0.3f, 0.7f};
  const float before[3] = {du[0], du[1], du[2]};
  EXPECT_EQ(project_to_obstacle(o, x, du, kSliding, 0.5f), kFree);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(du[k], before[k]);
}

TEST(ObstacleContact, PlanesThenObstaclesAndNoTunnelling) {
  ContactParams<double> c;
  c.nobstacles = 1;
  c.obstacles[0] = sphere(0, 0, 0, 0.01);
  // A fast node crossing the whole sphere in one step (from 2 cm above to 2 cm below):
  // projected onto the tangent plane at the top, not through.
  const double x[3] = {0, 0.03, 0};
  double du[3] = {0, -0.05, 0};
  EXPECT_NE(project_node_contacts(c, x, du), kFree);
  EXPECT_NEAR(x[1] + du[1], 0.01, 1e-15);
}

// The projection of eq. (11-12) on a single node: sliding keeps the tangential step,
// static scales it by u_y / u^_y, Coulomb switches between them at mu.
#include <gtest/gtest.h>

#include "sim/contact/plane_contact.h"

using namespace softtled;

namespace {
Plane<double> floor_plane() { return Plane<double>{{0, 0, 0}, {0, 1, 0}}; }
}  // namespace

TEST(PlaneContact, FreeNodeUntouched) {
  const double x[3] = {0, 1e-3, 0};
  double du[3] = {2e-4, -5e-4, 1e-4};  // stays above the plane
  EXPECT_EQ(project_to_plane(floor_plane(), x, du, kStatic, 0.5), kFree);
  EXPECT_DOUBLE_EQ(du[1], -5e-4);
}

TEST(PlaneContact, SlidingKeepsTangentialStepAndLandsOnPlane) {
  const double x[3] = {0, 1e-3, 0};
  double du[3] = {4e-3, -3e-3, -2e-3};
  EXPECT_EQ(project_to_plane(floor_plane(), x, du, kSliding, 0.5), kSlide);
  EXPECT_DOUBLE_EQ(x[1] + du[1], 0.0);
  EXPECT_DOUBLE_EQ(du[0], 4e-3);
  EXPECT_DOUBLE_EQ(du[2], -2e-3);
}

TEST(PlaneContact, StaticScalesTangentialAlongThePath) {
  const double x[3] = {0, 1e-3, 0};
  double du[3] = {4e-3, -3e-3, -2e-3};
  EXPECT_EQ(project_to_plane(floor_plane(), x, du, kStatic, 0.5), kStick);
  // u_y / u^_y = 1/3: the node stops where its straight path meets the plane.
  EXPECT_NEAR(du[0], 4e-3 / 3, 1e-18);
  EXPECT_NEAR(du[2], -2e-3 / 3, 1e-18);
  EXPECT_DOUBLE_EQ(x[1] + du[1], 0.0);
}

TEST(PlaneContact, CoulombSticksBelowMuAndSlidesAbove) {
  const double x[3] = {0, 0, 0};  // resting on the plane
  // Normal push 1e-6 into the plane; tangential 0.3e-6: sticks for mu = 0.5, slides for 0.2.
  double a[3] = {0.3e-6, -1e-6, 0};
  EXPECT_EQ(project_to_plane(floor_plane(), x, a, kCoulomb, 0.5), kStick);
  EXPECT_DOUBLE_EQ(a[0], 0.0);
  double b[3] = {0.3e-6, -1e-6, 0};
  EXPECT_EQ(project_to_plane(floor_plane(), x, b, kCoulomb, 0.2), kSlide);
  // Kinetic friction removes mu x the normal correction from the tangential step.
  EXPECT_NEAR(b[0], 0.3e-6 - 0.2 * 1e-6, 1e-20);
  EXPECT_DOUBLE_EQ(b[1], 0.0);
}

TEST(PlaneContact, NodeBelowPlaneIsPushedOut) {
  const double x[3] = {0, -2e-4, 0};
  double du[3] = {1e-4, 0, 0};
  EXPECT_EQ(project_to_plane(floor_plane(), x, du, kSliding, 0.5), kSlide);
  EXPECT_DOUBLE_EQ(x[1] + du[1], 0.0);
}

TEST(PlaneContact, TiltedPlaneProjectsAlongItsNormal) {
  const double s = std::sqrt(0.5);
  const Plane<double> pl{{0, 0, 0}, {-s, s, 0}};
  const double x[3] = {0, 1e-3, 0};
  double du[3] = {0, -3e-3, 0};
  project_to_plane(pl, x, du, kSliding, 0.0);
  const double xn[3] = {x[0] + du[0], x[1] + du[1], x[2] + du[2]};
  EXPECT_NEAR(plane_distance(pl, xn), 0.0, 1e-18);
}

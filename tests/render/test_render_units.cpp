// Render-side pieces that need no GL context: image comparison and PNG files, camera
// rays, planar shadows, mouse picking and the drag spring.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "render/camera.h"
#include "render/image.h"
#include "sim/io/output_file.h"
#include "render/math3d.h"
#include "render/scene_renderer.h"
#include "app/viewer_picking.h"
#include "sim/mesh/tet_mesh.h"
#include "sim/scene/simulation.h"
#include "tests/scene_helpers.h"

using namespace softtled;

namespace {
Image gradient(int w, int h) {
  Image im(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      unsigned char* p = im.px(x, y);
      p[0] = static_cast<unsigned char>(x * 7), p[1] = static_cast<unsigned char>(y * 5), p[2] = 90, p[3] = 255;
    }
  return im;
}
}  // namespace

TEST(ImageCompare, IdenticalImagesDoNotDiffer) {
  const Image a = gradient(32, 16);
  const ImageDiff d = compare_images(a, a, 0);
  EXPECT_TRUE(d.same_size);
  EXPECT_EQ(d.differing, 0);
  EXPECT_EQ(d.max_channel_diff, 0);
}

TEST(ImageCompare, ToleranceAndDiffImage) {
  const Image a = gradient(32, 16);
  Image b = a;
  b.px(3, 4)[1] = static_cast<unsigned char>(b.px(3, 4)[1] + 2);   // within +-2
  b.px(10, 5)[0] = static_cast<unsigned char>(b.px(10, 5)[0] + 9);  // beyond
  Image diff;
  const ImageDiff d = compare_images(a, b, 2, &diff);
  EXPECT_EQ(d.differing, 1);
  EXPECT_EQ(d.max_channel_diff, 9);
  EXPECT_NEAR(d.fraction(), 1.0 / (32 * 16), 1e-12);
  ASSERT_EQ(diff.w, 32);
  EXPECT_GT(diff.px(10, 5)[0], 128);  // marked red
  EXPECT_EQ(diff.px(10, 5)[1], 0);
  EXPECT_EQ(diff.px(3, 4)[0], diff.px(3, 4)[1]);  // grey: within tolerance
}

TEST(ImageCompare, SizeMismatchIsAllDifferent) {
  const ImageDiff d = compare_images(gradient(8, 8), gradient(8, 9), 255);
  EXPECT_FALSE(d.same_size);
  EXPECT_EQ(d.fraction(), 1.0);
}

TEST(ImagePng, RoundTrip) {
  const Image a = gradient(20, 10);
  const std::string path = (std::filesystem::temp_directory_path() / "softtled_png_roundtrip.png").string();
  write_file_atomic(path, encode_png(a));
  const Image b = read_png(path);
  std::remove(path.c_str());
  EXPECT_EQ(b.w, 20);
  EXPECT_EQ(b.h, 10);
  EXPECT_EQ(compare_images(a, b, 0).differing, 0);
}

TEST(ImagePng, MissingFileThrows) { EXPECT_THROW(read_png("/nonexistent/softtled.png"), std::runtime_error); }

// A PNG as the app writes it (write_file_atomic(path, encode_png(im))): a failed write is a
// ResourceError naming the file and the OS reason; a device is written in place, not replaced.
TEST(ImagePng, WriteErrorsAreResourceErrors) {
  Image a(64, 48);
  try {
    write_file_atomic("/dev/full", encode_png(a));
    ADD_FAILURE() << "writing /dev/full succeeded";
  } catch (const ResourceError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full: write failed: No space left on device"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/full"));
  try {
    write_file_atomic("/nonexistent/dir/x.png", encode_png(a));
    ADD_FAILURE() << "writing into a missing directory succeeded";
  } catch (const ResourceError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write: No such file or directory"), std::string::npos) << e.what();
  }
  const std::string png = encode_png(a);
  EXPECT_EQ(png.substr(1, 3), "PNG");
}

TEST(Math3d, InverseTimesMatrixIsIdentity) {
  Camera c;
  c.target = {0.01f, -0.002f, 0.003f};
  const Mat4 m = c.proj(1.5f) * c.view();
  const Mat4 r = inverse(m) * m;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(r(i, j), i == j ? 1.f : 0.f, 1e-4f);
}

TEST(Camera, CentreRayHitsTheTarget) {
  Camera c;
  c.target = {0.f, -0.004f, 0.f};
  c.distance = 0.08f;
  Vec3 o, d;
  c.ray(399.5f, 299.5f, 800, 600, o, d);  // pixel centre of an even-sized viewport
  const Vec3 to_target = normalize(c.target - o);
  EXPECT_GT(dot(d, to_target), 0.99999f);
}

TEST(Camera, LensShiftMovesTheTargetRight) {
  Camera c;
  c.shift_x = 0.5f;
  const Vec3 p = transform_point(c.proj(1.f) * c.view(), c.target);
  EXPECT_NEAR(p.x, 0.5f, 1e-5f);
  EXPECT_NEAR(p.y, 0.f, 1e-5f);
}

TEST(Math3d, PlanarShadowLandsOnThePlaneAlongTheLight) {
  const Vec3 n = normalize({0.2f, 1.f, 0.f}), light = normalize({-0.35f, 1.f, 0.55f});
  const float d = -0.012f;
  const Vec3 p{0.003f, 0.01f, -0.002f};
  const Vec3 s = transform_point(planar_shadow(n, d, light), p);
  EXPECT_NEAR(dot(n, s), d, 1e-6f);
  EXPECT_GT(dot(normalize(p - s), light), 0.9999f);  // moved along the light direction
}

TEST(Picking, RayTriangleHitAndMiss) {
  const Vec3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  float t = 0;
  EXPECT_TRUE(ray_triangle({0.2f, 0.2f, 1}, {0, 0, -1}, a, b, c, t));
  EXPECT_NEAR(t, 1.f, 1e-6f);
  EXPECT_TRUE(ray_triangle({0.2f, 0.2f, -1}, {0, 0, 1}, a, b, c, t));  // back side too
  EXPECT_FALSE(ray_triangle({0.8f, 0.8f, 1}, {0, 0, -1}, a, b, c, t));
  EXPECT_FALSE(ray_triangle({0.2f, 0.2f, 1}, {0, 0, 1}, a, b, c, t));  // behind the origin
}

TEST(Picking, NearestTriangleWins) {
  // Two parallel triangles at z = 0 and z = 0.5; a ray from z = 1 down hits the upper first.
  const std::vector<float> pos = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 1, 0, 0.5f, 0, 1, 0.5f};
  const std::vector<int> tri = {0, 1, 2, 3, 4, 5};
  const PickHit h = pick_surface({0.2f, 0.2f, 1}, {0, 0, -1}, pos, tri);
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.tri, 1);
  EXPECT_NEAR(h.point.z, 0.5f, 1e-6f);
  EXPECT_FALSE(pick_surface({5, 5, 1}, {0, 0, -1}, pos, tri).hit);
}

TEST(DragSpring, PullsTowardsTheTargetAndIsCapped) {
  const TetMesh m = make_tet_mesh({0, 0, 0, 0.001, 0, 0, 0, 0.001, 0, 0, 0, 0.001}, {0, 1, 2, 3});
  HostState s;
  s.u.assign(12, 0.0);
  s.du.assign(12, 0.0);
  const std::vector<double> mass(4, 1e-6);
  const int tri[3] = {1, 2, 3};
  DragSpring d(2.0f, 1.0f);
  d.grab(m, s, mass, m.surface_nodes, tri, {0.0004f, 0.0004f, 0.0002f}, 0.0008f, {0, 0, -1});
  ASSERT_TRUE(d.active);
  ASSERT_FALSE(d.nodes.empty());
  std::vector<double> f;
  d.forces(m, s, 1e-5, f);  // at the grab point, at rest: no force
  for (double v : f) EXPECT_NEAR(v, 0.0, 1e-12);

  d.target = d.target + Vec3{0.002f, 0, 0};  // 2 mm to +x
  d.forces(m, s, 1e-5, f);
  const int n = m.nnode();
  double fx = 0, fy = 0;
  for (int i = 0; i < n; ++i) fx += f[i], fy += f[n + i];
  EXPECT_NEAR(fx, 2.0 * 0.002, 1e-6);  // k x stretch
  EXPECT_NEAR(fy, 0.0, 1e-9);

  d.target = d.target + Vec3{1.0f, 0, 0};  // far away: capped at max_force
  d.forces(m, s, 1e-5, f);
  fx = 0;
  for (int i = 0; i < n; ++i) fx += f[i];
  EXPECT_NEAR(fx, 1.0, 1e-5);
  EXPECT_GT(d.max_hold_time(), 0.0);
}

// The viewer's pull as its loop applies it (forces from the state at the start of each
// hold, held for max_hold_time), on the paper's torus with T4ANP and the adaptive step:
// the grabbed patch weights its nodes by distance, not mass, so a light rim node can carry
// a large share. Held for the grabbed mass's time instead of the lightest node's, its
// damper overshot and rang, inverted elements and stopped the run within 0.05 s (as it
// did in the viewer on the GPU). A healthy pull lifts the grab point and trips nothing.
TEST(DragSpring, HeldPullOnTheTorusRimStaysHealthy) {
  Simulation sim(load_scene(test::assets_dir() + "/scenes/torus_drop.toml", {"material.element=T4ANP", "time.dt=adaptive"}));
  sim.advance_to(0.25);  // landed
  const TetMesh& m = sim.mesh();
  const int n = m.nnode();
  int rim = -1;  // outermost surface node (+x), where a user clicks the rim
  for (int i : m.surface_nodes)
    if (rim < 0 || m.X[3 * i] + sim.state().u[i] > m.X[3 * rim] + sim.state().u[rim]) rim = i;
  const HostState& s0 = sim.state();
  const Vec3 p{float(m.X[3 * rim] + s0.u[rim]), float(m.X[3 * rim + 1] + s0.u[n + rim]),
               float(m.X[3 * rim + 2] + s0.u[2 * n + rim])};
  DragSpring d(3.0f, 0.1f);  // the panel's defaults
  const int tri[3] = {rim, rim, rim};
  d.grab(m, sim.state(), sim.lumped_mass(), m.surface_nodes, tri, p, 1.5e-3f, Vec3{0, 0, -1});
  std::vector<double> f;
  const double t0 = sim.time();
  while (sim.time() < t0 + 0.2) {
    d.target = p + Vec3{0, float(std::min(1.0, (sim.time() - t0) / 0.1) * 5e-3), 0};  // 5 mm up over 0.1 s
    const double dt = sim.params().dt;
    d.forces(m, sim.state(), dt, f);
    sim.set_external_forces(f);
    ASSERT_NO_THROW(sim.advance(std::max(1L, long(d.max_hold_time() / dt)), 0)) << "at t = " << sim.time();
  }
  EXPECT_EQ(sim.watchdog_trips(), 0);
  EXPECT_GT(d.grab_point(m, sim.state()).y - p.y, 1e-3f);  // the pull lifts the rim
}

// A mesh obstacle is drawn where its collision surface is: each triangle's corners at
// center + R q, with the flat outward normal turned by R (here a quarter turn about z).
TEST(ObstacleTriangles, MeshCornersAndNormalsFollowThePose) {
  RenderObstacle o;
  o.shape = RenderObstacle::Shape::kMesh;
  o.center = Vec3{1, 2, 3};
  const float R[9] = {0, -1, 0, 1, 0, 0, 0, 0, 1};  // x -> y, y -> -x
  for (int k = 0; k < 9; ++k) o.R[k] = R[k];
  // One triangle in the local z = 0 plane, counter-clockwise seen from +z.
  o.triangles = std::make_shared<std::vector<float>>(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
  std::vector<float> out;
  obstacle_triangles(o, out);
  ASSERT_EQ(out.size(), 3u * kBodyFloatsPerVertex);
  const Vec3 want[3] = {{1, 2, 3}, {1, 3, 3}, {0, 2, 3}};  // center + R q
  for (int v = 0; v < 3; ++v) {
    const float* p = &out[v * kBodyFloatsPerVertex];
    EXPECT_NEAR(p[0], want[v].x, 1e-6f);
    EXPECT_NEAR(p[1], want[v].y, 1e-6f);
    EXPECT_NEAR(p[2], want[v].z, 1e-6f);
    EXPECT_NEAR(p[3], 0.f, 1e-6f);  // normal: R (0, 0, 1) = (0, 0, 1)
    EXPECT_NEAR(p[4], 0.f, 1e-6f);
    EXPECT_NEAR(p[5], 1.f, 1e-6f);
  }
}

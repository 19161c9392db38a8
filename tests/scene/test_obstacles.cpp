#define _USE_MATH_DEFINES
// Rigid obstacles ([[obstacle]], node_contact.h) on every backend: a block resting on a box
// top settles exactly as on the plane through that face; Coulomb, sliding and static on a
// tilted box face follow the plane of the same tilt (an independent check of the
// projection through the box's distance function); a moving box paddle pushes a body at
// its own speed; and the shipped scenes: torus_on_ball (slides off a frictionless ball,
// held with static friction) and stairs (a ball bouncing down box steps without going
// into them); an obstacle much faster than a step (800 m/s) leaves alone a body it passes by
// and still hits one in its path.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "backends.h"
#include "scene/state_compare.h"
#include "scene_helpers.h"
#include "sim/mesh/surface_generators.h"
#include "sim/mesh/surface_io.h"
#include "sim/scene/simulation.h"

using namespace softtled;
using namespace softtled::test;

namespace {

class Obstacles : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(Obstacles);

// Smallest signed distance of any node from obstacle o (pose now) [m].
double gap_to_obstacle(Simulation& sim, int o) {
  return min_node_distance(sim, [&](const double* x) { return signed_distance(sim.params().obstacles[o], x); });
}

// A 6 mm cube on an incline of theta through the origin (as tests/solver/test_tled_dynamics.cpp),
// the incline either the slope plane or the top face of a 200 x 100 x 40 mm box turned by theta.
Scene incline(double theta_deg, const std::string& mode, double mu, bool box) {
  const double th = theta_deg * M_PI / 180, h = 3.0 + 1e-6;
  char support[400];
  if (box)
    std::snprintf(support, sizeof support,
                  "[slope]\nenabled = false\n[[obstacle]]\nshape = \"box\"\ncenter = [%.17g, %.17g, 0]\n"
                  "size = [200, 100, 40]\nrotation_deg = [0, 0, %.17g]\n",
                  50 * std::sin(th), -50 * std::cos(th), theta_deg);
  else
    std::snprintf(support, sizeof support, "[slope]\nenabled = true\nangle_deg = %.17g\npoint = [0, 0, 0]\n", theta_deg);
  char buf[1400];
  std::snprintf(buf, sizeof buf,
                "units = \"mm\"\n[body]\nshape = \"box\"\nsize = [6, 6, 6]\ndivisions = [2, 2, 2]\n"
                "position = [%.12g, %.12g, 0]\nrotation_deg = [0, 0, %.12g]\n"
                "[material]\nE = 50000.0\nnu = 0.3\n[floor]\nenabled = false\n%s"
                "[contact]\nmode = \"%s\"\nmu = %.12g\n[time]\nlambda = 0.5\n",
                -std::sin(th) * h, std::cos(th) * h, theta_deg, support, mode.c_str(), mu);
  return parse_scene(buf, box ? "incline on a box" : "incline on a plane");
}

}  // namespace

TEST_P(Obstacles, BlockOnABoxTopRestsAsOnThePlaneThroughIt) {
  // A 10 mm cube dropped 0.5 mm onto the top of a box (y = -5.5 mm), and the same cube onto
  // a floor plane there: the face is that plane, so the runs agree to rounding, the cube
  // never goes into the box and it comes to rest.
  const std::string body = "units = \"mm\"\n[body]\nshape = \"box\"\nsize = [10, 10, 10]\ndivisions = [2, 2, 2]\n";
  Simulation on_box(parse_scene(body + "[floor]\nenabled = false\n[[obstacle]]\nshape = \"box\"\ncenter = [1, -15.5, 0]\n"
                                       "size = [30, 20, 30]\n", "box top"),
                    backend());
  Simulation on_plane(parse_scene(body + "[floor]\nenabled = true\npoint = [0, -5.5, 0]\n", "floor"), backend());
  const long every = std::lround(5e-4 / on_box.time_step().dt);
  double worst_gap = 1e300, worst_diff = 0, peak_ke = 0;
  while (on_box.time() < 0.6) {
    on_box.step(every);
    on_plane.step(every);
    worst_gap = std::min(worst_gap, on_box.diagnostics().min_gap);
    worst_diff = std::max(worst_diff, max_abs_diff(on_box, on_plane));
    peak_ke = std::max(peak_ke, on_box.diagnostics().ke);
  }
  const Diagnostics d = on_box.diagnostics();
  std::printf("block on a box top: min gap %.3g m, max |u| difference from the plane run %.3g m, KE %.3g of peak\n",
              worst_gap, worst_diff, d.ke / peak_ke);
  EXPECT_GT(worst_gap, -1e-12) << "no node inside the box";
  EXPECT_LT(worst_diff, 1e-9) << "the box top acts as the plane through it";
  EXPECT_GT(d.n_contact, 0);
  EXPECT_LT(d.ke, 1e-3 * peak_ke) << "comes to rest";
}

TEST_P(Obstacles, BlockOnASphereTopRestsWithoutPenetrating) {
  // Static friction: a 6 mm cube dropped 0.2 mm onto the top of a rigid ball of radius
  // 20 mm rests on its apex; no node goes into the ball.
  Simulation sim(parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [6, 6, 6]\ndivisions = [2, 2, 2]\n"
                             "[material]\nE = 20000.0\nnu = 0.3\n[floor]\nenabled = false\n[contact]\nmode = \"static\"\n"
                             "[[obstacle]]\nshape = \"sphere\"\ncenter = [0, -23.2, 0]\nradius = 20\n",
                             "block on a ball"),
                 backend());
  const long every = std::lround(5e-4 / sim.time_step().dt);
  double worst_gap = 1e300, peak_ke = 0;
  while (sim.time() < 0.6) {
    sim.step(every);
    worst_gap = std::min(worst_gap, sim.diagnostics().min_gap);
    peak_ke = std::max(peak_ke, sim.diagnostics().ke);
  }
  const Diagnostics d = sim.diagnostics();
  std::printf("block on a ball: min gap %.3g m, centroid x %.3g mm, KE %.3g of peak\n", worst_gap, d.centroid[0] * 1e3,
              d.ke / peak_ke);
  EXPECT_GT(worst_gap, -1e-12) << "no node inside the ball";
  EXPECT_LT(gap_to_obstacle(sim, 0), 1e-6) << "resting on it";
  EXPECT_LT(std::fabs(d.centroid[0]), 0.05e-3) << "stays on the apex";
  EXPECT_LT(d.ke, 1e-3 * peak_ke) << "comes to rest";
}

TEST_P(Obstacles, TiltedBoxFaceFollowsThePlaneOfTheSameTiltInEveryMode) {
  // The cube on a 20 degree incline: the incline as the slope plane, and as the top face
  // of a box turned 20 degrees. The box's distance function (rotation, clamping, nearest
  // face) must give the plane's projection: the same trajectory to rounding, and the
  // slide the analytic one (tests/solver/test_tled_dynamics.cpp checks the plane run).
  const double theta = 20, t_end = 0.05, th = theta * M_PI / 180;
  for (const char* mode : {"coulomb", "sliding", "static"}) {
    Simulation plane(incline(theta, mode, 0.2, false), backend()), box(incline(theta, mode, 0.2, true), backend());
    ASSERT_EQ(plane.time_step().dt, box.time_step().dt);
    const Diagnostics d0 = box.diagnostics();
    const long every = std::lround(2.5e-3 / box.time_step().dt);
    double worst = 0;
    while (box.time() < t_end - 1e-12) {
      box.step(every);
      plane.step(every);
      worst = std::max(worst, max_abs_diff(box, plane));
    }
    const Diagnostics d1 = box.diagnostics();
    const double s = -(d1.centroid[0] - d0.centroid[0]) * std::cos(th) - (d1.centroid[1] - d0.centroid[1]) * std::sin(th);
    std::printf("%s on a 20 deg box face: slid %.4f mm, max |u| difference from the plane %.3g m\n", mode, s * 1e3, worst);
    EXPECT_LT(worst, 1e-9) << mode;
    EXPECT_GT(d1.n_contact, 0) << mode;
    EXPECT_GT(d1.min_gap, -1e-12) << mode;
    if (std::string(mode) == "coulomb") {
      const double expect = damped_fall(9.81 * (std::sin(th) - 0.2 * std::cos(th)), 10.0, t_end);
      EXPECT_NEAR(s, expect, 0.1 * expect) << "kinetic friction: g (sin - mu cos)";
    }
  }
}

TEST_P(Obstacles, MovingPaddlePushesTheBodyAtItsSpeed) {
  // A box paddle moving +x at 50 mm/s meets a 6 mm cube resting 0.5 mm ahead of it on a
  // frictionless floor. Once in contact the paddle carries the cube: the cube's trailing
  // face stays within 1 mm ahead of the paddle's face (it bounces off a little and the
  // damping, alpha = 10, brings it back) and over 0.1-0.3 s it moves at the paddle's speed.
  const double v = 0.05;
  Simulation sim(parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [6, 6, 6]\ndivisions = [2, 2, 2]\n"
                             "[material]\nE = 20000.0\nnu = 0.3\n[floor]\nenabled = true\npoint = [0, -3, 0]\n"
                             "[[obstacle]]\nshape = \"box\"\ncenter = [-4.5, 2, 0]\nsize = [2, 8, 12]\nvelocity = [0.05, 0, 0]\n",
                             "paddle"),
                 backend());
  const long every = std::lround(5e-4 / sim.time_step().dt);
  const double t_contact = 0.5e-3 / v;
  double worst_gap = 1e300, lead_lo = 1e300, lead_hi = -1e300, x_a = 0;
  while (sim.time() < 0.3 - 1e-12) {
    sim.step(every);
    worst_gap = std::min(worst_gap, gap_to_obstacle(sim, 0));
    const double x = sim.diagnostics().centroid[0];
    const double paddle_face = sim.params().obstacles[0].center[0] + 1e-3;
    if (sim.time() > t_contact + 2e-3) {
      lead_lo = std::min(lead_lo, x - 3e-3 - paddle_face);
      lead_hi = std::max(lead_hi, x - 3e-3 - paddle_face);
    }
    if (sim.time() <= 0.1 + 1e-12) x_a = x;
  }
  const double speed = (sim.diagnostics().centroid[0] - x_a) / (sim.time() - 0.1);
  std::printf("paddle: cube ahead of the paddle by %.3f to %.3f mm after contact, speed %.4f m/s over 0.1-0.3 s, "
              "min gap to the paddle %.3g m\n",
              lead_lo * 1e3, lead_hi * 1e3, speed, worst_gap);
  EXPECT_NEAR(sim.params().obstacles[0].center[0], -4.5e-3 + v * sim.time(), 1e-12) << "the paddle's pose at t";
  EXPECT_GT(lead_lo, -0.1e-3) << "the cube's trailing face never behind the paddle (mesh-averaged)";
  EXPECT_LT(lead_hi, 1e-3) << "carried: never more than 1 mm ahead";
  EXPECT_NEAR(speed, v, 0.05 * v) << "at the paddle's speed";
  EXPECT_GT(worst_gap, -1e-12) << "no node inside the paddle";
}

TEST_P(Obstacles, TorusOnBallSlidesOffWithoutFrictionAndIsHeldWithStaticFriction) {
  // assets/scenes/torus_on_ball.toml: the flat ring lands on the ball's shoulder. In
  // sliding mode it slides off and lies flat on the floor; with static friction its
  // contact nodes stick and it stays propped on the ball.
  double t_off[2], y_end[2];
  for (int k = 0; k < 2; ++k) {
    Simulation sim(load_scene(assets_dir() + "/scenes/torus_on_ball.toml",
                              {k == 0 ? "contact.mode=sliding" : "contact.mode=static"}),
                   backend());
    const long every = std::lround(2e-3 / sim.time_step().dt);
    double worst_gap = 1e300;
    bool touched = false;
    t_off[k] = 1e9;
    while (sim.time() < 0.3 - 1e-12) {
      sim.step(every);
      const double g = gap_to_obstacle(sim, 0);
      worst_gap = std::min(worst_gap, sim.diagnostics().min_gap);
      touched = touched || g < 1e-6;
      if (touched && g > 0.5e-3 && t_off[k] > 1e8) t_off[k] = sim.time();
      if (touched && g < 1e-6) t_off[k] = 1e9;  // back on the ball: not off yet
    }
    y_end[k] = sim.diagnostics().centroid[1];
    std::printf("torus on ball, %s: off the ball at t = %.3f s, centroid y at 0.3 s %.3f mm, min gap %.3g m\n",
                k == 0 ? "sliding" : "static", t_off[k], y_end[k] * 1e3, worst_gap);
    EXPECT_TRUE(touched);
    EXPECT_GT(worst_gap, -1e-12) << "no node inside the ball or the floor";
  }
  const double flat = -4e-3 + 2.5e-3;  // floor + tube radius
  EXPECT_LT(t_off[0], 0.25) << "sliding: slides off the ball";
  EXPECT_NEAR(y_end[0], flat, 0.5e-3) << "sliding: lies flat on the floor";
  EXPECT_GT(t_off[1], 0.3) << "static: still on the ball at 0.3 s";
  EXPECT_GT(y_end[1], flat + 1.5e-3) << "static: propped on the ball";
}

TEST_P(Obstacles, BallBouncesDownTheStairsWithoutEnteringThem) {
  // assets/scenes/stairs.toml: three box steps (treads at 18, 12, 6 mm, 15 mm deep), then
  // the floor. The ball must touch every tread in turn, then the floor beyond the last
  // step, and no node may be found behind a step face or the floor (checked every 0.25 ms).
  Simulation sim(load_scene(assets_dir() + "/scenes/stairs.toml"), backend());
  ASSERT_EQ(sim.params().obstacles.size(), 3u);
  const long every = std::max(1L, std::lround(2.5e-4 / sim.time_step().dt));
  double worst_gap = 1e300, t_touch[4] = {-1, -1, -1, -1};  // the three treads, then the floor
  while (sim.time() < 0.5 - 1e-12) {
    sim.step(every);
    const Diagnostics d = sim.diagnostics();
    worst_gap = std::min(worst_gap, d.min_gap);
    for (int o = 0; o < 3; ++o)
      if (t_touch[o] < 0 && gap_to_obstacle(sim, o) < 1e-6) t_touch[o] = sim.time();
    const double floor_gap = signed_distance(sim.params().planes[0], d.centroid) - 4e-3;  // centroid height - radius
    if (t_touch[3] < 0 && floor_gap < 0.5e-3 && d.centroid[0] > 15e-3) t_touch[3] = sim.time();
  }
  const Diagnostics d = sim.diagnostics();
  std::printf("stairs: treads touched at %.3f, %.3f, %.3f s, the floor at %.3f s; end centroid (%.2f, %.2f) mm; "
              "min gap %.3g m\n",
              t_touch[0], t_touch[1], t_touch[2], t_touch[3], d.centroid[0] * 1e3, d.centroid[1] * 1e3, worst_gap);
  EXPECT_GT(worst_gap, -1e-12) << "a node behind a step face or the floor";
  EXPECT_GE(t_touch[0], 0);
  EXPECT_GT(t_touch[1], t_touch[0]) << "down the steps in order";
  EXPECT_GT(t_touch[2], t_touch[1]);
  EXPECT_GT(t_touch[3], t_touch[2]) << "then the floor beyond the last step";
  EXPECT_GT(d.centroid[0], 15e-3 + 4e-3) << "ends beyond the last step";
}

namespace {

// A 6 mm cube at rest in zero gravity, and one obstacle of each shape flying past it along
// x at 800 m/s, 8 mm per step (dt = 10 us). `offset` is the obstacle's centre line's height
// above the cube's centre [mm]; the obstacle is 4 mm across in y.
Scene fast_obstacle(const std::string& shape, double offset) {
  std::string o;
  if (shape == "sphere") o = "radius = 2.0\ncenter = [-30, " + std::to_string(offset) + ", 0]\n";
  if (shape == "box") o = "size = [4, 4, 4]\ncenter = [-30, " + std::to_string(offset) + ", 0]\n";
  if (shape == "capsule")
    o = "radius = 2.0\na = [-30, " + std::to_string(offset) + ", -2]\nb = [-30, " + std::to_string(offset) + ", 2]\n";
  if (shape == "mesh") {
    const std::string path = ::testing::TempDir() + "softtled_fast_obstacle_box.obj";
    write_obj(make_box(4, 4, 4, 1, 1, 1), path);
    o = "file = \"" + path + "\"\ncenter = [-30, " + std::to_string(offset) + ", 0]\n";
  }
  return parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [6, 6, 6]\ndivisions = [2, 2, 2]\n"
                     "[material]\nE = 20000.0\nnu = 0.3\n[floor]\nenabled = false\n[gravity]\ng = [0, 0, 0]\n"
                     "[time]\ndt = 1e-5\n[[obstacle]]\nshape = \"" + shape + "\"\n" + o +
                         "velocity = [800, 0, 0]\n",
                     "fast " + shape);
}

}  // namespace

TEST_P(Obstacles, FastObstacleLeavesAloneABodyItPassesAndHitsOneInItsPath) {
  // Passing 2 mm above the cube's top face, the obstacle never touches it: the cube, at
  // rest with no load, stays exactly at rest (every u bit for bit 0). The straight step of
  // a top node relative to the obstacle crosses the tangent plane at its closest point
  // (the obstacle is 30 mm behind, and 8 mm nearer after the step) while passing 4 mm from
  // its centre: a projection there would kick the cube. Aimed at the cube's centre, the
  // same obstacle moves through a whole cube width in under two steps and must still push
  // it along +x in the step it passes.
  for (const char* shape : {"sphere", "box", "capsule", "mesh"}) {
    SCOPED_TRACE(shape);
    Simulation miss(fast_obstacle(shape, 7), backend());
    miss.step(10);  // the obstacle from x = -30 to +50 mm
    EXPECT_EQ(max_abs_u(miss), 0.0) << "a body the obstacle never touched moved";
    EXPECT_EQ(miss.diagnostics().n_contact, 0);

    // The hit: the first step with a contact (after it the cube, hit by the obstacle at
    // 800 m/s, is torn apart and the watchdog's business).
    Simulation hit(fast_obstacle(shape, 0), backend());
    int steps = 0;
    while (steps < 10 && hit.diagnostics().n_contact == 0) hit.step(1), ++steps;
    const Diagnostics d = hit.diagnostics();
    std::printf("fast %s: the missed cube's largest |u| %.3g m; hit at step %d: %d nodes pushed, centroid +%.3f mm in x\n",
                shape, max_abs_u(miss), steps, d.n_contact, d.centroid[0] * 1e3);
    EXPECT_GT(d.n_contact, 0) << "the obstacle passed through the cube without touching it";
    EXPECT_GT(d.centroid[0], 0.1e-3) << "the hit does not push the cube along the obstacle's motion";
  }
}

TEST_P(Obstacles, AnObstacleFasterThanTheWaveSpeedIsNamedWhenTheRunBlowsUp) {
  // A box wall driven at 12 m/s into a 6 mm cube (E = 50 kPa, nu = 0.3, rho = 1000: c =
  // 8.2 m/s) crushes the elements it strikes within a step or two; the watchdog stops the
  // run, and its likely cause names the obstacle's speed against c, not only "numerical
  // blow-up". At 1.2 m/s (0.15 c) the same wall pushes the cube for 3 ms without a stop.
  auto wall = [](double v) {
    return parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [6, 6, 6]\ndivisions = [2, 2, 2]\n"
                       "[material]\nE = 50000.0\nnu = 0.3\n[damping]\nalpha = 0.0\n[gravity]\ng = [0, 0, 0]\n"
                       "[floor]\nenabled = false\n[[obstacle]]\nshape = \"box\"\ncenter = [-5.5, 0, 0]\n"
                       "size = [4, 20, 20]\nvelocity = [" + std::to_string(v) + ", 0, 0]\n",
                       "wall");
  };
  Simulation slow(wall(1.2), backend());
  EXPECT_NO_THROW(slow.advance(std::lround(3e-3 / slow.time_step().dt), 1)) << "a wall at 0.15 c is no blow-up";
  EXPECT_GT(slow.diagnostics().centroid[0], 0.5e-3) << "the slow wall did not push the cube";
  Simulation fast(wall(12), backend());
  try {
    fast.advance(std::lround(3e-3 / fast.time_step().dt), 1);
    ADD_FAILURE() << "a wall at 1.5 c ran 3 ms without the watchdog";
  } catch (const SimulationDiverged& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("obstacle[0] moves at 12 m/s, 1.5 x the material's wave speed c = 8.2 m/s"), std::string::npos)
        << msg;
    for (double u : fast.state().u) ASSERT_TRUE(std::isfinite(u)) << "rollback left NaN";
  }
}

TEST(ObstacleStart, AnObstacleThatFitsBetweenTheNodesIsReported) {
  // A 0.3 mm rod under a coarse torus (surface triangles of up to 1.6 mm circumradius):
  // contact is tested at nodes, and the torus falls through the rod between them. Said at
  // the start, naming the obstacle, its radius and the triangles; a 2 mm rod fits through
  // no triangle and is not mentioned, nor is the shipped torus_on_ball's ball.
  auto start_log = [](double radius) {
    char buf[600];
    std::snprintf(buf, sizeof buf,
                  "units = \"mm\"\n[body]\nshape = \"torus\"\nsegments = [24, 8]\n[floor]\npoint = [0, -40, 0]\n"
                  "[[obstacle]]\nshape = \"capsule\"\na = [1.3, -13, -20]\nb = [1.3, -13, 20]\nradius = %g\n",
                  radius);
    ::testing::internal::CaptureStderr();
    Simulation sim(parse_scene(buf, "rod"), "cpu");
    return ::testing::internal::GetCapturedStderr();
  };
  const std::string thin = start_log(0.3);
  EXPECT_NE(thin.find("warning: rod: obstacle[0] (a capsule of radius 0.3 mm) fits through body's largest surface "
                      "triangles (a point in one 1.5"),
            std::string::npos)
      << thin;
  const std::string thick = start_log(2.0);
  EXPECT_EQ(thick.find("fits through"), std::string::npos) << thick;
  ::testing::internal::CaptureStderr();
  Simulation ball(load_scene(assets_dir() + "/scenes/torus_on_ball.toml", {}), "cpu");
  const std::string shipped = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(shipped.find("fits through"), std::string::npos) << shipped;
}

// An obstacle thinner than the elements, through the torus's tube at the start: no node is
// inside it and its centre is in no element, but the tube's surface edges cross it. Each
// is refused naming the obstacle; moved clear of the tube, each is fine.
TEST(ObstacleStart, ThinObstacleThroughTheBodyIsRefused) {
  const std::string torus =
      "units = \"mm\"\n[body]\nshape = \"torus\"\nsegments = [45, 9]\nrotation_deg = [90, 0, 0]\n"
      "position = [6.5, 8.5, 0]\n[floor]\npoint = [0, -4, 0]\n[time]\nduration = 0.001\n[[obstacle]]\n";
  struct Case {
    const char* shape;
    std::string through, clear;
  } cases[] = {
      {"box", "shape = \"box\"\ncenter = [6.5, 9.1, 0]\nsize = [100, 0.001, 100]\n",
       "shape = \"box\"\ncenter = [6.5, 30, 0]\nsize = [100, 0.001, 100]\n"},
      {"capsule", "shape = \"capsule\"\na = [14, 8.5, -100]\nb = [14, 8.5, 500]\nradius = 0.05\n",
       "shape = \"capsule\"\na = [14, 30, -100]\nb = [14, 30, 500]\nradius = 0.05\n"},
  };
  for (const Case& c : cases) {
    std::string e;
    try {
      Simulation sim(parse_scene(torus + c.through, "thin.toml"), "cpu");
    } catch (const InputError& x) {
      e = x.what();
    }
    EXPECT_NE(e.find(std::string("obstacle[0]: the ") + c.shape + " obstacle cuts through the body at the start"),
              std::string::npos)
        << c.shape << ": " << e;
    EXPECT_NO_THROW(Simulation(parse_scene(torus + c.clear, "clear.toml"), "cpu")) << c.shape;
  }
}

// Through a face and touching none of its edges: a rod skewering a block through the
// interiors of two faces (no node, edge midpoint or triangle or element centre inside it,
// its ends outside, no edge crossing it), and a
// ball dipping 0.2 mm into one face. Each was accepted and the block ran impaled. Refused
// naming the face; moved 1 mm clear, each is fine. With two blocks, the one cut is named.
TEST(ObstacleStart, ObstacleThroughAFaceIsRefused) {
  const std::string block =
      "units = \"mm\"\n[body]\nshape = \"box\"\nsize = [10, 10, 10]\ndivisions = [2, 2, 2]\n[floor]\nenabled = false\n"
      "[time]\nduration = 0.001\n[[obstacle]]\n";
  const struct {
    const char* shape;
    std::string through, clear;
  } cases[] = {
      {"capsule", "shape = \"capsule\"\na = [2.5, -20, 2.1]\nb = [2.5, 20, 2.1]\nradius = 0.3\n",
       "shape = \"capsule\"\na = [2.5, -20, 6.3]\nb = [2.5, 20, 6.3]\nradius = 0.3\n"},
      {"box", "shape = \"box\"\ncenter = [2.5, 15, 2.1]\nsize = [0.6, 50, 0.6]\n",
       "shape = \"box\"\ncenter = [2.5, 15, 6.3]\nsize = [0.6, 50, 0.6]\n"},
      {"sphere", "shape = \"sphere\"\ncenter = [2.5, 5.3, 1.3]\nradius = 0.5\n",
       "shape = \"sphere\"\ncenter = [2.5, 6.3, 1.3]\nradius = 0.5\n"},
  };
  for (const auto& c : cases) {
    std::string e;
    try {
      Simulation sim(parse_scene(block + c.through, "face.toml"), "cpu");
    } catch (const InputError& x) {
      e = x.what();
    }
    EXPECT_NE(e.find(std::string("obstacle[0]: the ") + c.shape + " obstacle cuts through the body at the start (the "
                     "surface triangle of nodes "),
              std::string::npos)
        << c.shape << ": " << e;
    EXPECT_NO_THROW(Simulation(parse_scene(block + c.clear, "clear.toml"), "cpu")) << c.shape;
  }
  const std::string two =
      "units = \"mm\"\n[[body]]\nshape = \"box\"\nsize = [10, 10, 10]\ndivisions = [2, 2, 2]\nposition = [-20, 0, 0]\n"
      "[[body]]\nshape = \"box\"\nsize = [10, 10, 10]\ndivisions = [2, 2, 2]\n[floor]\nenabled = false\n[[obstacle]]\n";
  try {
    Simulation sim(parse_scene(two + cases[0].through, "two.toml"), "cpu");
    ADD_FAILURE() << "the rod through body[1] was accepted";
  } catch (const InputError& x) {
    EXPECT_NE(std::string(x.what()).find("obstacle cuts through body[1] at the start"), std::string::npos) << x.what();
    EXPECT_NE(std::string(x.what()).find("move body[1].position"), std::string::npos) << x.what();
  }
}

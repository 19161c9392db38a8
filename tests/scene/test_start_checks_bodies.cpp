// Start checks and messages of scenes with several bodies: the collision-course check
// (closing_speeds.h) judged by the surfaces where the bounding spheres already overlap, nodes
// and elements named by their body's own numbers (those of its VTU file, body_split.h), and
// the warning for a [material] key that every body overrides.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "sim/io/body_split.h"
#include "sim/scene/simulation.h"
#include "sim/scene/watchdog.h"

using namespace softtled;

namespace {

// The start's refusal of a scene, or "" when it starts.
std::string refusal(const Scene& s) {
  try {
    Simulation sim(s, "cpu");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const char* kStill = "[material]\nE = 20000.0\nnu = 0.4\n[damping]\nalpha = 0.0\n[gravity]\ng = [0, 0, 0]\n"
                     "[floor]\nenabled = false\n";

// A probe's scenes: a ball (r = 1.5 mm) 1 mm above a 20 x 1 x 20 mm plate, 8 mm off its
// centre, so that the bounding spheres overlap; dt is about 15 us and the plate 0.91 mm deep.
Scene ball_over_plate(const std::string& velocity) {
  return parse_scene("units = \"mm\"\n[[body]]\nshape = \"box\"\nsize = [20, 1, 20]\ndivisions = [6, 1, 6]\n"
                     "[[body]]\nshape = \"sphere\"\nradius = 1.5\nsubdivisions = 1\nposition = [8, 3, 0]\n"
                     "velocity = [" + velocity + "]\n" + kStill + "[time]\nduration = 0.0005\noutput_every = 0.00002\n",
                     "ball_over_plate");
}

// The same ball in the hole of a torus (R = 7.5 mm, r = 2.5 mm, axis z), 0.5 mm off its axis.
Scene ball_in_torus(const std::string& velocity) {
  return parse_scene("units = \"mm\"\n[[body]]\nshape = \"torus\"\nmajor_radius = 7.5\ntube_radius = 2.5\n"
                     "segments = [30, 8]\n[[body]]\nshape = \"sphere\"\nradius = 1.5\nsubdivisions = 1\n"
                     "position = [0.5, 0, 0]\nvelocity = [" + velocity + "]\n" + kStill + "[time]\nduration = 0.002\n",
                     "ball_in_torus");
}

// Two boxes of 4 mm ([2, 2, 2] divisions) centred at x = x0 and x = x1, and `extra`.
Scene two_boxes(double x0, double x1, const std::string& extra = "") {
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "units = \"mm\"\n[[body]]\nshape = \"box\"\nsize = [4, 4, 4]\ndivisions = [2, 2, 2]\n"
                "position = [%g, 0, 0]\n[[body]]\nshape = \"box\"\nsize = [4, 4, 4]\ndivisions = [2, 2, 2]\n"
                "position = [%g, 0, 0]\n",
                x0, x1);
  return parse_scene(buf + std::string(kStill) + "[time]\nduration = 0.002\n" + extra, "two_boxes");
}

// Body b's mesh alone, numbered as its VTU file (body_split.h).
TetMesh vtu_mesh(const Simulation& sim, int b) { return body_mesh(sim.mesh(), b); }

}  // namespace

// Where the bounding spheres overlap at the start, the centres' motion says nothing of the
// surfaces'. The ball flying down and sideways at the plate ([50, -100, 0] m/s: its centre
// moves away from the plate's) passed through it (exit 4, a misleading diagnosis) while the
// same ball flying straight down was refused; so did the ball in the torus's hole flying at
// the tube along +x. Both close by more than the thinner body's depth per step: refused.
TEST(StartChecksBodies, AFastBallAimedAtThePlateOrTubeIsRefusedWhereverItsCentreGoes) {
  const std::string straight = refusal(ball_over_plate("0, -100, 0"));
  EXPECT_NE(straight.find("body[0].velocity and body[1].velocity: the bodies are on a collision course at 100 m/s"),
            std::string::npos)
      << straight;
  const std::string glancing = refusal(ball_over_plate("50, -100, 0"));
  EXPECT_NE(glancing.find("body[0].velocity and body[1].velocity: the bodies are on a collision course at 111.8 m/s"),
            std::string::npos)
      << "the ball flying into the plate away from its centre was accepted: " << glancing;
  for (const char* v : {"100, 0, 0", "-100, 0, 0", "0, 100, 0"}) {
    const std::string e = refusal(ball_in_torus(v));
    EXPECT_NE(e.find("the bodies are on a collision course at 100 m/s"), std::string::npos)
        << "ball in the hole flying at the tube [" << v << "]: " << e;
  }
}

// What never meets is not refused however fast: the ball flying up off the plate, flying
// past it above its top face, or out of the torus's hole along the axis (the surfaces'
// paths cross nowhere).
TEST(StartChecksBodies, AFastBallThatMissesTheOtherBodyStarts) {
  EXPECT_EQ(refusal(ball_over_plate("50, 100, 0")), "");
  EXPECT_EQ(refusal(ball_over_plate("300, 0, 0")), "");
  EXPECT_EQ(refusal(ball_in_torus("0, 0, 100")), "");
  EXPECT_EQ(refusal(ball_in_torus("30, 0, 100")), "");
}

// Just under one depth per step ([25, -50, 0] m/s: 0.86 of the plate's 0.91 mm per step) the
// glancing ball starts, and contact sees it before it could pass.
TEST(StartChecksBodies, TheGlancingBallJustUnderTheLimitStartsAndTouches) {
  Simulation sim(ball_over_plate("25, -50, 0"), "cpu");
  bool met = false;
  try {
    for (int k = 0; k < 40 && !met; ++k) sim.step(1), met = sim.diagnostics().n_contact > 0;
  } catch (const SimulationDiverged&) {  // the crush that follows at ~8 c is the watchdog's business
  }
  EXPECT_TRUE(met) << "the ball closing at just under one depth per step never touched the plate";
}

// A capsule through the second of two boxes (a probe's scene): the message named "node 50"
// where body[1] has 26 nodes, numbered 0-25 in its VTU file. The node named is now that
// file's, and it lies inside the capsule (its axis x = 3, y = 0; radius 0.3 mm).
TEST(StartChecksBodies, AnObstacleMessageNamesTheNodeByItsBodysNumber) {
  const std::string capsule = "[[obstacle]]\nshape = \"capsule\"\na = [3, 0, -10]\nb = [3, 0, 10]\nradius = 0.3\n";
  const std::string e = refusal(two_boxes(-3, 3, capsule));
  std::smatch hit;
  const std::regex named(R"(body\[1\] starts inside this capsule obstacle \(node (\d+) of body\[1\] is)");
  ASSERT_TRUE(std::regex_search(e, hit, named)) << e;
  const Simulation apart(two_boxes(-3, 3), "cpu");
  const TetMesh b1 = vtu_mesh(apart, 1);
  const int k = std::stoi(hit[1]);
  ASSERT_LT(k, b1.nnode()) << e;
  const double* x = &b1.X[3 * k];
  EXPECT_LT(std::hypot(x[0] - 3e-3, x[1]), 0.3e-3 - 1e-9) << "node " << k << " of body[1]'s file is not in the capsule";
}

// Boxes overlapping by 1 mm: the message names a point of one body and the element of the
// other it lies in, each by its own body's numbers: that element of the second body's VTU
// mesh holds that point of the first's (each body meshed alone is the body's VTU mesh).
TEST(StartChecksBodies, AnOverlapMessageNamesThePointAndElementByTheirBodiesNumbers) {
  const std::string e = refusal(two_boxes(0, 3));
  std::smatch hit;
  const std::regex named(R"(\((.+) of body\[(\d)\] lies in element (\d+) of body\[(\d)\]\))");
  ASSERT_TRUE(std::regex_search(e, hit, named)) << e;
  const std::string point = hit[1];
  const int a = std::stoi(hit[2]), el = std::stoi(hit[3]), b = std::stoi(hit[4]);
  ASSERT_NE(a, b) << e;
  auto alone = [](double x) {
    return parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [4, 4, 4]\ndivisions = [2, 2, 2]\n"
                       "position = [" + std::to_string(x) + ", 0, 0]\n" + kStill,
                       "one_box");
  };
  const Simulation sa(alone(a == 0 ? 0 : 3), "cpu"), sb(alone(b == 0 ? 0 : 3), "cpu");
  const TetMesh& ma = sa.mesh();
  const TetMesh& mb = sb.mesh();
  ASSERT_LT(el, mb.ntet()) << e;
  // The point: the mean of the nodes (or of the element's corners) the description names.
  std::vector<int> nodes;
  const std::regex number(R"(\d+)");
  for (std::sregex_iterator it(point.begin(), point.end(), number), end; it != end; ++it)
    nodes.push_back(std::stoi(it->str()));
  ASSERT_FALSE(nodes.empty()) << e;
  if (point.find("element") != std::string::npos) {
    ASSERT_LT(nodes[0], ma.ntet()) << e;
    nodes.assign(&ma.tet[4 * nodes[0]], &ma.tet[4 * nodes[0]] + 4);
  }
  double x[3] = {0, 0, 0};
  for (int i : nodes) {
    ASSERT_LT(i, ma.nnode()) << e;
    for (int k = 0; k < 3; ++k) x[k] += ma.X[3 * i + k] / double(nodes.size());
  }
  const int* t = &mb.tet[4 * el];
  EXPECT_TRUE(point_in_tet(&mb.X[3 * t[0]], &mb.X[3 * t[1]], &mb.X[3 * t[2]], &mb.X[3 * t[3]], x))
      << point << " of body[" << a << "] is not in element " << el << " of body[" << b << "]'s file: " << e;
}

// The watchdog's findings in a two-body mesh name the node and element of the body they
// belong to by that body's numbers ("node 50 (element 50)" named nodes past body[1]'s 26).
TEST(StartChecksBodies, WatchdogFindingsNameNodesAndElementsByTheirBodysNumbers) {
  const Simulation sim(two_boxes(-3, 3), "cpu");
  const TetMesh& m = sim.mesh();
  const BodyRange r1 = body_range(m, 1);
  ASSERT_GT(r1.node_begin, 5);
  const int n = m.nnode();
  HostState s;
  s.u.assign(3 * std::size_t(n), 0.0);
  s.du.assign(3 * std::size_t(n), 0.0);
  s.contact.assign(std::size_t(n), 0);
  const Watchdog::SpeedTest no_speed{};
  auto finding = [&](const HostState& st) {
    Watchdog w;
    w.reset(0, 1);
    const std::optional<WatchdogFinding> f = w.check(m, st, Diagnostics{}, 0, {kTaylorNeoHookean}, false, no_speed, {});
    return f ? f->problem : std::string();
  };
  // NaN at body[1]'s node 5.
  HostState nan = s;
  nan.u[std::size_t(r1.node_begin) + 5] = std::nan("");
  const std::string p = finding(nan);
  std::smatch hit;
  ASSERT_TRUE(std::regex_search(p, hit, std::regex(R"(^node 5 of body\[1\] \(element (\d+) of body\[1\]\) has a NaN)")))
      << p;
  EXPECT_LT(std::stoi(hit[1]), r1.ntet()) << p;
  // Body[1] mirrored in x: every element of it inside out, its first (0) named.
  HostState mirrored = s;
  for (int i = r1.node_begin; i < r1.node_end; ++i) mirrored.u[i] = -2 * (m.X[3 * i] - 3e-3);
  const std::string q = finding(mirrored);
  EXPECT_EQ(q.rfind("element 0 of body[1] is inverted", 0), 0u) << q;
}

// A [material] key that every body overrides with its own [body.material] value is used by
// no body: said like the other unused keys (a probe's material.E beside two bodies' own E
// was taken silently), in the file or by --set, one body or several; not where some body
// follows it.
TEST(StartChecksBodies, AMaterialKeyEveryBodyOverridesIsNamed) {
  auto warnings_of = [](const std::string& toml, const std::vector<std::string>& set = {}) {
    testing::internal::CaptureStderr();
    parse_scene(toml, "w.toml", set);
    return testing::internal::GetCapturedStderr();
  };
  const std::string two = "[[body]]\nshape = \"box\"\n[body.material]\nE = 200000.0\nnu = 0.3\n"
                          "[[body]]\nshape = \"box\"\nposition = [20, 0, 0]\n[body.material]\nE = 100000.0\n";
  const std::string said = "warning: w.toml: material.E is not used: every body overrides it with its own "
                           "[body.material] E";
  EXPECT_NE(warnings_of(two + "[material]\nE = 20000.0\n").find(said), std::string::npos);
  EXPECT_NE(warnings_of(two, {"material.E=5000"}).find(said), std::string::npos);
  EXPECT_EQ(warnings_of(two), "") << "material.E not given: nothing to say";
  EXPECT_EQ(warnings_of(two + "[material]\nnu = 0.45\n"), "") << "body[1] follows material.nu";
  EXPECT_NE(warnings_of("[body]\nshape = \"box\"\n[body.material]\nrho = 2000.0\n[material]\nrho = 1000.0\n")
                .find("material.rho is not used: every body overrides it"),
            std::string::npos);
}

// A track point off the body names the node it follows by that body's own number too (it
// gave the whole-mesh number, 27 or more for body[1] of two 27-node boxes).
TEST(StartChecksBodies, AFarTrackPointNamesItsNodeByItsBodysNumber) {
  const Scene s = parse_scene(std::string("units = \"mm\"\n[[body]]\nshape = \"box\"\nsize = [4, 4, 4]\n"
                                          "divisions = [2, 2, 2]\nposition = [-3, 0, 0]\n[[body]]\nshape = \"box\"\n"
                                          "size = [4, 4, 4]\ndivisions = [2, 2, 2]\nposition = [3, 0, 0]\n") +
                                  kStill + "[output]\ntrack_points = [[40, 0, 0]]\n",
                              "far track point");
  ::testing::internal::CaptureStderr();
  Simulation sim(s, "cpu");
  const std::string log = ::testing::internal::GetCapturedStderr();
  std::smatch m;
  ASSERT_TRUE(std::regex_search(log, m, std::regex("nearest node \\(node ([0-9]+) of body\\[1\\]\\)"))) << log;
  EXPECT_LT(std::stoi(m[1]), 27) << "body[1] has 27 nodes";
}

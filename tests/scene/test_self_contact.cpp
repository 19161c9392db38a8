// Self-contact (contact.self, body_contact.h): the independent self-penetration measure of
// self_penetration.h, and that the stage changes nothing while a body does not touch
// itself (no spurious contacts on its own bent or resting surface).
//
// Not here yet: the beam_fold scene (a beam pushed by a capsule until it touches
// itself, with and without contact.self) and the free-floating momentum check; see the
// commit message for what was tried.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "scene/self_penetration.h"
#include "scene_helpers.h"
#include "sim/scene/simulation.h"

using namespace softtled;
using namespace softtled::test;

namespace {

Scene asset(const std::string& name, const std::vector<std::string>& set = {}) {
  return load_scene(assets_dir() + "/scenes/" + name, set);
}

// A 20 x 2 x 2 mm beam of 1 mm cubes along x, centred at the origin, no floor.
Simulation small_beam() {
  return Simulation(parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [20, 2, 2]\ndivisions = [20, 2, 2]\n"
                                "[floor]\nenabled = false\n",
                                "beam.toml"),
                    "cpu");
}

}  // namespace

// The measure: zero on the rest mesh, and it sees a part of the body moved into another.
TEST(SelfPenetration, ZeroAtRestAndSeesAFoldThroughItself) {
  Simulation sim = small_beam();
  const TetMesh& m = sim.mesh();
  SelfPenetration pen(m);
  int nodes = -1;
  EXPECT_EQ(pen(sim.state(), &nodes), 0.0);
  EXPECT_EQ(nodes, 0);

  // The right half (x > 0.5 mm) moved 10 mm to -x and 0.6 mm down: it lies in the left
  // half, its top face 0.6 mm below the left half's top face (and its bottom face 0.6 mm
  // below the left half's bottom, outside). Nothing is stepped: only the state is measured.
  const int n = m.nnode();
  HostState s;
  s.u.assign(3 * std::size_t(n), 0.0);
  s.du.assign(3 * std::size_t(n), 0.0);
  s.contact.assign(n, 0);
  for (int i = 0; i < n; ++i)
    if (m.X[3 * i] > 0.5e-3) s.u[i] = -10e-3, s.u[n + i] = -0.6e-3;
  const double d = pen(s, &nodes);
  std::printf("folded half: deepest self-penetration %.4f mm, %d surface nodes inside\n", d * 1e3, nodes);
  EXPECT_GT(nodes, 10);
  EXPECT_NEAR(d, 0.6e-3, 0.05e-3);  // the top face's nodes, 0.6 mm under the left half's top
}

// With no self-touching, self-contact changes nothing bit for bit: the cantilever bending
// under gravity (its compressed underside curves into itself) and a cube resting on the
// floor (box edges and corners, where triangles outside a node's 1-ring meet at right
// angles).
TEST(SelfContact, ChangesNothingWhereABodyDoesNotTouchItself) {
  for (const char* name : {"beam_cantilever.toml", "cube_rest.toml"}) {
    Simulation on(asset(name, {"contact.self=true"}), "cpu");
    Simulation off(asset(name, {"contact.self=false"}), "cpu");
    const long n = std::lround(0.05 / on.params().dt);
    on.advance(n, n);
    off.advance(n, n);
    EXPECT_GT(on.diagnostics().max_u, 1e-5) << name;  // it moved
    EXPECT_EQ(on.state().u, off.state().u) << name;
    EXPECT_EQ(on.state().contact, off.state().contact) << name;
    SelfPenetration pen(on.mesh());
    EXPECT_EQ(pen(on.state()), 0.0) << name;
  }
}

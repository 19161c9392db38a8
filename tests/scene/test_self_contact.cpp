// Self-contact (contact.self, body_contact.h): the independent self-penetration measure of
// self_penetration.h, and that the stage changes nothing while a body does not touch
// itself (no spurious contacts on its own bent or resting surface).
//
// And the beam_fold scene: a column crushed by a capsule folds until its halves meet; with
// contact.self they do not pass through each other, without they do.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "backends.h"
#include "scene/self_penetration.h"
#include "scene/state_compare.h"
#include "scene_helpers.h"
#include "sim/contact/body_contact_tables.h"
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
// floor (box edges and corners, where a node's neighbours' triangles meet its own at
// right angles).
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

namespace {
// beam_fold with the given overrides: the deepest self-penetration over the run (sampled
// every 2 ms), the most self-contacts flagged, and the end state's health.
struct FoldRun {
  double worst = 0;
  int inside = 0;
  double min_gap = INFINITY;
};
FoldRun run_beam_fold(const std::vector<std::string>& set) {
  const Scene s = asset("beam_fold.toml", set);
  Simulation sim(s, "cpu");
  SelfPenetration pen(sim.mesh());
  FoldRun r;
  const long every = std::max(1L, std::lround(2e-3 / sim.params().dt));
  while (sim.time() < s.duration) {
    sim.advance(every, every);
    int nodes = 0;
    r.worst = std::max(r.worst, pen(sim.state(), &nodes));
    r.inside = std::max(r.inside, nodes);
    r.min_gap = std::min(r.min_gap, sim.diagnostics().min_gap);
  }
  return r;
}
}  // namespace

// A plate thinner than a tenth of its mean edge (10 x 0.4 x 10 mm, one element thick, a
// probe's scene): with contact.self at rest, in zero gravity, nothing moves. With the
// tolerance a tenth of the mean edge its top nodes lay within it behind its bottom face,
// facing it, and the first step folded an element flat; the body's tolerance is now half
// its shallowest facing depth at rest (body_contact_tables.cpp).
class SelfContactOnEachBackend : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(SelfContactOnEachBackend);

TEST_P(SelfContactOnEachBackend, APlateThinnerThanTheToleranceStaysAtRest) {
  const Scene s = parse_scene(
      "units = \"mm\"\n[body]\nshape = \"box\"\nsize = [10, 0.4, 10]\ndivisions = [2, 1, 2]\n[material]\nE = 20000.0\n"
      "nu = 0.4\n[damping]\nalpha = 0.0\n[gravity]\ng = [0, 0, 0]\n[floor]\nenabled = false\n[contact]\nself = true\n",
      "thin.toml", {"mesh.radius_edge=0", "mesh.keep_boundary=true"});
  Simulation sim(s, backend());
  const BodyContactTables tab = build_body_contact_tables(sim.mesh());
  EXPECT_LE(tab.body_tol[0], 0.2e-3 + 1e-15) << "half the plate's thickness";
  sim.advance_to(0.01);
  const Diagnostics d = sim.diagnostics();
  std::printf("%s: thin plate under contact.self: tolerance %.3g mm, KE %.3g J, centroid off by %.3g m after 10 ms\n",
              backend().c_str(), tab.body_tol[0] * 1e3, d.ke, std::fabs(d.centroid[1]));
  EXPECT_LT(d.ke, 1e-25);
  EXPECT_LT(std::fabs(d.centroid[1]), 1e-12);
}

// On its own mesh and on three others of the same beam: each a different TetGen mesh (a
// beam 0.0001 mm wider, longer or thicker), since where a fold's crease lands on the mesh
// decides how hard it is to hold (README "Limits").
TEST(SelfContact, BeamFoldDoesNotPassThroughItself) {
  const FoldRun off = run_beam_fold({"contact.self=false"});
  std::printf("beam_fold without self-contact: deepest %.4f mm (%d nodes inside)\n", off.worst * 1e3, off.inside);
  EXPECT_GT(off.worst, 0.2e-3);   // without, the halves pass into each other
  EXPECT_GT(off.inside, 10);
  for (const char* size : {"", "body.size=[3.0001,40,3]", "body.size=[3,40.0001,3]", "body.size=[3,40,3.0001]"}) {
    const FoldRun on = run_beam_fold(*size ? std::vector<std::string>{size} : std::vector<std::string>{});
    std::printf("beam_fold %s: self-contact on: deepest %.4f mm (%d nodes inside), min_gap %.4f mm\n",
                *size ? size : "as shipped", on.worst * 1e3, on.inside, on.min_gap * 1e3);
    EXPECT_LT(on.worst, 0.05e-3) << size;  // with, they touch
  }
}

// The GPU's self-contact (the same stage as body-body contact, tled_contact.cu) against the
// CPU's on the folding beam, through its first self-contacts: float tolerance, and the
// same bits run after run.
TEST(SelfContact, BeamFoldOnTheGpuMatchesTheCpu) {
  const std::string why = backend_unavailable("cuda");
  if (!why.empty()) GTEST_SKIP() << why;
  const Scene s = asset("beam_fold.toml", {"solver.precision=double"});
  Simulation cpu(s, "cpu"), gpu(s, "cuda"), again(s, "cuda");
  const long n = std::lround(0.06 / cpu.params().dt);
  cpu.step(n);
  gpu.step(n);
  again.step(n);
  EXPECT_EQ(gpu.state().u, again.state().u);
  const double worst = max_abs_diff(gpu, cpu), umax = max_abs_u(cpu);
  std::printf("beam_fold after %ld steps: max |u_gpu - u_cpu| = %.3g m (max |u| %.3g m), %d contacts\n", n, worst, umax,
              cpu.diagnostics().n_contact);
  EXPECT_GT(cpu.diagnostics().n_contact, 20);
  EXPECT_LT(worst, 1e-4 * umax);
}

// Several bodies ([[body]]): per-body keys and material, body-body
// contact (body_contact.h) on the CPU, and the two shipped scenes' physics:
// two_ring_collision (momentum conserved, kinetic energy only lost, the rings separate)
// and torus_stack (no interpenetration beyond 0.05 mm, it settles). Bad input: overlapping
// bodies, too many bodies, unknown keys, a non-boolean contact.self.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "backends.h"
#include "scene_helpers.h"
#include "sim/contact/body_contact.h"
#include "sim/contact/body_contact_tables.h"
#include "sim/contact/mesh_sdf.h"
#include "sim/scene/closing_speeds.h"
#include "sim/scene/simulation.h"

using namespace softtled;
using namespace softtled::test;

namespace {

Scene asset(const std::string& name, const std::vector<std::string>& set = {}) {
  return load_scene(assets_dir() + "/scenes/" + name, set);
}

// Current position of node i.
void position(const Simulation& sim, const HostState& st, int i, double x[3]) {
  const int n = sim.mesh().nnode();
  for (int k = 0; k < 3; ++k) x[k] = sim.mesh().X[3 * i + k] + st.u[k * n + i];
}

double point_triangle_distance(const double p[3], const double a[3], const double b[3], const double c[3]) {
  double q[3];
  closest_point_on_triangle(p, a, b, c, q);  // Ericson 5.1.5 (sim/contact/mesh_sdf.h)
  return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
}

// Deepest penetration of a surface node of one body into another body now [m]: a node
// inside an element of another body is that far from the other body's boundary (the
// nearest boundary triangle); 0 when no node is inside another body.
double max_penetration(Simulation& sim) {
  const HostState& st = sim.state();
  const TetMesh& m = sim.mesh();
  const int nb = m.nbody();
  std::vector<double> x(3 * std::size_t(m.nnode()));
  for (int i = 0; i < m.nnode(); ++i) position(sim, st, i, &x[3 * i]);
  std::vector<double> lo(3 * nb, 1e300), hi(3 * nb, -1e300);
  for (int i = 0; i < m.nnode(); ++i)
    for (int k = 0; k < 3; ++k) {
      const int b = m.node_body[i];
      lo[3 * b + k] = std::min(lo[3 * b + k], x[3 * i + k]);
      hi[3 * b + k] = std::max(hi[3 * b + k], x[3 * i + k]);
    }
  double worst = 0;
  for (int i : m.surface_nodes) {
    const double* p = &x[3 * i];
    for (int b = 0; b < nb; ++b) {
      if (b == m.node_body[i]) continue;
      bool inbox = true;
      for (int k = 0; k < 3; ++k) inbox = inbox && p[k] >= lo[3 * b + k] && p[k] <= hi[3 * b + k];
      if (!inbox) continue;
      bool inside = false;
      for (int e = 0; e < m.ntet() && !inside; ++e) {
        if (m.tet_body[e] != b) continue;
        const int* t = &m.tet[4 * e];
        inside = point_in_tet(&x[3 * t[0]], &x[3 * t[1]], &x[3 * t[2]], &x[3 * t[3]], p);
      }
      if (!inside) continue;
      double depth = 1e300;
      for (int f = 0; f < m.nbtri(); ++f) {
        const int* t = &m.boundary_tri[3 * f];
        if (m.node_body[t[0]] != b) continue;
        depth = std::min(depth, point_triangle_distance(p, &x[3 * t[0]], &x[3 * t[1]], &x[3 * t[2]]));
      }
      worst = std::max(worst, depth);
    }
  }
  return worst;
}

// Total linear momentum (sum m du / dt) [kg m/s].
void momentum(Simulation& sim, double P[3]) {
  const HostState& st = sim.state();
  const int n = sim.mesh().nnode();
  const auto& m = sim.lumped_mass();
  for (int k = 0; k < 3; ++k) {
    P[k] = 0;
    for (int i = 0; i < n; ++i) P[k] += m[i] * st.du[k * n + i];
    P[k] /= sim.params().dt;
  }
}

// Mass-weighted mean velocity of body b along x [m/s].
double body_vx(Simulation& sim, int b) {
  const HostState& st = sim.state();
  const auto& m = sim.lumped_mass();
  double p = 0, mt = 0;
  for (int i = 0; i < sim.mesh().nnode(); ++i)
    if (sim.mesh().node_body[i] == b) p += m[i] * st.du[i], mt += m[i];
  return p / mt / sim.params().dt;
}

}  // namespace

// ---- scene format ----

TEST(Bodies, OneBodyTableAndOneBodyArrayAreTheSameScene) {
  const std::string body = "shape = \"box\"\nsize = [4, 4, 4]\ndivisions = [1, 1, 1]\nposition = [0, 5, 0]\n";
  const Scene a = parse_scene("[body]\n" + body, "a.toml");
  const Scene b = parse_scene("[[body]]\n" + body, "b.toml");
  EXPECT_EQ(a.body_count(), 1);
  EXPECT_EQ(b.body_count(), 1);
  EXPECT_EQ(a.position, b.position);
  EXPECT_FALSE(a.body_contact());
  Simulation sa(a, "cpu"), sb(b, "cpu");
  EXPECT_TRUE(sa.mesh().node_body.empty());
  sa.step(200);
  sb.step(200);
  EXPECT_EQ(sa.state().u, sb.state().u);  // bit for bit
}

TEST(Bodies, SetAddressesBodiesByIndex) {
  const std::string t = "[[body]]\nshape = \"sphere\"\n[[body]]\nshape = \"box\"\nposition = [20, 0, 0]\n";
  const Scene s = parse_scene(t, "s.toml", {"body.0.position=[1, 2, 3]", "body.1.velocity=[0, -1, 0]",
                                            "body.1.material.E=9000"});
  EXPECT_EQ(s.body(0).position, (std::array<double, 3>{1, 2, 3}));
  EXPECT_EQ(s.body(1).velocity, (std::array<double, 3>{0, -1, 0}));
  EXPECT_EQ(s.body_E(1), 9000);
  EXPECT_EQ(s.body_E(0), s.E);
  EXPECT_TRUE(s.body_contact());
  EXPECT_FALSE(parse_scene(t, "s.toml", {"contact.bodies=false"}).body_contact());
  // A one-body [body] scene takes body.0.*; a [[body]] scene refuses the plain body.* form.
  EXPECT_EQ(parse_scene("[body]\nshape = \"box\"\n", "s.toml", {"body.0.position=[0, 7, 0]"}).position[1], 7);
  EXPECT_THROW(parse_scene(t, "s.toml", {"body.position=[0, 0, 0]"}), InputError);
  EXPECT_THROW(parse_scene(t, "s.toml", {"body.2.position=[0, 0, 0]"}), InputError);
}

namespace {
std::string error_of(const std::string& toml, const std::vector<std::string>& set = {}) {
  try {
    const Scene s = parse_scene(toml, "bad.toml", set);
    Simulation sim(s, "cpu");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

// Two turned boxes face to face touch wherever they lie: 100 m from the origin their shared
// face is flat only to the rounding of the coordinates there (~1e-14 m), which once read as
// surface edges crossing it. 0.04 um into each other they overlap there too.
TEST(Bodies, TurnedBoxesFaceToFaceTouchFarFromTheOrigin) {
  // body.rotation_deg = [13, 27, 41] turns x, then y, then z: the turned x axis times 4 mm.
  const double pi = 3.14159265358979323846, ay = 27 * pi / 180, az = 41 * pi / 180;  // (x first: e_x stays)
  const double axis[3] = {std::cos(az) * std::cos(ay), std::sin(az) * std::cos(ay), -std::sin(ay)};
  for (const double x0 : {0.0, 100000.0}) {
    for (const double f : {1.0, 0.99999}) {
      char at[2][120];
      std::snprintf(at[0], sizeof at[0], "body.0.position=[%.17g, 0, 0]", x0);
      std::snprintf(at[1], sizeof at[1], "body.1.position=[%.17g, %.17g, %.17g]", x0 + 4 * f * axis[0], 4 * f * axis[1],
                    4 * f * axis[2]);
      const std::string box = "[[body]]\nshape = \"box\"\nsize = [4, 4, 4]\ndivisions = [2, 2, 2]\nrotation_deg = [13, 27, 41]\n";
      const std::string e = error_of("units = \"mm\"\n" + box + box + "[floor]\nenabled = false\n", {at[0], at[1]});
      if (f == 1.0)
        EXPECT_EQ(e, "") << "x0 = " << x0;
      else
        EXPECT_NE(e.find("overlap at the start"), std::string::npos) << "x0 = " << x0 << ": " << e;
    }
  }
}

TEST(Bodies, BadInputNamesTheKey) {
  const std::string two = "[[body]]\nshape = \"sphere\"\nradius = 3\nsubdivisions = 1\n[[body]]\nshape = \"sphere\"\n"
                          "radius = 3\nsubdivisions = 1\nposition = [10, 0, 0]\n[floor]\nenabled = false\n";
  EXPECT_EQ(error_of(two), "");
  // Overlapping at the start: both bodies named.
  const std::string e1 = error_of(two, {"body.1.position=[2, 0, 0]"});
  EXPECT_NE(e1.find("body[1] and body[0] overlap"), std::string::npos) << e1;
  // One body wholly inside the other.
  const std::string e1b = error_of(two, {"body.1.position=[0, 0, 0]", "body.1.radius=1"});
  EXPECT_NE(e1b.find("overlap"), std::string::npos) << e1b;
  // A plate 0.1 um thin through a torus's hole and tube: no node, edge midpoint or centre
  // of either lies inside the other, but the torus's surface edges cross the plate's faces.
  const std::string plate =
      "[[body]]\nshape = \"torus\"\nsegments = [45, 9]\n[[body]]\nshape = \"box\"\nsize = [40, 40, 0.0001]\n"
      "divisions = [1, 1, 1]\nposition = [0, 0.3, 0]\nrotation_deg = [90, 0, 0]\n[mesh]\nkeep_boundary = true\n"
      "radius_edge = 0\n[floor]\nenabled = false\n";
  const std::string e1c = error_of(plate);
  EXPECT_NE(e1c.find("body[0] and body[1] overlap at the start (the surface edge between nodes"), std::string::npos)
      << e1c;
  EXPECT_EQ(error_of(plate, {"body.1.position=[0, 10, 0]"}), "") << "the same plate above the torus is fine";
  // Touching is not overlapping: boxes face to face, along an edge, corner to corner (each
  // was refused, a node "in" the other's element or an edge "crossing" at its end point);
  // 1 um into each other they overlap.
  const std::string boxes = "units = \"mm\"\n[[body]]\nshape = \"box\"\nsize = [4, 4, 4]\ndivisions = [2, 2, 2]\n"
                            "[[body]]\nshape = \"box\"\nsize = [4, 4, 4]\ndivisions = [2, 2, 2]\n[floor]\nenabled = false\n";
  for (const char* at : {"[4, 0, 0]", "[4, 4, 0]", "[4, 4, 4]", "[4, 2, 2]"})
    EXPECT_EQ(error_of(boxes, {std::string("body.1.position=") + at}), "") << at;
  EXPECT_NE(error_of(boxes, {"body.1.position=[3.999, 0, 0]"}).find("overlap at the start"), std::string::npos);
  // Overlapping where every node and edge of each lies on the other's boundary: two copies
  // of a body at one place, and boxes of one element across (their face diagonals run
  // through the other's interior) overlapping by 4 mm down to a 1 um slab. Each was accepted
  // while only nodes and edge crossings were tested.
  const std::string cubes = "units = \"mm\"\n[[body]]\nshape = \"box\"\nsize = [4, 4, 4]\ndivisions = [1, 1, 1]\n"
                            "[[body]]\nshape = \"box\"\nsize = [4, 4, 4]\ndivisions = [1, 1, 1]\n[floor]\nenabled = false\n";
  for (const char* at : {"[0, 0, 0]", "[1, 0, 0]", "[2, 0, 0]", "[3.5, 0, 0]", "[3.9, 0, 0]", "[3.999, 0, 0]"}) {
    const std::string e = error_of(cubes, {std::string("body.1.position=") + at});
    EXPECT_NE(e.find("body[1] and body[0] overlap at the start"), std::string::npos) << at << ": " << e;
  }
  for (const char* at : {"[4, 0, 0]", "[4, 4, 0]", "[4, 4, 4]", "[4, 2, 2]"})
    EXPECT_EQ(error_of(cubes, {std::string("body.1.position=") + at}), "") << at;
  EXPECT_NE(error_of(two, {"body.1.position=[0, 0, 0]"}).find("overlap at the start"), std::string::npos)
      << "two copies of a sphere";
  EXPECT_NE(error_of(boxes, {"body.1.position=[0, 0, 0]"}).find("overlap at the start"), std::string::npos)
      << "two copies of a box";
  // A small plate inside a plate of the same thickness, straight and turned.
  const std::string plates = "units = \"mm\"\n[[body]]\nshape = \"box\"\nsize = [20, 1, 20]\ndivisions = [1, 1, 1]\n"
                             "[[body]]\nshape = \"box\"\nsize = [5, 1, 5]\ndivisions = [1, 1, 1]\n[floor]\nenabled = false\n";
  for (const char* turn : {"[0, 0, 0]", "[0, 30, 0]"})
    EXPECT_NE(error_of(plates, {std::string("body.1.rotation_deg=") + turn}).find("overlap at the start"), std::string::npos)
        << turn;
  // A body below the floor: named, with a key that can move it (body.position is refused
  // in a scene of several bodies).
  const std::string e_floor = error_of(two, {"body.1.position=[10, -20, 0]", "floor.enabled=true", "floor.point=[0, -10, 0]"});
  EXPECT_NE(e_floor.find("body[1] starts 13 mm inside the floor plane; move body[1].position"), std::string::npos)
      << e_floor;
  // TetGen's findings on one body of several name it.
  const std::string e_tetgen = error_of(two, {"mesh.max_tets=10"});
  EXPECT_NE(e_tetgen.find("bad.toml: body[0]: mesh too large"), std::string::npos) << e_tetgen;
  // Too many bodies.
  std::string many;
  for (int i = 0; i <= kMaxBodies; ++i) many += "[[body]]\nshape = \"sphere\"\n";
  const std::string e2 = error_of(many);
  EXPECT_NE(e2.find("body: at most 32 bodies"), std::string::npos) << e2;
  // Unknown keys, in a body and in its material.
  const std::string e3 = error_of(two + "[[body]]\nshape = \"box\"\ncolour = \"red\"\n");
  EXPECT_NE(e3.find("body[2].colour: unknown key"), std::string::npos) << e3;
  const std::string e4 = error_of("[[body]]\nshape = \"box\"\n[body.material]\ncolour = \"red\"\n");
  EXPECT_NE(e4.find("body[0].material.colour: unknown key"), std::string::npos) << e4;
  const std::string e4b = error_of("[body]\nshape = \"box\"\nsegmnts = [3, 3]\n");
  EXPECT_NE(e4b.find("bad.toml: body.segmnts: unknown key"), std::string::npos) << e4b;
  // contact.self takes a boolean.
  const std::string e5 = error_of(two + "[contact]\nself = 1\n");
  EXPECT_NE(e5.find("contact.self"), std::string::npos) << e5;
  EXPECT_EQ(error_of(two + "[contact]\nself = true\n"), "");
  // A body's own law out of range or not implemented (T4ANP of the stable model), and an
  // unknown model or element, name the body's key.
  const std::string e6 = error_of(two, {"body.1.material.nu=0.5"});
  EXPECT_NE(e6.find("body[1].material.nu"), std::string::npos) << e6;
  const std::string e7 = error_of(two, {"body.1.material.element=\"T4ANP\"", "material.model=\"stable_neo_hookean\""});
  EXPECT_NE(e7.find("body[1].material: T4ANP is implemented for the neo_hookean model only"), std::string::npos) << e7;
  const std::string e8 = error_of(two, {"body.0.material.model=\"mooney\""});
  EXPECT_NE(e8.find("body[0].material.model"), std::string::npos) << e8;
  const std::string e9 = error_of(two, {"body.1.material.element=\"T10\""});
  EXPECT_NE(e9.find("body[1].material.element"), std::string::npos) << e9;
}

// Per-body material: the mass follows each body's rho, and a stiffer body is stiffer.
TEST(Bodies, PerBodyMaterialSetsMassAndStiffness) {
  const std::string t = "[[body]]\nshape = \"box\"\nsize = [4, 4, 4]\ndivisions = [1, 1, 1]\n"
                        "[[body]]\nshape = \"box\"\nsize = [4, 4, 4]\ndivisions = [1, 1, 1]\nposition = [10, 0, 0]\n"
                        "[body.material]\nE = 12000\nrho = 3000\n"
                        "[material]\nE = 3000\nrho = 1000\nnu = 0.3\n[floor]\nenabled = false\n";
  Simulation sim(parse_scene(t, "m.toml"), "cpu");
  double mass[2] = {0, 0};
  for (int i = 0; i < sim.mesh().nnode(); ++i) mass[sim.mesh().node_body[i]] += sim.lumped_mass()[i];
  EXPECT_NEAR(mass[0], 1000 * 64e-9, 1e-15);
  EXPECT_NEAR(mass[1], 3000 * 64e-9, 1e-15);
  // Wave speed of body 1 is sqrt(12000/3000 / (3000/1000))... its 2/omega_max bounds dt:
  // with both bodies of the scene's material the stable step is sqrt(4 / 3) longer.
  Simulation plain(parse_scene(t, "m.toml", {"body.1.material.E=3000", "body.1.material.rho=1000"}), "cpu");
  EXPECT_NEAR(plain.time_step().dt_eigen / sim.time_step().dt_eigen, std::sqrt(4.0 / 3.0), 1e-3);
}

// ---- body-body contact ----

class BodyContactOnEachBackend : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(BodyContactOnEachBackend);

TEST_P(BodyContactOnEachBackend, TwoRingCollisionConservesMomentumLosesEnergyAndSeparates) {
  Scene s = asset("two_ring_collision.toml");
  Simulation sim(s, backend());
  double P0[3];
  momentum(sim, P0);
  const double p0 = std::sqrt(P0[0] * P0[0] + P0[1] * P0[1] + P0[2] * P0[2]);
  ASSERT_GT(p0, 0);
  const double ke0 = sim.diagnostics().ke;
  double drift = 0, min_dx = 1e300, worst_pen = 0, min_gap = INFINITY;
  int contacts = 0;
  const long every = std::max(1L, std::lround(5e-4 / sim.params().dt));
  while (sim.time() < s.duration) {
    sim.advance(every, every);
    double P[3];
    momentum(sim, P);
    for (int k = 0; k < 3; ++k) drift = std::max(drift, std::fabs(P[k] - P0[k]) / p0);
    const Diagnostics d = sim.diagnostics();
    min_dx = std::min(min_dx, d.body_centroid[3] - d.body_centroid[0]);
    contacts = std::max(contacts, d.n_contact);
    min_gap = std::min(min_gap, d.min_gap);
    worst_pen = std::max(worst_pen, max_penetration(sim));
  }
  const Diagnostics d = sim.diagnostics();
  const double v0 = body_vx(sim, 0), v1 = body_vx(sim, 1);
  std::printf("two rings: momentum drift %.3g (relative), KE %.6g -> %.6g J, closest centroids %.3f mm, "
              "final v %.4f / %.4f m/s, max penetration %.4f mm, max contacts %d, min_gap %.4f mm\n",
              drift, ke0, d.ke, min_dx * 1e3, v0, v1, worst_pen * 1e3, contacts, min_gap * 1e3);
  EXPECT_LT(drift, 1e-6);
  EXPECT_GT(contacts, 10);                     // they did meet
  EXPECT_LE(d.ke, ke0);                        // projection contact is inelastic
  EXPECT_LT(v0, v1);                           // ring 0 now slower than ring 1: moving apart
  EXPECT_GT(d.body_centroid[3] - d.body_centroid[0], min_dx + 1e-4);  // and apart by now
  EXPECT_LT(min_dx, 8e-3 - 1e-3);              // started 8 mm apart, came closer by > 1 mm
  EXPECT_LT(worst_pen, 0.05e-3);
  // min_gap (no planes here) is the rings' gap: measured while they touch, never deeper
  // than the penetration bound.
  EXPECT_LT(min_gap, 1e-4);
  EXPECT_GT(min_gap, -0.05e-3);
}

// Without body-body contact the same rings pass into each other (the measure can fail).
TEST(Bodies, WithoutBodyContactTheRingsInterpenetrate) {
  Simulation sim(asset("two_ring_collision.toml", {"contact.bodies=false", "time.duration=0.01"}), "cpu");
  double worst = 0;
  const long every = std::max(1L, std::lround(5e-4 / sim.params().dt));
  while (sim.time() < 0.01) {
    sim.advance(every, every);
    worst = std::max(worst, max_penetration(sim));
  }
  EXPECT_GT(worst, 0.5e-3) << worst;
}

TEST_P(BodyContactOnEachBackend, TorusStackSettlesWithoutInterpenetration) {
  Scene s = asset("torus_stack.toml");
  Simulation sim(s, backend());
  double peak = 0, worst = 0, ke = 0;
  const long every = std::max(1L, std::lround(2e-3 / sim.params().dt));
  while (sim.time() < s.duration) {
    sim.advance(every, every);
    ke = sim.diagnostics().ke;
    peak = std::max(peak, ke);
    worst = std::max(worst, max_penetration(sim));
  }
  const Diagnostics d = sim.diagnostics();
  std::printf("torus stack: max penetration %.4f mm, KE peak %.4g J, final %.4g J (%.3f %%), centroids y %.3f %.3f %.3f mm\n",
              worst * 1e3, peak, ke, 100 * ke / peak, d.body_centroid[1] * 1e3, d.body_centroid[4] * 1e3,
              d.body_centroid[7] * 1e3);
  EXPECT_LT(worst, 0.05e-3);
  EXPECT_LT(ke, 0.01 * peak);
  // Stacked: each ring rests above the one below (5 mm apart when flat on each other; less
  // where a ring tilts down past the rim of the one below).
  EXPECT_GT(d.body_centroid[4], d.body_centroid[1] + 1e-3);
  EXPECT_GT(d.body_centroid[7], d.body_centroid[4] + 1e-3);
  EXPECT_GT(d.min_gap, -0.05e-3);  // and on the floor, not in it
}

// A block sliding over another body moves as over a rigid box: a 4 mm cube at 0.1 m/s on a
// clamped slab (E = 200 kPa, alpha = 0) keeps its speed without friction (6.047 mm in
// 0.06047 s) and with Coulomb friction stops after v^2 / (2 mu g) = 1.699 mm, never
// turning back. The slab's surface nodes under the cube's front edge lie on its bottom
// face and behind its front face; pushed out through the front face (which does not face
// them, body_contact.h faces_some) they stopped the cube after 1 mm, turned it back and
// made it hop; min_gap read them as 0.2 mm inside the cube.
TEST_P(BodyContactOnEachBackend, ABlockSlidesOverAnotherBodyAsOverARigidBox) {
  const std::string t =
      "units = \"mm\"\n"
      "[[body]]\nshape = \"box\"\nsize = [30, 4, 20]\ndivisions = [6, 1, 4]\nposition = [0, -2, 0]\n"
      "[[body]]\nshape = \"box\"\nsize = [4, 4, 4]\ndivisions = [2, 2, 2]\nposition = [-8, 2, 0]\n"
      "velocity = [0.1, 0, 0]\n"
      "[material]\nE = 2e5\nnu = 0.3\nrho = 1000\n[damping]\nalpha = 0\nbeta = 1e-5\n[floor]\nenabled = false\n"
      "[[fixed]]\nbox_min = [-16, -5, -11]\nbox_max = [16, -3.99, 11]\n[contact]\nmu = 0.3\n"
      "[time]\nduration = 0.06\n";
  const double g = 9.81, v = 0.1, mu = 0.3;
  for (const char* mode : {"sliding", "coulomb"}) {
    const Scene s = parse_scene(t, "slide.toml", {std::string("contact.mode=") + mode});
    Simulation sim(s, backend());
    const double x0 = sim.diagnostics().body_centroid[3];
    double x = x0, back = 0, lift = 0, gap = INFINITY;
    const long every = std::max(1L, std::lround(1e-3 / sim.params().dt));
    while (sim.time() < s.duration) {
      sim.advance(every, every);
      const Diagnostics d = sim.diagnostics();
      back = std::max(back, x - d.body_centroid[3]);  // turning back
      lift = std::max(lift, d.body_centroid[4] - 2e-3);  // hopping
      gap = std::min(gap, d.min_gap);
      x = d.body_centroid[3];
    }
    const double slid = x - x0, expect = mode[0] == 's' ? v * sim.time() : v * v / (2 * mu * g);
    std::printf("%s: slid %.4f mm (rigid block %.4f), turned back %.2g mm, rose %.2g mm, min_gap %.2g mm\n", mode,
                slid * 1e3, expect * 1e3, back * 1e3, lift * 1e3, gap * 1e3);
    EXPECT_NEAR(slid, expect, 0.01 * expect) << mode;
    EXPECT_LT(back, 1e-6) << mode;
    EXPECT_LT(lift, 1e-5) << mode;
    // The block rests on the slab: min_gap is the slab's elastic give, not a node behind the
    // front face it slid over (-0.2 mm when the gap did not ask which triangles face it).
    EXPECT_GT(gap, -1e-6) << mode;
    EXPECT_LT(gap, 0) << mode;
  }
}

// The scaling scene (bench/bodies_scaling.sh): ten rings falling onto each other. Through
// the first 0.1 s (each ring lands on the one below, up to 631 nodes in contact) no node
// goes halfway to the contact tolerance into another ring (a node deeper than the
// tolerance would be lost by the node-triangle rule; measured 0.0003 mm), nor 0.05 mm
// into the floor.
TEST(Bodies, TorusPileFallsWithoutInterpenetration) {
  Scene s = asset("torus_pile.toml", {"time.duration=0.1"});
  Simulation sim(s, "cpu");
  ASSERT_EQ(sim.mesh().nbody(), 10);
  double worst = 0, min_gap = INFINITY;
  int contacts = 0;
  const long every = std::max(1L, std::lround(10e-3 / sim.params().dt));
  while (sim.time() < s.duration) {
    sim.advance(every, every);
    const Diagnostics d = sim.diagnostics();
    contacts = std::max(contacts, d.n_contact);
    min_gap = std::min(min_gap, d.min_gap);
    worst = std::max(worst, max_penetration(sim));
  }
  std::printf("torus pile: max penetration %.4f mm, min_gap %.4f mm, max contacts %d\n", worst * 1e3, min_gap * 1e3,
              contacts);
  EXPECT_GT(contacts, 50);
  const std::vector<double> tol = build_body_contact_tables(sim.mesh()).body_tol;
  EXPECT_LT(worst, 0.5 * *std::min_element(tol.begin(), tol.end()));
  EXPECT_GT(min_gap, -0.05e-3);
}

// Deterministic: the same run twice, and on 1 and 2 threads, bit for bit.
TEST(Bodies, BodyContactIsBitwiseRepeatable) {
  Scene s = asset("two_ring_collision.toml", {"time.duration=0.01"});
  Scene s1 = s;
  s1.threads = 1;
  Scene s2 = s;
  s2.threads = 2;
  Simulation a(s1, "cpu"), b(s2, "cpu"), c(s1, "cpu");
  const long n = std::lround(0.006 / a.params().dt);
  a.step(n);
  b.step(n);
  c.step(n);
  EXPECT_GT(a.diagnostics().n_contact, 0);
  EXPECT_EQ(a.state().u, b.state().u);
  EXPECT_EQ(a.state().du, b.state().du);
  EXPECT_EQ(a.state().u, c.state().u);
}

// The GPU's contact stage (tled_contact.cu) against the CPU's (body_contact_cpu.cpp): the
// same pairs, shares and sums, so the rings agree to float tolerance through the impact;
// and every CUDA mode gives the same bits, run after run.
TEST(Bodies, BodyContactOnTheGpuMatchesTheCpuAndRepeats) {
  const std::string why = backend_unavailable("cuda");
  if (!why.empty()) GTEST_SKIP() << why;
  const Scene s = asset("two_ring_collision.toml", {"time.duration=0.01"});
  Simulation cpu(s, "cpu");
  const long n = std::lround(0.006 / cpu.params().dt);  // through the first contact
  cpu.step(n);
  ASSERT_GT(cpu.diagnostics().n_contact, 10);
  std::vector<std::vector<double>> runs;
  for (const char* mode : {"fused", "graph-pdl", "fused", "halo"}) {
    setenv("SOFTTLED_CUDA_MODE", mode, 1);
    Simulation gpu(s, "cuda");
    unsetenv("SOFTTLED_CUDA_MODE");
    gpu.step(n);
    runs.push_back(gpu.state().u);
  }
  EXPECT_EQ(runs[0], runs[1]) << "fused and graph-pdl differ";
  EXPECT_EQ(runs[0], runs[2]) << "two fused runs differ";
  EXPECT_EQ(runs[0], runs[3]) << "fused and halo differ";
  double worst = 0, umax = 0;
  const std::vector<double>& uc = cpu.state().u;
  for (std::size_t k = 0; k < uc.size(); ++k) {
    worst = std::max(worst, std::fabs(runs[0][k] - uc[k]));
    umax = std::max(umax, std::fabs(uc[k]));
  }
  std::printf("two rings after %ld steps: max |u_gpu - u_cpu| = %.3g m (max |u| %.3g m)\n", n, worst, umax);
  EXPECT_LT(worst, 1e-4 * umax);
}

// The value functions alone: a node falling onto a triangle lands on its plane, and the
// four nodes' shares (pair_terms) keep sum m du, frictionless and with friction. A node
// already behind the plane by less than the tolerance (a split impulse) is shifted back
// onto it by a change of position alone, which keeps sum m x; its step goes no deeper.
TEST(Bodies, NodeTriangleCorrectionConservesMomentum) {
  const double m[4] = {2, 1, 3, 5}, inv_m[4] = {1 / m[0], 1 / m[1], 1 / m[2], 1 / m[3]};
  const int one[4] = {1, 1, 1, 1};
  for (double zp0 : {0.01, -0.02})
    for (int mode : {int(kSliding), int(kStatic), int(kCoulomb)}) {
      const double xa[3] = {0, 0, 0}, xb[3] = {1, 0, 0}, xc[3] = {0, 1, 0}, xp[3] = {0.2, 0.3, zp0};
      const double dua[3] = {0, 0, 0.001}, dub[3] = {0.002, 0, 0}, duc[3] = {0, 0, 0.003}, dup[3] = {0.01, 0.02, -0.05};
      const auto r = node_triangle_contact(xp, dup, true, xa, dua, xb, dub, xc, duc, 0.1, mode, 0.3);
      ASSERT_NE(r.state, kFree);
      double step[4][3], shift[4][3];
      for (int a = 0; a < 4; ++a) pair_terms(r, one, inv_m, a, step[a], shift[a]);
      for (int k = 0; k < 3; ++k) {
        double dp = 0, dx = 0;
        for (int a = 0; a < 4; ++a) dp += m[a] * step[a][k], dx += m[a] * shift[a][k];
        EXPECT_NEAR(dp, 0, 1e-17) << mode;
        EXPECT_NEAR(dx, 0, 1e-17) << mode;
      }
      // The node ends on the triangle's (moving) plane, or as deep as it was at t where it
      // was behind it: z of the node - z of its point. The shift then puts it on the plane.
      const double wa = 0.5, wb = 0.2, wc = 0.3;
      auto gap = [&](bool shifted) {
        const double s = shifted ? 1 : 0;
        const double zp = xp[2] + dup[2] + step[0][2] + s * shift[0][2];
        const double zt = wa * (xa[2] + dua[2] + step[1][2] + s * shift[1][2]) +
                          wb * (xb[2] + dub[2] + step[2][2] + s * shift[2][2]) +
                          wc * (xc[2] + duc[2] + step[3][2] + s * shift[3][2]);
        return zp - zt;
      };
      EXPECT_NEAR(gap(false), std::min(zp0, 0.0), 1e-15) << mode;
      EXPECT_NEAR(gap(true), 0, 1e-15) << mode;
    }
}

// A node resting on a vertex shared by six coplanar triangles (two meshes node on node):
// its foot is that corner in each, where rounding put the weights a hair outside every
// triangle until the foot was snapped (kFootSnap). All six pairs are accepted with the
// foot on the centre; the corners it has no weight on take no part; and the mass-split
// terms of the six pairs together change the relative step by exactly Delta (each pair
// solved for sub-bodies of mass m / 6) and keep sum m du.
TEST(Bodies, ANodeOnASharedVertexIsHeldByEveryTriangleAroundIt) {
  const double xc[3] = {0, 0, 0}, xp[3] = {1e-17, -1e-17, -0.001}, zero[3] = {0, 0, 0}, dup[3] = {0, 0, -0.01};
  const double m_node = 2, m_centre = 3, inv_m_node = 1 / m_node, inv_m_centre = 1 / m_centre;
  std::vector<NodeTriangleCorrection<double>> pairs;
  for (int k = 0; k < 6; ++k) {
    const double a0 = k * M_PI / 3, a1 = (k + 1) * M_PI / 3;
    const double xa[3] = {std::cos(a0), std::sin(a0), 0}, xb[3] = {std::cos(a1), std::sin(a1), 0};
    const auto r = node_triangle_contact(xp, dup, true, xc, zero, xa, zero, xb, zero, 0.1, int(kSliding), 0.0);
    ASSERT_NE(r.state, kFree) << "triangle " << k;
    EXPECT_EQ(r.w[0], 1.0) << k;
    EXPECT_TRUE(takes_part(r, 0) && takes_part(r, 1) && !takes_part(r, 2) && !takes_part(r, 3)) << k;
    pairs.push_back(r);
  }
  const int count[4] = {6, 6, 0, 0};
  const double inv_m[4] = {inv_m_node, inv_m_centre, 1.0, 1.0};
  double node_z = 0, centre_z = 0, node_shift = 0, centre_shift = 0;
  for (const auto& r : pairs) {
    double step[3], shift[3];
    pair_terms(r, count, inv_m, 0, step, shift);
    node_z += step[2], node_shift += shift[2];
    pair_terms(r, count, inv_m, 1, step, shift);
    centre_z += step[2], centre_shift += shift[2];
    pair_terms(r, count, inv_m, 2, step, shift);
    EXPECT_EQ(step[2], 0.0);
  }
  // Delta: the relative step -0.01 goes to 0 (the node is behind: no deeper); the shift
  // takes the 0.001 of depth back.
  EXPECT_NEAR((dup[2] + node_z) - centre_z, 0.0, 1e-15);
  EXPECT_NEAR(node_shift - centre_shift, 0.001, 1e-15);
  EXPECT_NEAR(m_node * node_z + m_centre * centre_z, 0.0, 1e-17);
  EXPECT_NEAR(m_node * node_shift + m_centre * centre_shift, 0.0, 1e-17);
}

// Several bodies without body-body contact run on every backend (CUDA included: the
// per-body material is in the rest state, which the CUDA solver renumbers), and agree:
// the same masses and strain energy, and two rings of different E and rho falling side by
// side onto the floor land as on the CPU.
class BodiesOnEachBackend : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(BodiesOnEachBackend);

TEST_P(BodiesOnEachBackend, TwoRingsWithOwnMaterialsFallSideBySide) {
  const std::vector<std::string> set = {"contact.bodies=false", "gravity.g=[0, -9.81, 0]", "floor.enabled=true",
                                        "floor.point=[0, -11, 0]", "body.0.velocity=[0, 0, 0]",
                                        "body.1.velocity=[0, 0, 0]", "body.1.position=[12, 0, 0]",
                                        "damping.alpha=10", "solver.precision=float"};
  Simulation cpu(asset("two_ring_collision.toml", set), "cpu");
  Simulation sim(asset("two_ring_collision.toml", set), backend());
  // The rest state carries each body's material: the same masses, and the same strain
  // energy at an imposed stretch (ring 1 has twice ring 0's E).
  ASSERT_EQ(cpu.lumped_mass().size(), sim.lumped_mass().size());
  for (std::size_t i = 0; i < cpu.lumped_mass().size(); ++i)
    ASSERT_NEAR(cpu.lumped_mass()[i], sim.lumped_mass()[i], 1e-12 * cpu.lumped_mass()[i]) << i;
  {
    HostState st = cpu.state();
    const int n = cpu.mesh().nnode();
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) st.u[k * n + i] = (k == 1 ? 0.02 : -0.005) * cpu.mesh().X[3 * i + k];
    cpu.set_state(st);
    sim.set_state(st);
    const double e0 = cpu.diagnostics().se, e1 = sim.diagnostics().se;
    EXPECT_GT(e0, 0);
    EXPECT_NEAR(e1, e0, 1e-4 * e0);
    // Ring 1 alone (twice as stiff) against ring 0 alone under the same stretch: its energy
    // per volume is twice ring 0's, and the rings have the same volume.
    HostState half = st;
    for (int i = 0; i < n; ++i)
      if (cpu.mesh().node_body[i] == 1)
        for (int k = 0; k < 3; ++k) half.u[k * n + i] = 0;
    cpu.set_state(half);
    const double e_ring0 = cpu.diagnostics().se;
    EXPECT_NEAR(e0 - e_ring0, 2 * e_ring0, 0.02 * e_ring0);
  }
  cpu.reset();
  sim.reset();
  const long n = std::lround(0.03 / cpu.params().dt);
  cpu.advance(n, n);
  sim.advance(n, n);
  const Diagnostics a = cpu.diagnostics(), b = sim.diagnostics();
  ASSERT_EQ(a.body_centroid.size(), 6u);
  // 0.03 s in float through a landing: the backends round differently (FMA, order).
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(a.body_centroid[k], b.body_centroid[k], 5e-5) << k;
  EXPECT_GT(a.n_contact, 0);  // landed (from 1 mm up, at 14 ms)
  EXPECT_GT(b.n_contact, 0);
}

// Friction acts on the relative tangential motion: a block flying obliquely onto a free
// block (zero gravity, alpha = 0) keeps its sliding velocity without friction and drags
// the other along with static friction; total momentum is conserved either way.
TEST(Bodies, FrictionActsOnTheRelativeTangentialMotion) {
  const std::string t =
      "[[body]]\nshape = \"box\"\nsize = [6, 6, 6]\ndivisions = [3, 3, 3]\n"
      "[[body]]\nshape = \"box\"\nsize = [6, 6, 6]\ndivisions = [3, 3, 3]\nposition = [0.7, 7, 0.3]\n"
      "velocity = [0.5, -0.3, 0]\n"
      "[material]\nE = 20000\nnu = 0.3\n[damping]\nalpha = 0\n[gravity]\ng = [0, 0, 0]\n[floor]\nenabled = false\n"
      "[time]\nduration = 0.015\n";
  double vx[2][2], px[2];
  for (int m = 0; m < 2; ++m) {
    const Scene s = parse_scene(t, "f.toml", {m == 0 ? "contact.mode=sliding" : "contact.mode=static"});
    Simulation sim(s, "cpu");
    double P0[3];
    momentum(sim, P0);
    int contacts = 0;
    while (sim.time() < s.duration) {
      sim.advance(20, 20);
      contacts = std::max(contacts, sim.diagnostics().n_contact);
    }
    double P[3];
    momentum(sim, P);
    px[m] = std::fabs(P[0] - P0[0]) / std::fabs(P0[0]);
    vx[m][0] = body_vx(sim, 0);
    vx[m][1] = body_vx(sim, 1);
    std::printf("%s: contacts %d, vx bottom %.4f top %.4f m/s, x-momentum drift %.2g\n", m ? "static" : "sliding",
                contacts, vx[m][0], vx[m][1], px[m]);
    EXPECT_GT(contacts, 4);
    EXPECT_LT(px[m], 1e-9);
  }
  EXPECT_LT(std::fabs(vx[0][0]), 0.01);  // frictionless: the normal is along y, nothing drags along x
  EXPECT_GT(vx[0][1], 0.49);
  EXPECT_GT(vx[1][0], 0.05);             // static friction drags the bottom block along
  EXPECT_LT(vx[1][1], 0.45);
}

TEST(Bodies, DepthIsTwoVolumesOverAreaAndAClosingStepBeyondItIsRefused) {
  // 2 V / A: the tube radius of a torus (R = 7.5 mm, r = 2.5 mm; a little less for the
  // faceted mesh).
  Simulation rings(asset("two_ring_collision.toml", {"time.duration=0.001"}), "cpu");
  const std::vector<double> depths = body_depths(rings.mesh());
  ASSERT_EQ(depths.size(), 2u);
  for (int b = 0; b < 2; ++b) EXPECT_NEAR(depths[b], 2.5e-3, 0.2e-3) << b;
  // Rings flying at 1e4 m/s each crossed 370 mm per step and passed through each other
  // with exit 0 and no contact; whatever closes by more than the thinner depth per step
  // is refused at the start, naming both velocities.
  const double dt = rings.time_step().dt, depth = std::min(depths[0], depths[1]);
  const double v_over = 0.51 * depth / dt, v_under = 0.49 * depth / dt;  // each; they close at twice that
  const auto with_speed = [&](double v) {
    char a[80], b[80];
    std::snprintf(a, sizeof a, "body.0.velocity=[%.17g, 0, 0]", v);
    std::snprintf(b, sizeof b, "body.1.velocity=[%.17g, 0, 0]", -v);
    return std::vector<std::string>{a, b, "time.duration=0.0001"};
  };
  try {
    Simulation sim(asset("two_ring_collision.toml", with_speed(v_over)), "cpu");
    ADD_FAILURE() << "closing by more than the depth per step was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("body[0].velocity and body[1].velocity: the bodies are on a collision course at"), std::string::npos)
        << e.what();
  }
  // Just under it the run starts, and the rings meet: contact is seen before they could
  // pass (at ~250 m/s the crush that follows is the watchdog's business).
  Simulation under(asset("two_ring_collision.toml", with_speed(v_under)), "cpu");
  bool met = false;
  try {
    for (int k = 0; k < 40 && !met; ++k) under.step(1), met = under.diagnostics().n_contact > 0;
  } catch (const SimulationDiverged&) {
  }
  EXPECT_TRUE(met) << "rings closing at just under one depth per step never touched";
  // Flying apart, or past each other 400 mm apart, as fast: nothing to miss (both were
  // refused while the check looked at |v_i - v_j| alone).
  const auto with = [&](std::vector<std::string> set) {
    set.push_back("time.duration=0.0001");
    return asset("two_ring_collision.toml", set);
  };
  EXPECT_NO_THROW(Simulation(with({"body.0.velocity=[-5000, 0, 0]", "body.1.velocity=[5000, 0, 0]"}), "cpu"));
  EXPECT_NO_THROW(Simulation(with({"body.1.position=[400, 0, 0]", "body.0.velocity=[0, 5000, 0]",
                                   "body.1.velocity=[0, 5000, 3000]"}), "cpu"));
  // On a collision course but meeting only after time.duration: the run ends first.
  std::vector<std::string> late = with_speed(v_over);
  late.push_back("body.1.position=[1000, 0, 0]");
  EXPECT_NO_THROW(Simulation(asset("two_ring_collision.toml", late), "cpu"));
  late.back() = "body.1.position=[20, 0, 0]";  // meets within the 0.1 ms
  EXPECT_THROW(Simulation(asset("two_ring_collision.toml", late), "cpu"), InputError);
  // Without body contact there is nothing to miss.
  std::vector<std::string> off = with_speed(v_over);
  off.push_back("contact.bodies=false");
  EXPECT_NO_THROW(Simulation(asset("two_ring_collision.toml", off), "cpu"));
}

// Two soft 6 mm cubes stacked face to face on the floor, node on node (a probe's scene):
// the upper one stays on the lower. With the uniform shares and the push-out of residual
// depth it sank through the lower cube in 1.1 s (sliding, exit 0), and with Coulomb
// friction it kept 4e-10 J of buzz; now the sliding stack holds and the Coulomb stack comes
// to rest (alpha = 150 damps 1e-65 per second).
TEST(Bodies, CubesStackedFaceToFaceStayStacked) {
  auto stack = [](const std::string& mode) {
    char buf[700];
    std::snprintf(buf, sizeof buf,
                  "units = \"mm\"\n[[body]]\nshape = \"box\"\nsize = [6,6,6]\ndivisions = [2,2,2]\nposition = [0,3,0]\n"
                  "[[body]]\nshape = \"box\"\nsize = [6,6,6]\ndivisions = [2,2,2]\nposition = [0,9,0]\n"
                  "[material]\nE = 5000.0\nnu = 0.0\n[damping]\nalpha = 150.0\n[floor]\npoint = [0,0,0]\n"
                  "[contact]\nmode = \"%s\"\nmu = 0.5\n[time]\nlambda = 0.2\n",
                  mode.c_str());
    return parse_scene(buf, "stack");
  };
  {
    Simulation sim(stack("sliding"), "cpu");
    double lowest = 1;
    for (int k = 0; k < 15; ++k) {
      sim.advance_to(0.1 * (k + 1));
      lowest = std::min(lowest, sim.diagnostics().body_centroid[4]);
    }
    std::printf("sliding stack: upper centroid lowest %.4f mm, KE at 1.5 s %.3g J\n", lowest * 1e3, sim.diagnostics().ke);
    EXPECT_GT(lowest, 8.8e-3) << "the upper cube sank into the lower one";
  }
  Simulation sim(stack("coulomb"), "cpu");
  sim.advance_to(1.0);
  const Diagnostics d = sim.diagnostics();
  std::printf("coulomb stack at 1 s: upper centroid %.4f mm, KE %.3g J, min_gap %.3g mm\n", d.body_centroid[4] * 1e3, d.ke,
              d.min_gap * 1e3);
  EXPECT_GT(d.body_centroid[4], 8.8e-3);
  EXPECT_LT(d.ke, 1e-20) << "the stack does not come to rest";
  EXPECT_GT(d.min_gap, -1e-9);
}

// Two 2 mm cubes side by side, touching, in zero gravity at rest, with a coarse 300 mm
// one-element box far away (a probe's scene): the cubes stay at rest. With one contact
// tolerance for the scene (a tenth of the mean edge over every body: 11 mm here) each
// cube's top nodes lay within it behind the other's bottom face, facing it, and were
// pushed 2 mm down: a NaN within a millisecond. Each pair now takes the smaller of its
// two bodies' tolerances (pair_tolerance).
TEST_P(BodyContactOnEachBackend, TouchingSmallBodiesBesideACoarseOneStayAtRest) {
  const Scene s = parse_scene(
      "units = \"mm\"\n[[body]]\nshape = \"box\"\nsize = [2,2,2]\ndivisions = [2,2,2]\nposition = [-1,0,0]\n"
      "[[body]]\nshape = \"box\"\nsize = [2,2,2]\ndivisions = [2,2,2]\nposition = [1,0,0]\n"
      "[[body]]\nshape = \"box\"\nsize = [300,300,300]\ndivisions = [1,1,1]\nposition = [0,400,0]\n"
      "[material]\nE = 20000.0\nnu = 0.4\n[damping]\nalpha = 0.0\n[gravity]\ng = [0,0,0]\n[floor]\nenabled = false\n"
      "[contact]\nmode = \"coulomb\"\nmu = 0.5\n",
      "touching cubes");
  const BodyContactTables tab = build_body_contact_tables(Simulation(s, "cpu").mesh());
  ASSERT_EQ(tab.body_tol.size(), 3u);
  EXPECT_GT(tab.body_tol[2], 2e-3) << "the coarse box's own tolerance exceeds the cubes' size";
  EXPECT_LT(tab.body_tol[0], 0.2e-3);
  Simulation sim(s, backend());
  sim.advance_to(0.01);
  const Diagnostics d = sim.diagnostics();
  double moved = 0;
  for (int b = 0; b < 2; ++b)
    moved = std::max({moved, std::fabs(d.body_centroid[3 * b] - (2 * b - 1) * 1e-3), std::fabs(d.body_centroid[3 * b + 1]),
                      std::fabs(d.body_centroid[3 * b + 2])});
  std::printf("%s: cubes' centroids moved %.3g m, KE %.3g J after 10 ms\n", backend().c_str(), moved, d.ke);
  EXPECT_LT(moved, 1e-9);
  EXPECT_LT(d.ke, 1e-20);
}

// The same cubes with the upper one 1.3 mm and 0.7 mm off centre, alpha = 10 (the probe's
// second scene): held by Coulomb friction it must not creep (it crept 41 um/s sideways).
TEST(Bodies, OffsetStackHeldByFrictionDoesNotCreep) {
  const Scene s = parse_scene(
      "units = \"mm\"\n[[body]]\nshape = \"box\"\nsize = [6,6,6]\ndivisions = [2,2,2]\nposition = [0,3,0]\n"
      "[[body]]\nshape = \"box\"\nsize = [6,6,6]\ndivisions = [2,2,2]\nposition = [1.3,9,0.7]\n"
      "[material]\nE = 5000.0\nnu = 0.45\n[damping]\nalpha = 10.0\n[floor]\npoint = [0,0,0]\n"
      "[contact]\nmode = \"coulomb\"\nmu = 0.5\n",
      "offset stack");
  Simulation sim(s, "cpu");
  sim.advance_to(1.0);
  const double x1 = sim.diagnostics().body_centroid[3];
  sim.advance_to(2.0);
  const Diagnostics d = sim.diagnostics();
  std::printf("offset stack: upper cube moved %.3g um in x from 1 s to 2 s, KE %.3g J\n", (d.body_centroid[3] - x1) * 1e6,
              d.ke);
  EXPECT_LT(std::fabs(d.body_centroid[3] - x1), 1e-6) << "the upper cube creeps";
  EXPECT_LT(d.ke, 1e-14);
}

// A soft 4 mm cube thrown at 1 m/s onto a slab of 100 x its density, alpha = 0, no
// gravity (after a CLI probe's scene, README limits "energy from body contact"): projection
// contact is inelastic, so kinetic plus strain energy may only fall, at any step size.
TEST(Bodies, PressedIntoADenseSlabGainsNoEnergy) {
  for (double lambda : {0.5, 0.1}) {
    const Scene s = parse_scene(
        "units = \"mm\"\n[[body]]\nshape = \"box\"\nsize = [4,4,4]\ndivisions = [2,2,2]\nposition = [0,2.05,0]\n"
        "velocity = [0,-1,0]\n[[body]]\nshape = \"box\"\nsize = [20,4,20]\ndivisions = [5,1,5]\nposition = [0,-2,0]\n"
        "[body.material]\nrho = 100000.0\n[material]\nE = 20000.0\nnu = 0.3\n[damping]\nalpha = 0.0\n"
        "[gravity]\ng = [0,0,0]\n[floor]\nenabled = false\n[time]\nlambda = " + std::to_string(lambda) + "\n",
        "press");
    Simulation sim(s, "cpu");
    const double h0 = sim.diagnostics().ke;
    double h_max = 0;
    for (int k = 1; k <= 20; ++k) {
      sim.advance_to(1e-3 * k);
      const Diagnostics d = sim.diagnostics();
      h_max = std::max(h_max, d.ke + d.se);
    }
    std::printf("pressed cube, lambda %g: kinetic + strain energy at most %.4g J of %.4g J at the start\n", lambda, h_max, h0);
    EXPECT_LE(h_max, h0 * (1 + 1e-3)) << "lambda " << lambda;
  }
}

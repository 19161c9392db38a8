// TetGen's inputs are checked before TetGen sees them: switches (only the documented
// subset, with bounds), the numeric options, the final geometry, and the mesh size.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "sim/contact/mesh_sdf.h"
#include "sim/mesh/surface_generators.h"
#include "sim/mesh/surface_io.h"
#include "sim/mesh/tet_io.h"
#include "sim/mesh/tetgen_mesher.h"
#include "sim/scene/scene.h"
#include "sim/scene/scene_geometry.h"

using namespace softtled;

namespace {

// Runs f, which must throw InputError whose message contains every fragment.
template <class F>
void expect_input_error(F f, std::initializer_list<std::string> fragments, const std::string& what) {
  try {
    f();
    ADD_FAILURE() << what << ": accepted, but should fail";
  } catch (const InputError& e) {
    for (const std::string& frag : fragments)
      EXPECT_NE(std::string(e.what()).find(frag), std::string::npos) << what << ": expected '" << frag << "' in: " << e.what();
  }
}

TetgenOptions with_switches(const std::string& s) {
  TetgenOptions o;
  o.switches = s;
  return o;
}

const SurfaceMesh& small_box() {
  static const SurfaceMesh b = make_box(0.01, 0.01, 0.01, 2, 2, 2);
  return b;
}

}  // namespace

// Raw switches reach TetGen only through the parsed subset: a long value (TetGen copies it
// into a 1 kB buffer), switches that crash or hang TetGen (T, H, r, w, i, m, ...) and
// numbers outside the bounds are refused with the key and the offending part.
TEST(TetgenSwitches, OnlyTheDocumentedSubsetIsAccepted) {
  const std::string long_value = "pq" + std::string(1500, '1');
  expect_input_error([&] { tetgen_switches(with_switches(long_value)); }, {"mesh.switches", "too long"}, "1.5 kB value");
  expect_input_error([&] { tetrahedralize_surface(small_box(), with_switches(long_value)); }, {"mesh.switches"},
                     "1.5 kB value, meshed");
  for (const char* bad : {"pT1", "pH", "ph", "p?", "pr", "pw", "pi", "pm", "pR", "pc", "pA", "pd", "po2", "pN", "pE",
                          "pI", "pV", "pS0", "pO9", "pM", "px", "pD", "pC", "pb", "pl", "pL", "pk", "pJ", "pF", "pB"}) {
    const std::string letter(1, bad[1]);
    expect_input_error([&] { tetgen_switches(with_switches(bad)); }, {"mesh.switches", "'" + letter + "'"}, bad);
    expect_input_error([&] { tetrahedralize_surface(small_box(), with_switches(bad)); }, {"mesh.switches"}, bad);
  }
  const struct {
    const char* sw;
    const char* fragment;
  } numeric[] = {
      {"pq0.5", "q0.5"},         {"pq1000000", "q1000000"}, {"pq1.5/40", "/40"},      {"pa", "a"},
      {"pa0", "a0"},             {"pa1e999", "a1e999"},     {"pa-1", "a"},           {"pq1..2", "q1.."},
      {"pqq", "'q' given twice"}, {"pq1.2/", "q1.2/"},      {"pa1e-3q2a2", "twice"}, {"p q", "' '"},
      {"pY2", "Y2"},             {"pq1e3", "no exponent"},  {"pq1.4/2E1", "no exponent"},
  };
  for (const auto& c : numeric)
    expect_input_error([&] { tetgen_switches(with_switches(c.sw)); }, {"mesh.switches", c.fragment}, c.sw);
}

TEST(TetgenSwitches, TheSubsetMeshesLikeTheTypedOptions) {
  // "a" in mesh.switches is in mm^3 (TetGen meshes in millimetres); max_volume is in m^3.
  TetgenOptions typed;
  typed.radius_edge = 1.4;
  typed.min_dihedral = 10;
  typed.max_volume = 20e-9;
  typed.keep_boundary = true;
  for (const char* sw : {"pq1.4/10a20Y", "-q1.4/10a20YzQ", "Ya20q1.4/10"}) {
    EXPECT_EQ(tetgen_switches(with_switches(sw)), tetgen_switches(typed)) << sw;
    const TetMesh a = tetrahedralize_surface(small_box(), with_switches(sw));
    const TetMesh b = tetrahedralize_surface(small_box(), typed);
    EXPECT_EQ(a.tet, b.tet) << sw;
    EXPECT_EQ(a.X, b.X) << sw;
  }
  EXPECT_EQ(tetgen_switches(TetgenOptions{}), "pq2zQ");  // the paper's -pq2
  EXPECT_EQ(tetgen_switches(with_switches("p")), "pzQ");
  EXPECT_EQ(tetgen_switches(with_switches("pq")), "pq2zQ");  // TetGen's default bound
}

// "a" is in the scene's units cubed, as mesh.max_volume: a units = "m" scene's a1e-8 is
// max_volume = 1e-8 m^3 (it was read as 1e-8 mm^3 and refused as 10^11 tets), a1 is 1 m^3.
TEST(TetgenSwitches, TheVolumeIsInTheScenesUnits) {
  for (const char* units : {"m", "mm"}) {
    SCOPED_TRACE(units);
    const double v = std::string(units) == "m" ? 1e-8 : 10.0;  // 10 mm^3 either way
    const std::string head = std::string("units = \"") + units + "\"\n[mesh]\n";
    char a[64], typed[64];
    std::snprintf(a, sizeof a, "switches = \"pq2a%g\"\n", v);
    std::snprintf(typed, sizeof typed, "max_volume = %g\n", v);
    EXPECT_EQ(tetgen_switches(scene_tetgen_options(parse_scene(head + a, "s.toml"))),
              tetgen_switches(scene_tetgen_options(parse_scene(head + typed, "s.toml"))));
  }
  EXPECT_EQ(tetgen_switches(scene_tetgen_options(parse_scene("units = \"m\"\n[mesh]\nswitches = \"pq2a1\"\n", "s.toml"))),
            "pq2a1e+09zQ");
}

TEST(TetgenOptions, NumbersAreBoundedInsideTheMesher) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  struct Case {
    double TetgenOptions::*field;
    double value;
    const char* key;
  };
  const Case cases[] = {
      {&TetgenOptions::radius_edge, nan, "mesh.radius_edge"},     {&TetgenOptions::radius_edge, 0.5, "mesh.radius_edge"},
      {&TetgenOptions::radius_edge, 1e9, "mesh.radius_edge"},     {&TetgenOptions::radius_edge, -1, "mesh.radius_edge"},
      {&TetgenOptions::min_dihedral, nan, "mesh.min_dihedral"},   {&TetgenOptions::min_dihedral, -1, "mesh.min_dihedral"},
      {&TetgenOptions::min_dihedral, 45, "mesh.min_dihedral"},    {&TetgenOptions::max_volume, nan, "mesh.max_volume"},
      {&TetgenOptions::max_volume, inf, "mesh.max_volume"},       {&TetgenOptions::max_volume, -1e-9, "mesh.max_volume"},
  };
  for (const Case& c : cases) {
    TetgenOptions o;
    o.*c.field = c.value;
    const std::string what = std::string(c.key) + "=" + std::to_string(c.value);
    expect_input_error([&] { tetgen_switches(o); }, {c.key}, what);
    expect_input_error([&] { tetrahedralize_surface(small_box(), o); }, {c.key}, what);
  }
  TetgenOptions off;
  off.radius_edge = 0;  // 0 disables -q
  EXPECT_EQ(tetgen_switches(off), "pzQ");
  const TetMesh m = tetrahedralize_surface(small_box(), off);
  EXPECT_NEAR(tet_mesh_volume(m), 1e-6, 1e-15);
}

namespace {

// body.scale, body.rotation_deg (x, then y, then z) and body.position, as the scene applies them.
SurfaceMesh placed(SurfaceMesh s, double scale, const double rot_deg[3], const double pos[3]) {
  const double pi = 3.14159265358979323846;
  const double a[3] = {rot_deg[0] * pi / 180, rot_deg[1] * pi / 180, rot_deg[2] * pi / 180};
  for (int i = 0; i < s.npoint(); ++i) {
    double* p = &s.xyz[3 * i];
    for (int k = 0; k < 3; ++k) p[k] *= scale;
    double y = p[1] * std::cos(a[0]) - p[2] * std::sin(a[0]), z = p[1] * std::sin(a[0]) + p[2] * std::cos(a[0]);
    p[1] = y, p[2] = z;
    double x = p[0] * std::cos(a[1]) + p[2] * std::sin(a[1]);
    z = -p[0] * std::sin(a[1]) + p[2] * std::cos(a[1]);
    p[0] = x, p[2] = z;
    x = p[0] * std::cos(a[2]) - p[1] * std::sin(a[2]);
    y = p[0] * std::sin(a[2]) + p[1] * std::cos(a[2]);
    p[0] = x, p[1] = y;
    for (int k = 0; k < 3; ++k) p[k] += pos[k];
  }
  return s;
}

}  // namespace

// Extreme placements made TetGen assert (scale 1e100), segfault (scale 1e-200, position
// 1e15) or silently mesh differently (position 1e10). The final surface is checked first.
TEST(TetgenGeometry, ExtremePlacementsAreRefusedBeforeTetGen) {
  const SurfaceMesh torus = make_torus(7.5e-3, 2.5e-3, 24, 8);  // 20 mm across
  const double zero[3] = {0, 0, 0};
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    double scale, rot, pos;
    const char* fragment;
  } cases[] = {
      {1e-200, 0, 0, "size"}, {1e-9, 0, 0, "size"},         {1e6, 0, 0, "size"},
      {1e100, 0, 0, "size"},  {1e200, 0, 0, "size"}, {1e306, 0, 1e306, "size"}, {1, 0, 1e5, "from the origin"},
      {1, 0, 1e15, "from the origin"}, {1, 0, 1e300, "from the origin"}, {1e-4, 0, 1e3, "times the body's size"},
      {1, 0, inf, "NaN or infinite"},
  };
  for (const Case& c : cases) {
    const double rot[3] = {c.rot, c.rot, c.rot}, pos[3] = {c.pos, 0, c.pos};
    const SurfaceMesh s = placed(torus, c.scale, rot, pos);
    char what[96];
    std::snprintf(what, sizeof what, "scale %g position %g", c.scale, c.pos);
    expect_input_error([&] { check_surface_for_meshing(s); }, {"surface to mesh", c.fragment}, what);
    expect_input_error([&] { tetrahedralize_surface(s, TetgenOptions{}); }, {"surface to mesh", c.fragment}, what);
  }
  // Inside the documented range the mesh is the same, wherever the body is and however
  // far it is turned (1e20 degrees is still a rotation).
  const TetMesh ref = tetrahedralize_surface(torus, TetgenOptions{});
  const double big_turn[3] = {1e20, -3e17, 7e15}, far[3] = {1e3, -1e3, 5e2};
  const struct {
    SurfaceMesh s;
    double scale;
  } fine[] = {{placed(torus, 1, zero, far), 1}, {placed(torus, 1e-3, zero, zero), 1e-3},
              {placed(torus, 1e4, zero, zero), 1e4}, {placed(torus, 1, big_turn, zero), 1}};
  for (const auto& f : fine) {
    ASSERT_NO_THROW(check_surface_for_meshing(f.s));
    const TetMesh m = tetrahedralize_surface(f.s, TetgenOptions{});
    const double v = tet_mesh_volume(ref) * f.scale * f.scale * f.scale;
    EXPECT_NEAR(tet_mesh_volume(m), v, 1e-6 * v) << "scale " << f.scale;
    EXPECT_NEAR(enclosed_volume(f.s), v, 1e-6 * v) << "scale " << f.scale;  // far from the origin too
  }
}

// Two closed cubes, each a valid shell, touching along an edge or at a corner: TetGen
// merges the coincident vertices, so the mesh's boundary is not a manifold there (its
// `mesh --vtu` did not read back). Refused naming where; apart, they mesh.
TEST(TetgenGeometry, PartsTouchingAtAnEdgeOrAPointAreRefused) {
  auto two_cubes = [](double dx, double dy, double dz) {
    SurfaceMesh s = make_box(0.01, 0.01, 0.01, 1, 1, 1), b = s;
    const int n = s.npoint();
    for (int i = 0; i < b.npoint(); ++i) {
      s.xyz.insert(s.xyz.end(), {b.xyz[3 * i] + dx, b.xyz[3 * i + 1] + dy, b.xyz[3 * i + 2] + dz});
    }
    for (int v : b.tri) s.tri.push_back(v + n);
    return s;
  };
  for (const double dz : {0.0, 0.01}) {  // an edge, a corner
    try {
      tetrahedralize_surface(two_cubes(0.01, 0.01, dz), TetgenOptions{});
      ADD_FAILURE() << "touching cubes meshed, dz = " << dz;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("the surface's parts touch"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(dz == 0 ? "belongs to 4 boundary faces" : "separate fans"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_NEAR(tet_mesh_volume(tetrahedralize_surface(two_cubes(0.0101, 0.0101, 0), TetgenOptions{})), 2e-6, 1e-15);
}

// A feature far below the body's size (TetGen's tolerance is 1e-8 of it: a point 1e-8 off
// an edge was merged into it and the mesh came out wrong) is refused with its size.
TEST(TetgenGeometry, TinyFeaturesAreRefused) {
  auto split_tetrahedron = [](double x, double y) {
    SurfaceMesh s;
    s.xyz = {0, 0, 0, 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01, x, y, 0};  // face 0-1-2 split at point 4
    s.tri = {0, 1, 3, 1, 2, 3, 0, 3, 2, 0, 2, 4, 2, 1, 4, 1, 0, 4};
    return s;
  };
  expect_input_error([&] { tetrahedralize_surface(split_tetrahedron(1e-10, 1e-10), TetgenOptions{}); },
                     {"surface to mesh", "short edge"}, "point 1e-10 from a corner");
  expect_input_error([&] { tetrahedralize_surface(split_tetrahedron(0.005, 1e-10), TetgenOptions{}); },
                     {"surface to mesh", "sliver"}, "point 1e-10 off an edge");
  const TetMesh m = tetrahedralize_surface(split_tetrahedron(0.003, 0.002), TetgenOptions{});
  EXPECT_NEAR(tet_mesh_volume(m), 1e-6 / 6, 1e-18);
  // Indices out of range or an open surface never reach TetGen either.
  SurfaceMesh bad = split_tetrahedron(0.003, 0.002);
  bad.tri[0] = 99;
  expect_input_error([&] { tetrahedralize_surface(bad, TetgenOptions{}); }, {"surface to mesh", "vertex 99"}, "index");
  bad.tri.resize(15);
  expect_input_error([&] { tetrahedralize_surface(bad, TetgenOptions{}); }, {"surface to mesh"}, "open");
}

// The estimate is close enough to refuse absurd meshes: within a factor of 3 of what
// TetGen makes on shapes with surface-, thickness- and volume-driven sizes.
TEST(TetgenBudget, EstimateIsWithinAFactorOfThree) {
  TetgenOptions plain, small_tets, sharper;
  small_tets.max_volume = 1e-10;
  sharper.radius_edge = 1.4;
  sharper.min_dihedral = 10;
  const struct {
    SurfaceMesh s;
    const char* name;
  } shapes[] = {{make_torus(7.5e-3, 2.5e-3, 91, 19), "paper torus"}, {make_box(0.02, 0.01, 0.008, 8, 8, 8), "box"},
                {make_sphere(5e-3, 3), "sphere"}, {make_box(0.02, 0.02, 2e-4, 1, 1, 1), "plate 100:1 of 12 triangles"}};
  for (const auto& shape : shapes)
    for (const TetgenOptions* o : {&plain, &small_tets, &sharper}) {
      const double est = estimate_tet_count(shape.s, *o);
      const int actual = tetrahedralize_surface(shape.s, *o).ntet();
      EXPECT_GT(est, actual / 3.0) << shape.name << " -" << tetgen_switches(*o) << ": " << actual << " tets";
      EXPECT_LT(est, actual * 3.0) << shape.name << " -" << tetgen_switches(*o) << ": " << actual << " tets";
    }
}

// A tiny max_volume ran 68 s and 4 GB before TetGen failed, a thin plate of 12 triangles
// makes millions of tets: both are refused up front, with the estimate and the budget.
TEST(TetgenBudget, TooLargeMeshesAreRefusedBeforeMeshing) {
  const SurfaceMesh torus = make_torus(7.5e-3, 2.5e-3, 91, 19);
  TetgenOptions tiny;
  tiny.max_volume = 1e-18;  // 1e-9 mm^3
  expect_input_error([&] { tetrahedralize_surface(torus, tiny); }, {"mesh too large", "max_tets", "5000000"}, "max_volume 1e-18");
  TetgenOptions tiny_sw;
  tiny_sw.switches = "pq2a1e-9";
  expect_input_error([&] { tetrahedralize_surface(torus, tiny_sw); }, {"mesh too large"}, "switches a1e-9");
  expect_input_error([&] { tetrahedralize_surface(make_box(0.02, 0.02, 1e-5, 1, 1, 1), TetgenOptions{}); },
                     {"mesh too large"}, "plate 2000:1");
  // The budget is an option: the paper's torus (about 7000 tets) fits the default, not 1000.
  TetgenOptions small_budget;
  small_budget.max_tets = 1000;
  expect_input_error([&] { tetrahedralize_surface(torus, small_budget); }, {"mesh too large", "1000"}, "max_tets 1000");
  small_budget.max_tets = 0;
  expect_input_error([&] { tetgen_switches(small_budget); }, {"mesh.max_tets"}, "max_tets 0");
  // When the estimate is low, TetGen's own count is checked too: q1.1 on a coarse torus
  // makes about 190 tets per surface triangle.
  TetgenOptions sharp;
  sharp.radius_edge = 1.1;
  const SurfaceMesh coarse = make_torus(7.5e-3, 2.5e-3, 24, 8);
  sharp.max_tets = long(estimate_tet_count(coarse, sharp) * 1.05);
  expect_input_error([&] { tetrahedralize_surface(coarse, sharp); }, {"mesh too large", "TetGen -pq1.1zQ made"}, "q1.1");
}

// body.segments = [4096, 4096] died with std::bad_alloc: generators refuse absurd counts
// before allocating.
TEST(TetgenBudget, GeneratorsRefuseAbsurdSegmentCounts) {
  expect_input_error([] { make_torus(7.5e-3, 2.5e-3, 4096, 4096); }, {"torus", "4096 x 4096", "33554432"}, "torus");
  expect_input_error([] { make_torus(7.5e-3, 2.5e-3, 1 << 30, 1 << 30); }, {"torus", "triangles"}, "int overflow");
  expect_input_error([] { make_box(1, 1, 1, 1024, 1024, 1024); }, {"box", "1024 x 1024 x 1024"}, "box");
  EXPECT_EQ(make_torus(7.5e-3, 2.5e-3, 500, 1000).ntri(), 1'000'000);  // the limit itself is fine
}

// TetGen 1.5 runs in a child process: the fuzzer found a plain rotated box on which it
// fails an assertion ("oriB != 0.0" in insphere_s) and aborted the whole program. Now
// the outcome is a mesh or an InputError, and a run past the time limit is stopped.
TEST(TetgenIsolation, TetgenCrashIsAnErrorNotAnAbort) {
  const double rot[3] = {30, 45, 60}, pos[3] = {0.5, -0.4, 1.0};
  const SurfaceMesh box = placed(make_box(0.01, 0.02, 0.005, 2, 3, 1), 1, rot, pos);  // tests/fuzz/crashes/fuzz_mesh
  TetgenOptions o;
  o.max_volume = 2e-8;
  try {
    const TetMesh m = tetrahedralize_surface(box, o);
    EXPECT_NEAR(tet_mesh_volume(m), 1e-6, 1e-12);  // a TetGen without the bug meshes it
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("TetGen (-pq2a20zQ) crashed on this surface (signal 6"), std::string::npos)
        << e.what();
  }
  // The process and TetGen still work afterwards.
  EXPECT_NEAR(tet_mesh_volume(tetrahedralize_surface(small_box(), TetgenOptions{})), 1e-6, 1e-15);
}

TEST(TetgenIsolation, TimeLimitStopsTetgen) {
  TetgenOptions o;
  o.time_limit_s = 1e-3;  // the paper's torus takes a good part of a second
  expect_input_error([&] { tetrahedralize_surface(make_torus(7.5e-3, 2.5e-3, 91, 19), o); },
                     {"did not finish within 0.001 s", "mesh.time_limit_s"}, "1 ms");
  o.time_limit_s = -1;
  expect_input_error([&] { tetgen_switches(o); }, {"mesh.time_limit_s"}, "negative limit");
}

namespace {
// An axis-aligned box [lo, lo + size]^3 as 12 triangles, outward (or inward when `in`).
void add_box(SurfaceMesh& s, double lo, double size, bool in = false) {
  const int b = s.npoint();
  for (int k = 0; k < 8; ++k) s.xyz.insert(s.xyz.end(), {lo + size * (k & 1), lo + size * ((k >> 1) & 1), lo + size * ((k >> 2) & 1)});
  const int F[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                        {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  for (const auto& f : F) {
    if (in) s.tri.insert(s.tri.end(), {b + f[0], b + f[2], b + f[1]});
    else s.tri.insert(s.tri.end(), {b + f[0], b + f[1], b + f[2]});
  }
}
}  // namespace

TEST(TetgenHollow, NestedShellCavityIsKeptEmpty) {
  for (bool inner_inward : {false, true}) {  // either orientation of the inner shell in the file
    SurfaceMesh s;
    add_box(s, 0, 0.03);
    add_box(s, 0.01, 0.01, inner_inward);
    ASSERT_NEAR(enclosed_volume(s) > 0 ? 1 : 0, 1, 0);
    SurfaceMesh oriented = s;
    check_and_orient_closed_surface(oriented, "hollow");
    EXPECT_NEAR(enclosed_volume(oriented), 27e-6 - 1e-6, 1e-15);  // the solid's volume
    const ShellNesting nest = shell_nesting(s);
    ASSERT_EQ(nest.ncomp, 2);
    EXPECT_EQ(nest.depth[0], 0);
    EXPECT_EQ(nest.depth[1], 1);
    const std::vector<double> holes = cavity_hole_points(s);
    ASSERT_EQ(holes.size(), 3u);
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(holes[k] > 0.01 && holes[k] < 0.02) << holes[k];
    TetgenOptions o;
    const TetMesh m = tetrahedralize_surface(s, o);
    double vol = 0;
    int in_cavity = 0;
    for (int e = 0; e < m.ntet(); ++e) {
      const int* t = &m.tet[4 * e];
      vol += std::fabs(tet_signed_volume(&m.X[3 * t[0]], &m.X[3 * t[1]], &m.X[3 * t[2]], &m.X[3 * t[3]]));
      double c[3] = {0, 0, 0};
      for (int k = 0; k < 4; ++k)
        for (int d = 0; d < 3; ++d) c[d] += m.X[3 * t[k] + d] / 4;
      if (c[0] > 0.01 && c[0] < 0.02 && c[1] > 0.01 && c[1] < 0.02 && c[2] > 0.01 && c[2] < 0.02) ++in_cavity;
    }
    EXPECT_NEAR(vol, 26e-6, 1e-12);  // outer minus inner
    EXPECT_EQ(in_cavity, 0);
    // The hollow mesh, read back as a tet file, is one part (no overlap): the cavity's
    // boundary lies in no other part's solid.
    EXPECT_NO_THROW(check_tet_boundary_overlap(m, "hollow.mesh"));
  }
}

TEST(TetgenHollow, SolidInsideACavityIsMeshedToo) {
  // Three nested shells: solid, cavity, solid island inside the cavity.
  SurfaceMesh s;
  add_box(s, 0, 0.05);
  add_box(s, 0.01, 0.03);
  add_box(s, 0.02, 0.01);
  SurfaceMesh oriented = s;
  check_and_orient_closed_surface(oriented, "island");
  EXPECT_NEAR(enclosed_volume(oriented), 125e-6 - 27e-6 + 1e-6, 1e-14);
  const TetMesh m = tetrahedralize_surface(s, TetgenOptions{});
  double vol = 0;
  for (int e = 0; e < m.ntet(); ++e) {
    const int* t = &m.tet[4 * e];
    vol += std::fabs(tet_signed_volume(&m.X[3 * t[0]], &m.X[3 * t[1]], &m.X[3 * t[2]], &m.X[3 * t[3]]));
  }
  EXPECT_NEAR(vol, 99e-6, 1e-11);
}

TEST(TetgenHollow, EveryShellEnclosesVolumeAndOrientingTwiceChangesNothing) {
  // A flat shell (a triangle and its back) beside a solid box: the whole surface encloses
  // the box's volume, but the flat shell's sign is rounding noise, so it has no outside.
  // tests/fuzz/crashes/fuzz_obj/flat_shell_beside_a_solid.obj is the fuzzer's version.
  SurfaceMesh s;
  add_box(s, 0, 0.01);
  const int b = s.npoint();
  s.xyz.insert(s.xyz.end(), {0.05, 0, 0, 0.06, 0, 0, 0.05, 0.01, 0});
  s.tri.insert(s.tri.end(), {b, b + 1, b + 2, b, b + 2, b + 1});
  expect_input_error([&] { check_and_orient_closed_surface(s, "flat shell"); }, {"shell 2 of 2", "encloses no volume"},
                     "flat shell");
  // Orientation is a fixed point: an oriented surface with shells in every role (solid,
  // cavity, island, and a second solid beside them) passes through unchanged.
  SurfaceMesh many;
  add_box(many, 0, 0.05);
  add_box(many, 0.01, 0.03, true);
  add_box(many, 0.02, 0.01);
  add_box(many, 0.1, 0.01, true);
  check_and_orient_closed_surface(many, "many");
  SurfaceMesh again = many;
  check_and_orient_closed_surface(again, "many");
  EXPECT_EQ(again.tri, many.tri);
  EXPECT_NEAR(enclosed_volume(many), 125e-6 - 27e-6 + 1e-6 + 1e-6, 1e-14);
}

TEST(TetgenHollow, ShellsAreJudgedAlikeInEitherOrientation) {
  // Two tetrahedra that cross, the first one's first centroid on an edge of the second
  // (tests/fuzz/crashes/fuzz_obj/shell_through_a_centroid.obj): the points either side of
  // that triangle lie in the second shell's plane, where the winding number once took its
  // sign from rounding, so the surface was accepted and its oriented copy refused. Every
  // orientation of the two shells must now get the same verdict and the same result (they
  // cross, which TetGen's self-intersection probe refuses later; here it is the verdict's
  // independence of orientation that is tested).
  const double P[8][3] = {{0, 0, 1}, {1, 1, 1}, {0, 1, 1}, {0, 0, 0.5}, {5, 5, 5}, {0, 0, 0}, {1, 2, 1}, {0, 0, 1}};
  const int F[8][3] = {{0, 1, 2}, {0, 3, 1}, {1, 3, 2}, {2, 3, 0}, {4, 5, 6}, {4, 7, 5}, {4, 6, 7}, {5, 7, 6}};
  std::string first;
  for (int flips = 0; flips < 4; ++flips) {
    SurfaceMesh s;
    for (const auto& p : P) s.xyz.insert(s.xyz.end(), {p[0], p[1], p[2]});
    for (int f = 0; f < 8; ++f) {
      const bool flip = (flips >> (f / 4)) & 1;
      s.tri.insert(s.tri.end(), {F[f][0], F[f][flip ? 2 : 1], F[f][flip ? 1 : 2]});
    }
    std::string verdict;  // the refusal, or the oriented triangles
    bool accepted = true;
    try {
      check_and_orient_closed_surface(s, "crossing tetrahedra");
    } catch (const InputError& e) {
      verdict = e.what(), accepted = false;
    }
    if (accepted) {
      for (int v : s.tri) verdict += std::to_string(v) + " ";
      SurfaceMesh again = s;
      ASSERT_NO_THROW(check_and_orient_closed_surface(again, "again")) << "flips " << flips << ": its own output refused";
      EXPECT_EQ(again.tri, s.tri) << "flips " << flips << ": its own output oriented again";
    }
    if (flips == 0) first = verdict;
    EXPECT_EQ(verdict, first) << "flips " << flips;
  }
}

TEST(TetgenHollow, CoincidentShellsAreRefused) {
  // Two copies of a cube on separate vertices: each lies on the other, so the winding number
  // at a centroid was 0 or 1 by rounding and the depths flipped with the orientation
  // (tests/fuzz/crashes/fuzz_obj/coincident_shells.obj: accepted, then refused when
  // oriented again). Beside a solid and alone, in either orientation.
  for (const bool inward : {false, true}) {
    SurfaceMesh s;
    add_box(s, 0, 0.01);
    add_box(s, 0, 0.01, inward);
    expect_input_error([&] { check_and_orient_closed_surface(s, "copies"); }, {"lies on shell", "coincide or cross"},
                       "coincident shells");
    add_box(s, 0.05, 0.02);
    expect_input_error([&] { check_and_orient_closed_surface(s, "copies"); }, {"lies on shell"}, "beside a solid");
  }
}

TEST(TetgenHollow, TwoSolidsOneInsideOutAreOrientedNotRefused) {
  // Equal cubes side by side, the second inside out: the whole surface's signed volume is
  // zero, which once refused it as enclosing none; each shell oriented, it encloses both.
  SurfaceMesh s;
  add_box(s, 0, 0.01);
  add_box(s, 0.02, 0.01, true);
  check_and_orient_closed_surface(s, "two cubes");
  EXPECT_NEAR(enclosed_volume(s), 2e-6, 1e-15);
  // Nor does the distance between them matter: 10 cm cubes 300 m apart (against the whole
  // surface's 520 m diagonal they were refused as enclosing nothing).
  SurfaceMesh far;
  add_box(far, 0, 0.1);
  add_box(far, 300, 0.1);
  check_and_orient_closed_surface(far, "far cubes");
  EXPECT_NEAR(enclosed_volume(far), 2e-3, 1e-8);  // summed about vertex 0, 300 m from the second cube
}

TEST(TetgenHollow, VolumeDoesNotDependOnWhereVertexZeroLies) {
  // A 1 m cube whose file lists first a point no triangle uses, 1e9 m away: about that
  // point the terms are ~1e18 and cancel to 1, so the rounding (~100) chose the cube's
  // orientation and its volume.
  for (const bool inward : {false, true}) {
    SurfaceMesh s;
    s.xyz = {1e9, 1e9, 1e9};
    add_box(s, 0, 1, inward);
    check_and_orient_closed_surface(s, "cube after a far unused point");
    EXPECT_NEAR(enclosed_volume(s), 1.0, 1e-12) << "inward " << inward;
  }
  // A 1 mm cube (vertex 0) and, 1e6 m away, a 1 m cube hollowed to a 0.1 mm wall: about
  // vertex 0 the big shells' terms are ~1e12 and their rounding (~1e-3) swamps the wall's
  // 6e-4 m^3. The wall is also thinner than the 1e-3 of a triangle's height that the
  // nesting test once stepped off a triangle, which read it as shells crossing.
  SurfaceMesh h;
  add_box(h, -1e6, 1e-3);
  add_box(h, 0, 1);
  add_box(h, 1e-4, 1 - 2e-4, true);
  check_and_orient_closed_surface(h, "hollow cube far from a small one");
  const double wall = 1 - (1 - 2e-4) * (1 - 2e-4) * (1 - 2e-4);
  EXPECT_NEAR(enclosed_volume(h), 1e-9 + wall, 1e-6 * wall);
}

TEST(TetgenHollow, AThinShellIsJudgedAndOrientedTheSameWhereverItLies) {
  // A 1 m box and, D metres away, an octahedron 20 mm across and 0.4 nm thick: a thin but
  // solid shell, 1.2x its own no-volume threshold. Its volume must be taken about a point
  // of its own; about the box's corner the rounding of terms ~D^2 refused it at D = 500 and
  // not at 300, and could as well have flipped it.
  for (const double D : {300.0, 500.0}) {
    for (const bool inward : {false, true}) {
      SurfaceMesh s;
      add_box(s, 0, 1);
      const int b = s.npoint();
      const double d = 0.01, h = 2e-10;
      const double P[6][3] = {{d, 0, 0}, {-d, 0, 0}, {0, d, 0}, {0, -d, 0}, {0, 0, h}, {0, 0, -h}};
      for (const auto& p : P) s.xyz.insert(s.xyz.end(), {D + p[0], D + p[1], D + p[2]});
      const int F[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
      for (const auto& f : F) {
        if (inward) s.tri.insert(s.tri.end(), {b + f[0], b + f[2], b + f[1]});
        else s.tri.insert(s.tri.end(), {b + f[0], b + f[1], b + f[2]});
      }
      check_and_orient_closed_surface(s, "thin shell");
      SurfaceMesh thin;  // the octahedron alone, as oriented
      thin.xyz.assign(s.xyz.begin() + 3 * b, s.xyz.end());
      for (std::size_t i = 36; i < s.tri.size(); ++i) thin.tri.push_back(s.tri[i] - b);
      EXPECT_NEAR(enclosed_volume(thin), 4.0 / 3.0 * d * d * h, 1e-3 * d * d * h) << "D = " << D;
    }
  }
}

TEST(TetgenProbe, CountsSelfIntersections) {
  SurfaceMesh one;
  add_box(one, 0, 1);
  EXPECT_EQ(count_self_intersections(one), 0);
  SurfaceMesh two = one;
  add_box(two, 0.5, 1);  // overlapping cubes
  EXPECT_GT(count_self_intersections(two), 0);
}

TEST(ObstacleSurface, SelfIntersectingOrNestedShellsAreRefused) {
  auto error = [](const SurfaceMesh& s) -> std::string {
    try {
      check_obstacle_surface(s, "obs.obj");
    } catch (const InputError& e) {
      return e.what();
    }
    return "(accepted)";
  };
  SurfaceMesh one;
  add_box(one, 0, 1);
  EXPECT_EQ(error(one), "(accepted)");
  SurfaceMesh apart = one;
  add_box(apart, 2, 1);  // two separate solids: fine
  EXPECT_EQ(error(apart), "(accepted)");
  SurfaceMesh overlapping = one;
  add_box(overlapping, 0.5, 1);
  EXPECT_NE(error(overlapping).find("obs.obj: the surface intersects itself"), std::string::npos) << error(overlapping);
  SurfaceMesh twice = one;
  add_box(twice, 0, 1);  // the same cube twice, on separate vertices
  EXPECT_NE(error(twice).find("obs.obj: "), std::string::npos);
  EXPECT_NE(error(twice), "(accepted)");
  SurfaceMesh nested = one;
  add_box(nested, 0.25, 0.5);
  EXPECT_NE(error(nested).find("obs.obj: shell 2 of 2 (the one with triangle 12) lies inside another shell"), std::string::npos)
      << error(nested);
  // The tester's files: overlapping cubes, a cube inside a cube (either orientation).
  const std::string f = __FILE__;
  const std::string dir = f.substr(0, f.find_last_of('/')) + "/data/";
  for (const char* name : {"overlap.obj", "nested_hollow.obj", "nested_same.obj"}) {
    const std::string path = dir + name;
    const std::string e = error(load_surface(path));
    EXPECT_NE(e, "(accepted)") << name;
    try {
      check_obstacle_surface(load_surface(path), path);
      ADD_FAILURE() << name << " accepted";
    } catch (const InputError& x) {
      EXPECT_EQ(std::string(x.what()).rfind(path + ": ", 0), 0u) << x.what();
    }
  }
  // build_mesh_sdf checks too (InputError, exit 2).
  EXPECT_THROW(build_mesh_sdf(nested, 16), InputError);
  EXPECT_NO_THROW(build_mesh_sdf(one, 16));
}

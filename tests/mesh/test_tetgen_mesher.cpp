// TetGen's inputs are checked before TetGen sees them: switches (only the documented
// subset, with bounds), the numeric options, the final geometry, and the mesh size.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "sim/mesh/surface_generators.h"
#include "sim/mesh/tetgen_mesher.h"

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
      {"pY2", "Y2"},
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

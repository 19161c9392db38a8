// TetGen's inputs are checked before TetGen sees them: switches (only the documented
// subset, with bounds), the numeric options, the final geometry, and the mesh size.
#include <gtest/gtest.h>

#include <cmath>
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

double mesh_volume(const TetMesh& m) {
  double v = 0;
  for (int e = 0; e < m.ntet(); ++e) {
    const int* t = &m.tet[4 * e];
    v += tet_signed_volume(&m.X[3 * t[0]], &m.X[3 * t[1]], &m.X[3 * t[2]], &m.X[3 * t[3]]);
  }
  return v;
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
  EXPECT_NEAR(mesh_volume(m), 1e-6, 1e-15);
}
